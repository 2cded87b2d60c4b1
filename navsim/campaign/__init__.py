"""Campaigns over many seeded runs: Monte Carlo (local processes or Dask), filter tuning and the error budget."""
