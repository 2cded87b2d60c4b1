"""Estimation: the attitude filter (MEKF), its compiled kernels and the analytic limits it is checked against."""
