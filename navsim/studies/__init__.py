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
table or option that asks for it (``wanted(scenario)``); each has a seed-free part
(``build(scenario, sensor)``), a per-run part (``start(filter, rng, n_frames)``, which sees every
prediction and frame and lists the frames it wants read in full, then ``finish(series, steady)``) and
a campaign pool (``pool(run summaries)``). Their findings carry ``key``, ``stats``, ``rows`` (the
comparison table), ``notes`` and extra ``series``.
"""

from navsim.studies import attitude_precision, contest_starmap
from navsim.studies.common import StudyResult
from navsim.studies.dim_star_comparison import DimStarComparison
from navsim.studies.tracking_failure_probes import TrackingFailureProbes

#: study.kind -> module
STUDIES = {"attitude_precision": attitude_precision, "contest_starmap": contest_starmap}
#: Per-frame observers, in the order their findings appear in a summary.
OBSERVERS = (TrackingFailureProbes, DimStarComparison)

__all__ = ["OBSERVERS", "STUDIES", "StudyResult"]
