"""Campaigns over many seeded runs: Monte Carlo (local processes or Dask) and filter tuning."""
