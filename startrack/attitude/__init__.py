"""Attitude from matched directions: the solvers and the boresight solves."""
