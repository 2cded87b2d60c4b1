"""k-vector of eq. 3-5 of 000 against brute-force scans."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from startrack.base.errors import InputError
from startrack.catalog.kvector import KVector


def brute_force(values, lower, upper):
    return np.flatnonzero((values >= lower) & (values <= upper))


sorted_tables = st.lists(
    st.floats(min_value=0.0, max_value=0.3, allow_nan=False, allow_subnormal=False), min_size=2, max_size=300
).map(lambda v: np.sort(np.asarray(v)))


@st.composite
def table_and_interval(draw):
    values = draw(sorted_tables)
    # Ends drawn from the table itself (exact hits), neighbours of table values, or anywhere.
    def end():
        kind = draw(st.sampled_from(["value", "next", "free"]))
        if kind == "value":
            return float(values[draw(st.integers(0, values.size - 1))])
        if kind == "next":
            v = float(values[draw(st.integers(0, values.size - 1))])
            return float(np.nextafter(v, draw(st.sampled_from([-1.0, 1.0]))))
        return draw(st.floats(min_value=-0.05, max_value=0.35, allow_nan=False))

    a, b = end(), end()
    return values, min(a, b), max(a, b)


@settings(max_examples=400, deadline=None)
@given(table_and_interval())
def test_range_search_equals_brute_force(case):
    values, lower, upper = case
    kv = KVector.build(values)
    assert np.array_equal(kv.search(lower, upper), brute_force(values, lower, upper))


@settings(max_examples=150, deadline=None)
@given(sorted_tables, st.lists(st.tuples(st.floats(-0.05, 0.35), st.floats(-0.05, 0.35)), min_size=1, max_size=40))
def test_many_intervals_equal_brute_force(values, intervals):
    kv = KVector.build(values, lower=0.0, upper=0.3)
    lower = np.array([min(a, b) for a, b in intervals] + [float(values[0]), float(values[-1])])
    upper = np.array([max(a, b) for a, b in intervals] + [float(values[0]), float(values[-1])])
    lo, hi = kv.range_many(lower, upper)
    for a, b, l, h in zip(lower, upper, lo, hi):
        assert np.array_equal(np.arange(l, h), brute_force(values, a, b))


def test_k_vector_definition_of_eq_4():
    rng = np.random.default_rng(7)
    values = np.sort(rng.uniform(0.01, 0.28, 5000))
    kv = KVector.build(values, 0.01, 0.28)
    n = values.size
    assert kv.k[0] == 0 and kv.k[-1] == n
    x = np.arange(2, n)  # 1-based x = 2 .. n_s - 1
    z = kv.slope * x + kv.intercept
    k = kv.k[x - 1]
    # P(k) <= z(x) < P(k + 1), with P 1-based (P(0) = -inf).
    assert np.all(np.where(k > 0, values[np.maximum(k - 1, 0)] <= z, True))
    assert np.all(np.where(k < n, z < values[np.minimum(k, n - 1)], True))
    # Line of eq. 3 through (1, theta_min - xi) and (n_s, theta_max + xi).
    assert kv.slope * 1 + kv.intercept < 0.01 and kv.slope * n + kv.intercept > 0.28


def test_empty_and_reversed_intervals():
    kv = KVector.build(np.array([0.1, 0.2, 0.2, 0.3]))
    assert kv.search(0.2, 0.1).size == 0
    assert kv.search(float("nan"), 0.2).size == 0
    assert kv.search(0.4, 0.5).size == 0
    assert kv.search(0.2, 0.2).tolist() == [1, 2]
    lo, hi = kv.range_many([0.2, 0.5, float("nan")], [0.1, 0.6, 0.3])
    assert np.all(lo == hi)


def test_bad_tables_are_rejected():
    with pytest.raises(InputError, match="at least 2"):
        KVector.build(np.array([0.1]))
    with pytest.raises(InputError, match="sorted"):
        KVector.build(np.array([0.2, 0.1]))
    with pytest.raises(InputError, match="not finite"):
        KVector.build(np.array([0.1, np.inf]))
    with pytest.raises(InputError, match="contain"):
        KVector.build(np.array([0.1, 0.2]), lower=0.15)
