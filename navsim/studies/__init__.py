"""Static studies: star-sensor experiments of the source documents that need no trajectory.

A scenario file with a ``[study]`` table (``kind`` and the kind's own table of parameters) is a
static study; ``navsim run`` runs it like any scenario, writes ``summary.json`` (every point, our
figures beside the source document's in ``paper_comparison``) and ``study.npz``, and ``--report``
typesets it. Each kind is a module with ``PARAMETERS`` (its schema), ``run(params, seed, progress)``,
``text(summary, params)`` (the printed comparison), ``figures(summary, arrays, params)`` and
``key_results(summary, params)``.
"""

from navsim.studies import attitude_precision, contest_starmap
from navsim.studies.common import StudyResult

#: study.kind -> module
STUDIES = {"attitude_precision": attitude_precision, "contest_starmap": contest_starmap}

__all__ = ["STUDIES", "StudyResult"]
