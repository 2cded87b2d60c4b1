"""The records of spacecraft runs and campaigns (:mod:`navsim.records`): the attitude kind's figures, and what a
spacecraft adds — each head's availability and the fused accuracy about its own boresight, the orbit, the pointing
and the wheels.

Units at this edge: attitude in arcsec, gyro bias in deg/h, heights in km, angles in deg, momentum in N m s.
"""

from dataclasses import dataclass
from typing import ClassVar

from navsim.attitude import records as attitude_records


@dataclass(frozen=True, kw_only=True)
class RunSummary(attitude_records.RunSummary):
    """A spacecraft run: the attitude kind's figures (``cross_boresight`` and ``roll`` about the first head's
    boresight) and ``heads``: per head its name, the frames it measured and the frames each exclusion took, its stars
    per frame, the fused attitude's cross-boresight and roll RMS in its axes and their ratio, its mounting error
    (truth, estimate, σ, normalised); ``orbit``: propagator, heights, speed, the time in the Earth's shadow;
    ``pointing``: the law, the truth's error from it, body rates, the wheels' momentum and saturation."""

    kind: ClassVar[str] = "spacecraft"

    heads: list
    orbit: dict
    pointing: dict


@dataclass(frozen=True, kw_only=True)
class CampaignSummary(attitude_records.CampaignSummary):
    """A spacecraft campaign: the attitude kind's pooled figures and per head the spread of its cross-boresight and
    roll RMS, its availability and the normalised errors of its mounting states."""

    heads: list | None = None
