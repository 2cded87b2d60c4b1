"""Rotations (one convention, numpy and compiled), the sphere, attitude angles."""
