"""The run-kind registry (docs/design.md, "Run kinds"): every kind provides the whole interface, a
scenario's kind is named by its table, and generic code reaches each kind through the registry."""

from pathlib import Path

import numpy as np
import pytest

from navsim import kinds
from navsim.estimation.attitude_filter import AttitudeFilter, AttitudeFilterConfig
from navsim.estimation.nav_filter import ImuNoise, NavFilterConfig
from navsim.simulation import prepare, simulate
from startrack.base.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parent / "data"


@pytest.mark.parametrize("name", sorted(kinds.KINDS))
def test_every_kind_provides_the_interface(name):
    kind = kinds.KINDS[name]
    assert kind.NAME == name
    missing = [attribute for attribute in kinds.INTERFACE if not hasattr(kind, attribute)]
    assert missing == []
    assert kind.RunSummary.kind == name


def test_exactly_one_kind_takes_the_unmarked_scenarios():
    assert [kind.NAME for kind in kinds.KINDS.values() if kind.TABLE is None] == ["attitude"]


@pytest.mark.parametrize("path, kind", [(ROOT / "scenarios" / "paper000_high_dynamic.toml", "attitude"),
                                        (ROOT / "scenarios" / "sins_cns_psins.toml", "navigation"),
                                        (ROOT / "scenarios" / "paper003_precision.toml", "study")])
def test_a_scenario_is_of_the_kind_its_table_names(path, kind):
    assert kinds.load_scenario(path).kind == kind


def test_a_static_study_is_refused_where_a_run_is_needed():
    study = kinds.load_scenario(ROOT / "scenarios" / "paper003_precision.toml")
    with pytest.raises(InputError, match="a static study .* cannot be used for a Monte Carlo campaign"):
        kinds.run_kind(study, "a Monte Carlo campaign")


def test_truth_sources_are_the_kinds_own():
    attitude = kinds.load_scenario(DATA / "base_constant.toml")
    with pytest.raises(InputError, match="truth_off needs a navigation scenario"):
        prepare(attitude, truth_off={"gravity"})
    navigation = kinds.load_scenario(DATA / "base_navigation.toml")
    with pytest.raises(InputError, match="unknown source"):
        prepare(navigation, truth_off={"baro"})


def test_observers_run_on_an_ins():
    """The tracking-failure probes of 000 §5 (a per-frame observer) on the image-fidelity SINS/CNS corpus base:
    the image chain's set-up and epilogue are the same for both kinds, so the probes' trials and their
    comparison rows reach a navigation run's summary."""
    prepared = prepare(DATA / "base_sins_cns.toml", {"faults.outages": [], "faults.attitude_jumps": [],
                                                        "faults.false_star_storms": []})
    summary = simulate(prepared, 3).summary
    assert summary["tracking_failure_probes"]["trials"] == 2
    assert 0.0 <= summary["tracking_failure_probes"]["subcatalog"]["recognition_rate"] <= 1.0
    assert summary.paper_comparison and "tracking_failure_probes" in summary.timing


def test_the_dim_star_comparison_needs_no_attitude_series_without_its_shadow():
    """An INS run's series has no attitude-filter error: without the shadow filter the comparison reports the
    stacked frames alone (a navigation run with stacked frames used to end in a KeyError)."""
    from navsim.studies.dim_star_comparison import DimStarComparison

    run = DimStarComparison(shadow=False).start(None, np.random.default_rng(0), 3)
    run._logs["stacked_uv_error_px"].append(np.array([0.1, -0.2]))  # one stacked frame's centroid error
    found = run.finish({"t": np.arange(3.0), "error_state": np.zeros((3, 15))}, np.ones(3, bool))
    assert found.stats["stacked_centroid"]["frames"] == 1 and "filter_with_stacking" not in found.stats


def test_the_shadow_filter_comparison_is_the_attitude_kinds():
    """004 §3's shadow filter copies the attitude filter; a navigation run keeps the solver comparison only."""
    with pytest.raises(InputError, match="star_sensor.image.compare_without_stacking: the shadow filter of 004 §3"):
        kinds.load_scenario(DATA / "base_sins_cns.toml", {"star_sensor.image.compare_without_stacking": True})


def test_a_filter_configuration_is_checked_where_it_is_built():
    with pytest.raises(InputError, match="filter.scale_factor: must be one of estimate, consider, ignore"):
        AttitudeFilterConfig(np.eye(6), 1e-6, 1e-9, scale_factor="estimated")
    with pytest.raises(InputError, match="P0 must be 9x9"):
        AttitudeFilterConfig(np.eye(6), 1e-6, 1e-9, scale_factor="consider")
    with pytest.raises(InputError, match="filter.gate_probability"):
        NavFilterConfig(np.eye(15), ImuNoise(arw=1e-5, vrw=1e-3), 0.01, gate_probability=1.0)
    config = AttitudeFilterConfig(np.eye(6) * 1e-6, 1e-6, 1e-9)
    with pytest.raises(ValueError):
        config.P0[0, 0] = 1.0  # the record is immutable; the filter works on its own copy
    filt = AttitudeFilter([0.0, 0.0, 0.0, 1.0], np.zeros(3), config)
    filt.predict(np.zeros((2, 3)), 0.01)
    assert config.P0[0, 0] == 1e-6 and filt.P[0, 0] > 1e-6
