"""Star identification: full-sky lost-in-space, predicted sub-catalog with redundant neighbours, tracking.

Modules: :mod:`~startrack.identify.features` (centroid directions, angular distances, the error gate
of 001 §4.3.1), :mod:`~startrack.identify.pairs` (pair tables: k-vector of 000 eq. 3-5, the
sub-catalogs' pairs), :mod:`~startrack.identify.pyramid` (the compiled triangle/pyramid search),
:mod:`~startrack.identify.zones` (declination-zone index of the field stars),
:mod:`~startrack.identify.verify` (prediction, one-to-one matching, SVD refit, false-match probability),
:mod:`~startrack.identify.lost_in_space` (full sky), :mod:`~startrack.identify.subcatalog` (000 §4),
:mod:`~startrack.identify.tracking`, :mod:`~startrack.identify.context` (what the strategies share),
:mod:`~startrack.identify.warmup` (kernels loaded at construction), :mod:`~startrack.identify.result`
(the result record) and :mod:`~startrack.identify.identifier` (:class:`StarIdentifier`, the one call
per frame; each strategy is one compiled call).
"""

from startrack.identify.identifier import METHODS, Prior, StarIdentifier
from startrack.identify.result import IdentificationResult

__all__ = ["METHODS", "IdentificationResult", "Prior", "StarIdentifier"]
