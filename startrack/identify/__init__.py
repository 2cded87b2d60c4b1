"""Star identification: full-sky lost-in-space, predicted sub-catalog with redundant neighbours, tracking.

Modules: :mod:`~startrack.identify.features` (angular distances, the error gate of 001 §4.3.1),
:mod:`~startrack.identify.lost_in_space` (triangle and four-star-group search on the k-vector),
:mod:`~startrack.identify.verify` (prediction, one-to-one matching, SVD refit, false-match probability),
:mod:`~startrack.identify.subcatalog` (000 §4), :mod:`~startrack.identify.tracking`,
:mod:`~startrack.identify.result` (the result record) and :mod:`~startrack.identify.identifier`
(:class:`StarIdentifier`, the one call per frame).
"""

from startrack.identify.identifier import METHODS, Prior, StarIdentifier
from startrack.identify.result import IdentificationResult

__all__ = ["METHODS", "IdentificationResult", "Prior", "StarIdentifier"]
