"""Static studies: star-sensor experiments of the source documents that need no trajectory.

A scenario file with a ``[study]`` table (``kind`` and the kind's own table of parameters) is a
static study; ``navsim run`` runs it like any scenario, writes ``summary.json`` (every point, our
figures beside the source document's in ``paper_comparison``) and ``study.npz``, and ``--report``
typesets it. Each kind is a module with ``PARAMETERS`` (its schema), ``run(params, seed, progress)``,
``text(summary, params)`` (the printed comparison), ``figures(summary, arrays, params)`` and
``key_results(summary, params)``.

Per-frame observers: experiments of the source documents that run inside a simulation — the
tracking-failure probes of 000 §5 (:mod:`~navsim.studies.tracking_failure_probes`) and the dim-star
comparison of 004 §3 (:mod:`~navsim.studies.dim_star_comparison`). A scenario registers one by the
table or option that asks for it (``wanted(scenario)``; :func:`observers` lists them); each has a seed-free part
(``build(scenario, sensor)``), a per-run part (``start(filter, rng, n_frames)``, which sees every
prediction and frame and lists the frames it wants read in full, then ``finish(series, steady)``) and
a campaign pool (``pool(run summaries)``). Their findings carry ``key``, ``stats``, ``rows`` (the
comparison table), ``notes`` and extra ``series``.
"""

import functools
import importlib
from collections.abc import Mapping

from navsim.scenario import checked_table, only_chosen
from navsim.scenario.schema import Table, Value
from navsim.studies.common import StudyResult


class _Modules(Mapping):
    """kind -> module of this package, imported on first use (a study's dependencies load only when
    that study runs)."""

    def __init__(self, kinds):
        self._kinds = tuple(kinds)

    def __getitem__(self, kind):
        if kind not in self._kinds:
            raise KeyError(kind)
        return importlib.import_module(f"{__name__}.{kind}")

    def __iter__(self):
        return iter(self._kinds)

    def __len__(self):
        return len(self._kinds)


#: study.kind -> module
STUDIES = _Modules(("attitude_precision", "contest_starmap"))


@functools.cache
def schema():
    """The schema of a static study: its kind and the kind's own parameters (built when first needed,
    so that validating one study imports every study module only once)."""
    return Table(
        {
            "name": Value("str"),
            "description": Value("str", default=""),
            "seed": Value("int", default=0, minimum=0),
            "study": Table({"kind": Value("str", choices=tuple(STUDIES))}
                           | {kind: Table(module.PARAMETERS.entries, optional=True)
                              for kind, module in STUDIES.items()}),
        }
    )


def validate(data, source):
    """The checked dictionary of a static study: the kind's own table (all defaults when absent), no
    other kind's table."""
    checked = checked_table(schema(), data, source)
    study = checked["study"]
    kind = study["kind"]
    only_chosen(study, "study", "kind", STUDIES, source)
    if kind not in study:
        study[kind] = STUDIES[kind].PARAMETERS.check(f"study.{kind}", {})
    return checked


def parameters(scenario):
    """The parameters of a static study's kind (a validated study scenario)."""
    return scenario["study"][scenario["study"]["kind"]]


def observers():
    """The per-frame observer kinds, in the order their findings appear in a summary."""
    from navsim.studies.dim_star_comparison import DimStarComparison
    from navsim.studies.tracking_failure_probes import TrackingFailureProbes

    return (TrackingFailureProbes, DimStarComparison)


__all__ = ["STUDIES", "StudyResult", "observers", "parameters", "schema", "validate"]
