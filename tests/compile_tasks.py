"""Compile-ahead tasks of the tests of :mod:`startrack.compiled.compile_ahead` (importable by its spawned lanes)."""

from startrack.compiled.numba_setup import njit


@njit
def _twice(x):
    return 2.0 * x


@njit
def _thrice(x):
    return 3.0 * x


def twice():
    _twice(1.0)


def thrice():
    _thrice(1.0)


def fails():
    raise RuntimeError("made to fail")
