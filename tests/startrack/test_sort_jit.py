"""The kernels' sorts (``startrack.compiled.sorts``) give numpy's answers: the stable argsort, unique and median,
on keys with many ties and every length around the insertion runs and the merge widths."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from startrack.compiled.sorts import argsort, median, unique

LENGTHS = [0, 1, 2, 15, 16, 17, 31, 32, 33, 48, 64, 65, 1000, 4097]


@pytest.mark.parametrize("n", LENGTHS)
def test_argsort_is_numpys_stable_argsort(n):
    rng = np.random.default_rng(n)
    ties = rng.integers(0, max(1, n // 4) + 1, n).astype(float)  # about four of each key
    for keys in (ties, rng.normal(size=n), -ties, np.sort(ties), np.sort(ties)[::-1].copy()):
        assert np.array_equal(argsort(keys), np.argsort(keys, kind="stable"))


@given(arrays(np.float64, st.integers(0, 200), elements=st.floats(-1e6, 1e6, allow_nan=False)))
@settings(max_examples=200, deadline=None)
def test_argsort_of_any_finite_keys(keys):
    assert np.array_equal(argsort(keys), np.argsort(keys, kind="stable"))


@pytest.mark.parametrize("n", LENGTHS)
def test_unique_and_median_are_numpys(n):
    rng = np.random.default_rng(100 + n)
    values = rng.integers(-(2**40), 2**40, n) // (2**36)  # many repeats, large magnitudes
    assert np.array_equal(unique(values), np.unique(values))
    if n:
        x = rng.normal(size=n)
        assert median(x) == np.median(x)  # the same two middle values, averaged the same way
