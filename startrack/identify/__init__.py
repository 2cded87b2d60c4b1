"""Star identification: full-sky lost-in-space, predicted sub-catalog with redundant neighbours, tracking.

Modules: :mod:`~startrack.identify.features` (centroid directions, angular distances, the error gate
of 001 §4.3.1), :mod:`~startrack.identify.pairs` (pair tables: k-vector of 000 eq. 3-5, the
sub-catalogs' pairs), :mod:`~startrack.identify.pyramid` (the compiled triangle/pyramid search),
:mod:`~startrack.identify.zones` (declination-zone index of the field stars),
:mod:`~startrack.identify.verify` (prediction, one-to-one matching, SVD refit, false-match probability),
:mod:`~startrack.identify.lost_in_space` (full sky), :mod:`~startrack.identify.subcatalog` (000 §4),
:mod:`~startrack.identify.tracking`, :mod:`~startrack.identify.context` (what the strategies share),
:mod:`~startrack.identify.prior` (what is known before a frame),
:mod:`~startrack.identify.kernel_loading` (kernels loaded at construction), :mod:`~startrack.identify.result`
(the result record), :mod:`~startrack.identify.identifier` (:class:`StarIdentifier`, the one call
per frame; each strategy is one compiled call) and :mod:`~startrack.identify.calibrated`
(:class:`CalibratedSolver`: catalog and identifier built for a camera, frames taken as the plate solver
takes them).

Without a calibrated camera (issue 18): :mod:`~startrack.identify.pattern_catalog` (four-star patterns
keyed by edge ratios, by scale level), :mod:`~startrack.identify.scale_free` (the compiled pattern
search), :mod:`~startrack.identify.self_calibration` (verification that fits the camera),
:mod:`~startrack.identify.chance` (the false-match probability from the local density of the
detections) and :mod:`~startrack.identify.plate_solver` (:class:`PlateSolver`).  Names are imported
on first use (PEP 562), so a plate solve loads none of the calibrated identifier's tables.
"""

from startrack.base.lazy_exports import lazy_exports

__getattr__, __dir__, __all__ = lazy_exports(__name__, {
    "startrack.identify.calibrated": ("CalibratedSolver",),
    "startrack.identify.identifier": ("METHODS", "StarIdentifier"),
    "startrack.identify.prior": ("Prior",),
    "startrack.identify.plate_solver": ("PlateSolver",),
    "startrack.identify.result": ("IdentificationResult",),
})
