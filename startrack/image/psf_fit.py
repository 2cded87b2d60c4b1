"""Star positions at the Cramér-Rao bound: the pixel model of a star image, its Fisher information, and the
maximum-likelihood fit that reaches it, with each position's covariance.

Pixel model (the one :mod:`startrack.image.render` draws): a star of flux N [DN] whose image moves uniformly by the
smear (Δu, Δv) [px] during the exposure, a Gaussian PSF of radius σ integrated over each unit pixel, on a
background b [DN]:

    μ_j(θ) = N P_j(u, v) + b,   P_j = (1/K) Σ_k F(c_j − u − s_k Δu) F(r_j − v − s_k Δv),              (1)
    F(d) = [erf((d + ½)/(√2 σ)) − erf((d − ½)/(√2 σ))] / 2,   s_k = (k + ½)/K − ½,

θ = (u, v, N, b), (u, v) the centre of the track (column, row: docs/design.md), the time integral of the
moving PSF by the midpoint rule with K points at most σ/4 apart. The noise of pixel j [DN²]:

    var_j = σ_n² + q + (μ_j − b)/g                                                               (2)

σ_n the background noise (read noise and the background's shot noise), q = 1/12 the rounding to whole DN,
and the star's own shot noise through the gain g [e-/DN] (Winick 1986's Poisson-plus-Gaussian noise as a
shifted Poisson variance). The Fisher information of θ (Winick 1986, eq. 17, with the read, background and
quantisation noise in the variance) and the bound on the position:

    J = Σ_j ∇μ_j ∇μ_jᵀ / var_j,   Σ_uv ≥ [J⁻¹]_uv (the 2 x 2 block of the inverse)                  (3)

with the flux and the background unknown (nuisance parameters). Its limits (tested): a bright star on no
background, σ_u² → (σ² + 1/12)/N_e for a PSF wide against the pixel (σ²/N_e unpixelated); background-limited,
σ_u² → 8π σ⁴ B / N_e² (B the background variance per pixel [e²]).

The fit (:func:`fit_stars`) maximises the likelihood of (1)-(2) by Gauss-Newton with the weights 1/var_j of
the current model (not of the data, which would bias it), over a window of half-width ⌈3σ + |Δ|/2⌉ + 1 px
around each start; its covariance is J⁻¹ at the estimate (u and v correlated along the smear). The χ² of
the residuals over the window tests the model: a blend, a hot pixel or a cosmic-ray hit leaves χ² above
the 99.9 % quantile of χ²(dof) and the star is flagged ``outlier`` with its covariance scaled by the
measured χ²/dof (nothing is inflated by a set factor); a window cut by the border of the frame (or of its
readout window) is flagged ``edge`` -- the model knows which pixels it has, so the fit stays unbiased and
its covariance grows with the light lost; pixels at saturation are left out of the fit and the star flagged
``saturated``; a fit that does not converge to a positive flux, within 2 px (and half the smear) of its
start and inside its window, is flagged ``failed`` and not used. A χ² test cannot see every blend: two trails
of a fast-turning camera overlap pixel for pixel, each faint per pixel, and the fit slides along the pair
with a χ² that looks like one star's. So a caller who knows where the other sources are (a catalog's
prediction, the other detections) passes them as ``neighbours``, and a star whose window another source's
light reaches (its track, smeared like the star's, within 5σ -- where the PSF holds 3e-7 of the light -- of
the window) is flagged ``blended`` and not used.
"""

import functools
import hashlib
import math
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from startrack.base.cache_dir import cache_dir, publish_file
from startrack.base.errors import InputError
from startrack.compiled.numba_setup import njit

#: Rounding of a pixel to whole DN: its variance [DN²].
_QUANTISATION_DN2 = 1.0 / 12.0
#: Track points per PSF radius of smear in (1) (the renderer's midpoint rule: startrack.image.render.SMEAR_STEP_SIGMA).
_TRACK_STEP_SIGMA = 0.25
#: Gauss-Newton stops when a step moves the position by less than this [px] ...
_STEP_TOLERANCE_PX = 1e-5
#: ... or after this many steps.
_MAX_STEPS = 30
#: Largest step [px] of the position, and its largest distance from the start [px] beyond half the smear
#: (a faint smeared star may be detected as a fragment of its trail; farther: ``failed``).
MAX_STEP_PX, MAX_SHIFT_PX = 1.0, 2.0
#: Probability of χ²(dof) below which a fit's residuals are the model's noise (above it: ``outlier``).
_OUTLIER_PROBABILITY = 0.999
#: Reach of a neighbour's light beyond its track [PSF radii] for the ``blended`` flag (the renderer's extent:
#: startrack.image.render.PSF_EXTENT_SIGMA).
_NEIGHBOUR_REACH_SIGMA = 5.0


@njit
def _profiles(first, count, centre, offsets, sigma):
    """F (1) and dF/dd on ``count`` pixels from ``first`` for each track point: (K, count) each, d the
    pixel's coordinate minus (``centre`` + offset_k)."""
    f = np.empty((offsets.size, count))
    g = np.empty((offsets.size, count))
    a = 1.0 / (math.sqrt(2.0) * sigma)
    c = 1.0 / (math.sqrt(2.0 * math.pi) * sigma)
    h = 0.5 / (sigma * sigma)
    for k in range(offsets.size):
        for i in range(count):
            d = first + i - centre - offsets[k]
            hi, lo = d + 0.5, d - 0.5
            f[k, i] = 0.5 * (math.erf(hi * a) - math.erf(lo * a))
            g[k, i] = c * (math.exp(-hi * hi * h) - math.exp(-lo * lo * h))
    return f, g


@njit
def _model(theta, r0, c0, rows, cols, su, sv, sigma):
    """μ (rows, cols) of (1) over the window [r0, r0 + rows) x [c0, c0 + cols) and ∇μ (rows, cols, 4)."""
    u, v, flux, background = theta[0], theta[1], theta[2], theta[3]
    fx, gx = _profiles(c0, cols, u, su, sigma)
    fy, gy = _profiles(r0, rows, v, sv, sigma)
    count = su.size
    mu = np.empty((rows, cols))
    grad = np.empty((rows, cols, 4))
    for i in range(rows):
        for j in range(cols):
            p = pu = pv = 0.0
            for k in range(count):
                p += fy[k, i] * fx[k, j]
                pu -= fy[k, i] * gx[k, j]
                pv -= gy[k, i] * fx[k, j]
            p, pu, pv = p / count, pu / count, pv / count
            mu[i, j] = flux * p + background
            grad[i, j, 0] = flux * pu
            grad[i, j, 1] = flux * pv
            grad[i, j, 2] = p
            grad[i, j, 3] = 1.0
    return mu, grad


@njit
def _normal_equations(data, valid, mu, grad, background, noise2, inv_gain):
    """(Σ ∇μ ∇μᵀ / var, Σ ∇μ (data − μ) / var, χ², valid pixels) over the valid pixels, var of (2)."""
    A = np.zeros((4, 4))
    y = np.zeros(4)
    chi2_sum = 0.0
    n = 0
    for i in range(mu.shape[0]):
        for j in range(mu.shape[1]):
            if not valid[i, j]:
                continue
            var = noise2 + max(mu[i, j] - background, 0.0) * inv_gain
            r = data[i, j] - mu[i, j]
            chi2_sum += r * r / var
            n += 1
            for a in range(4):
                y[a] += grad[i, j, a] * r / var
                for b in range(4):
                    A[a, b] += grad[i, j, a] * grad[i, j, b] / var
    return A, y, chi2_sum, n


@njit
def information(theta, r0, c0, rows, cols, su, sv, sigma, noise2, inv_gain):
    """The Fisher information J (4, 4) of θ = (u, v, N, b) over a window, eq. (3)."""
    mu, grad = _model(theta, r0, c0, rows, cols, su, sv, sigma)
    valid = np.ones((rows, cols), dtype=np.bool_)
    A, _, _, _ = _normal_equations(mu, valid, mu, grad, theta[3], noise2, inv_gain)
    return A


@njit
def _fit_window(data, valid, r0, c0, theta0, su, sv, sigma, noise2, inv_gain):
    """Gauss-Newton of eq. (1)-(2) on one window (``data`` (rows, cols) [DN] from pixel (r0, c0), ``valid``
    the pixels that count) from θ0. Returns (θ, J at θ, χ², valid pixels, converged)."""
    rows, cols = data.shape
    theta = theta0.copy()
    converged = False
    for _ in range(_MAX_STEPS):
        mu, grad = _model(theta, r0, c0, rows, cols, su, sv, sigma)
        A, y, _, _ = _normal_equations(data, valid, mu, grad, theta[3], noise2, inv_gain)
        step = np.linalg.solve(A, y)
        largest = max(abs(step[0]), abs(step[1]))
        if largest > MAX_STEP_PX:
            step *= MAX_STEP_PX / largest
        if theta[2] + step[2] <= 0.0:
            step *= 0.5 * theta[2] / max(-step[2], 1e-300)
        theta += step
        if largest < _STEP_TOLERANCE_PX:
            converged = True
            break
    mu, grad = _model(theta, r0, c0, rows, cols, su, sv, sigma)
    A, _, chi2_sum, n = _normal_equations(data, valid, mu, grad, theta[3], noise2, inv_gain)
    return theta, A, chi2_sum, n, converged


@dataclass(frozen=True)
class PixelNoise:
    """The noise of a pixel, eq. (2): the background noise σ_n [DN] (read noise and the background's shot
    noise), the gain [e-/DN] that gives a star's own shot noise (None: unknown, left out), and whether the
    pixels are rounded to whole DN (variance 1/12 DN²)."""

    sigma_n_dn: float
    gain_e_per_dn: float | None = None
    quantised: bool = True

    def __post_init__(self):
        if not (np.isfinite(self.sigma_n_dn) and self.sigma_n_dn >= 0.0):
            raise InputError(f"pixel noise sigma_n = {self.sigma_n_dn!r} DN must be a finite number >= 0")
        if self.gain_e_per_dn is not None and not (np.isfinite(self.gain_e_per_dn) and self.gain_e_per_dn > 0.0):
            raise InputError(f"gain = {self.gain_e_per_dn!r} e-/DN must be a finite number > 0")
        if self.variance_dn2 <= 0.0:
            raise InputError("pixel noise: a zero background noise needs the rounding to whole DN (quantised)")

    @property
    def variance_dn2(self):
        """σ_n² + q [DN²]: the variance of a pixel without a star."""
        return self.sigma_n_dn**2 + (_QUANTISATION_DN2 if self.quantised else 0.0)

    @property
    def inverse_gain(self):
        """1/g [DN/e-]: the factor of a star's charge in its variance (0 without a gain)."""
        return 0.0 if self.gain_e_per_dn is None else 1.0 / self.gain_e_per_dn


def track_offsets(smear_px, psf_sigma_px):
    """(su, sv) (K,) [px]: the track points of eq. (1) about the centre for the smear (Δu, Δv) [px]."""
    du, dv = (float(x) for x in smear_px)
    count = max(1, int(np.ceil(np.hypot(du, dv) / (_TRACK_STEP_SIGMA * psf_sigma_px))))
    s = (np.arange(count) + 0.5) / count - 0.5
    return s * du, s * dv


def half_width(psf_sigma_px, smear_px):
    """Half-width [px] of the fit window: ⌈3σ + |Δ|/2⌉ + 1."""
    return int(np.ceil(3.0 * psf_sigma_px + 0.5 * np.hypot(*smear_px))) + 1


def centroid_bound(uv, flux_dn, psf_sigma_px, noise, smear_px=(0.0, 0.0)):
    """The Cramér-Rao bound Σ_uv (2, 2) [px²] of eq. (3) on the position of a star at ``uv`` [px] of flux
    ``flux_dn`` [DN] with the PSF radius, pixel noise (:class:`PixelNoise`) and smear (Δu, Δv) [px] given;
    flux and background unknown. Over the pixels within 5σ + |Δ|/2 of the star (the rest hold no light)."""
    if not (flux_dn > 0.0 and psf_sigma_px > 0.0):
        raise InputError(f"the bound needs a positive flux and PSF radius, got {flux_dn!r} DN and {psf_sigma_px!r} px")
    su, sv = track_offsets(smear_px, psf_sigma_px)
    half = int(np.ceil(5.0 * psf_sigma_px + 0.5 * np.hypot(*smear_px))) + 1
    r0, c0 = int(np.rint(uv[1])) - half, int(np.rint(uv[0])) - half
    theta = np.array([uv[0], uv[1], flux_dn, 0.0], dtype=float)
    J = information(theta, r0, c0, 2 * half + 1, 2 * half + 1, su, sv, float(psf_sigma_px), noise.variance_dn2,
                    noise.inverse_gain)
    return np.linalg.inv(J)[:2, :2]


#: Grids of the tabulated bound (:func:`centroid_variance`): t = v/N [e⁻], a pixel's variance over the star's
#: charge, and the trail length [px]; the sub-pixel phases it is averaged over.
_BOUND_T = np.concatenate([np.logspace(-5.0, -3.0, 5)[:-1], np.logspace(-3.0, 1.0, 33)[:-1], np.logspace(1.0, 4.0, 7)])
_BOUND_SMEAR = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 24.0, 32.0, 40.0,
                         48.0, 64.0])
_BOUND_PHASES = (0.125, 0.375)
#: Bump when the table's computation changes (its cached files are keyed by it and the grids).
_BOUND_FORMAT = b"crb-table/1"


@functools.lru_cache(maxsize=16)
def _bound_table(psf_sigma_px):
    """N σ²(t, L) on the grids: the bound's mean variance over the two axes and the sub-pixel phases times the
    charge, a function of t = v/N and the trail alone (the Fisher information (3) scales as N at fixed v/N);
    computed once per PSF radius and grids (~2 s) and kept in the cache directory."""
    grids = np.concatenate([_BOUND_T, _BOUND_SMEAR, _BOUND_PHASES, [psf_sigma_px]])
    key = hashlib.sha256(grids.tobytes() + _BOUND_FORMAT).hexdigest()[:16]
    path = cache_dir() / f"crb-table-{key}.npy"
    try:
        return np.load(path, allow_pickle=False)
    except (OSError, ValueError):
        pass
    n = 1.0e6
    table = np.empty((_BOUND_T.size, _BOUND_SMEAR.size))
    for i, t in enumerate(_BOUND_T):
        noise = PixelNoise(math.sqrt(t * n), gain_e_per_dn=1.0, quantised=False)
        for j, length in enumerate(_BOUND_SMEAR):
            traces = [np.trace(centroid_bound((40.0 + du, 40.0 + dv), n, psf_sigma_px, noise, (length, 0.0)))
                      for du in _BOUND_PHASES for dv in _BOUND_PHASES]
            table[i, j] = 0.5 * n * np.mean(traces)
    publish_file(path, lambda temporary: np.save(temporary, table))
    return table


def centroid_variance(electrons, pixel_variance_e2, psf_sigma_px, smear_px=0.0):
    """The Cramér-Rao bound (3) on a star's position [px²] as one number per star: the mean over the two image
    axes and over the star's sub-pixel phase, for a charge ``electrons`` [e⁻] on pixels of variance
    ``pixel_variance_e2`` [e⁻²] (read noise and background shot noise), the PSF radius and a trail of
    ``smear_px`` [px] (up to 64). The bound is exactly h(v/N; σ, L)/N; h is tabulated once per PSF radius
    on 43 x 19 points (every 1/8 decade across the knee between the bright and the sky-limited star, 10⁻³ to 10; the
phases' 2 x 2 midpoints, within 0.1 % of a fine average) and its logarithm interpolated, linear in log(v/N)
and in L: within 2.5 % of the bound (tested; the L steps leave the most)."""
    n = np.asarray(electrons, dtype=float)
    table = np.log(_bound_table(float(psf_sigma_px)))
    log_t = np.log(np.clip(np.asarray(pixel_variance_e2, dtype=float) / n, _BOUND_T[0], _BOUND_T[-1]))
    length = np.clip(np.abs(np.asarray(smear_px, dtype=float)), 0.0, _BOUND_SMEAR[-1])
    log_t, length = np.broadcast_arrays(log_t, length)
    i = np.clip(np.searchsorted(np.log(_BOUND_T), log_t) - 1, 0, _BOUND_T.size - 2)
    j = np.clip(np.searchsorted(_BOUND_SMEAR, length) - 1, 0, _BOUND_SMEAR.size - 2)
    wt = (log_t - np.log(_BOUND_T[i])) / (np.log(_BOUND_T[i + 1]) - np.log(_BOUND_T[i]))
    wl = (length - _BOUND_SMEAR[j]) / (_BOUND_SMEAR[j + 1] - _BOUND_SMEAR[j])
    h = ((1 - wt) * (1 - wl) * table[i, j] + wt * (1 - wl) * table[i + 1, j]
         + (1 - wt) * wl * table[i, j + 1] + wt * wl * table[i + 1, j + 1])
    return np.exp(h) / n


@dataclass(frozen=True)
class StarFits:
    """The fits of N stars: positions ``uv`` (N, 2) [px], their covariance ``cov`` (N, 2, 2) [px²] (J⁻¹ at
    the estimate; an ``outlier``'s scaled by its χ²/dof), ``flux`` and ``background`` [DN], the fit's ``chi2``
    and ``dof``, and the flags of the module docstring: ``outlier``, ``edge``, ``saturated``, ``failed``,
    ``blended``."""

    uv: np.ndarray
    cov: np.ndarray
    flux: np.ndarray
    background: np.ndarray
    chi2: np.ndarray
    dof: np.ndarray
    outlier: np.ndarray
    edge: np.ndarray
    saturated: np.ndarray
    failed: np.ndarray
    blended: np.ndarray

    def __len__(self):
        return len(self.uv)

    @property
    def usable(self):
        """True for the fits whose position and covariance can be fused: those that converged alone in their
        window (a star cut by the border keeps the information of its pixels in the image, and its covariance
        says so)."""
        return ~(self.failed | self.blended)


def concatenate_fits(fits):
    """One :class:`StarFits` of the stars of several, in their order."""
    return StarFits(*(np.concatenate([getattr(f, name) for f in fits]) for name in StarFits.__dataclass_fields__))


def fit_stars(image, uv0, psf_sigma_px, noise, background_dn, smear_px=None, saturation_dn=None, origin=(0, 0),
              neighbours=None):
    """Fit eq. (1)-(2) to the stars starting at ``uv0`` (N, 2) [px, image coordinates] in ``image`` (2-D [DN],
    its top-left pixel at image row, column ``origin``: a full frame or one readout window).

    ``psf_sigma_px`` the PSF radius [px]; ``noise`` a :class:`PixelNoise`; ``background_dn`` the background's
    start value [DN] (fitted per star); ``smear_px`` (N, 2) or (2,) the smear of each star during the exposure
    [px] (None: none); ``saturation_dn`` the grey level of a saturated pixel (None: none); ``neighbours`` N
    arrays (M_k, 2) [px]: the centres of the other sources known near each star, smeared like it (None: none
    known). Returns :class:`StarFits`."""
    array = np.asarray(image, dtype=float)
    uv0 = np.atleast_2d(np.asarray(uv0, dtype=float)).reshape(-1, 2)
    if array.ndim != 2 or array.size == 0:
        raise InputError(f"fit_stars needs a 2-D image, got shape {array.shape}")
    if not (np.isfinite(psf_sigma_px) and psf_sigma_px > 0.0):
        raise InputError(f"PSF radius {psf_sigma_px!r} px must be a positive number")
    smear = np.zeros((len(uv0), 2)) if smear_px is None else np.broadcast_to(np.asarray(smear_px, float), (len(uv0), 2))
    others = [np.zeros((0, 2))] * len(uv0) if neighbours is None else [np.asarray(n, float).reshape(-1, 2) for n in neighbours]
    if len(others) != len(uv0):
        raise InputError(f"fit_stars got neighbours for {len(others)} stars but {len(uv0)} stars to fit")
    out = {name: [] for name in StarFits.__dataclass_fields__}
    for start, drift, near in zip(uv0, smear, others):
        _fit_one(array, start, drift, float(psf_sigma_px), noise, float(background_dn), saturation_dn, origin, out)
        out["blended"].append(bool(np.any(np.all(np.abs(near - np.rint(start)) <= neighbour_reach(psf_sigma_px, drift),
                                                 axis=1))))
    flags = ("outlier", "edge", "saturated", "failed", "blended")
    return StarFits(*(np.array(out[name], dtype=bool if name in flags else float)
                      .reshape((len(uv0),) + ((2,) if name == "uv" else (2, 2) if name == "cov" else ()))
                      for name in out))


def fit_detections(image, uv, psf_sigma_px, sigma_n_dn, background_dn, smear_px=None, gain_e_per_dn=None,
                   saturation_dn=None):
    """:func:`fit_stars` of a detector's detections at ``uv`` (N, 2) [px] in a full frame, each one's neighbours
    the other detections (a star whose window another one's light reaches is ``blended``), the pixel noise the
    frame's background noise ``sigma_n_dn`` [DN] as read (measured on the frame's pixels: the rounding to whole DN
    is in it) with the stars' shot noise through ``gain_e_per_dn`` (None: left out), the background's start
    ``background_dn`` [DN]; ``smear_px`` (Δu, Δv) [px] the trail of every star (None: none). What
    :func:`startrack.image.trail_detection.detect_trailed` and ``startrack detect`` fit."""
    uv = np.atleast_2d(np.asarray(uv, dtype=float)).reshape(-1, 2)
    noise = PixelNoise(sigma_n_dn, gain_e_per_dn=gain_e_per_dn, quantised=False)
    others = [np.delete(uv, k, axis=0) for k in range(len(uv))]
    return fit_stars(image, uv, psf_sigma_px, noise, background_dn, smear_px=smear_px, saturation_dn=saturation_dn,
                     neighbours=others)


def neighbour_reach(psf_sigma_px, smear_px):
    """(2,) [px]: how far from the centre of a star's fit window, per axis, the centre of another source smeared
    like it (``smear_px`` (Δu, Δv)) may lie and still send light into the window -- its track within
    _NEIGHBOUR_REACH_SIGMA σ of the window: the bounding boxes of the track and of the window, grown by that
    reach, overlap (the ``blended`` flag)."""
    smear = np.asarray(smear_px, dtype=float)
    return half_width(psf_sigma_px, smear) + 0.5 + _NEIGHBOUR_REACH_SIGMA * psf_sigma_px + 0.5 * np.abs(smear)


@functools.lru_cache(maxsize=4096)
def _outlier_chi2(dof):
    """The χ² above which a fit of ``dof`` degrees of freedom is an ``outlier`` (its 99.9 % quantile)."""
    return float(chi2.ppf(_OUTLIER_PROBABILITY, dof))


def _fit_one(array, start, drift, sigma, noise, background, saturation_dn, origin, out):
    """Fit one star (:func:`fit_stars`) and append its results to the lists of ``out``."""
    half = half_width(sigma, drift)
    height, width = array.shape
    row, col = int(np.rint(start[1])) - origin[0], int(np.rint(start[0])) - origin[1]
    top, bottom = max(row - half, 0), min(row + half + 1, height)
    left, right = max(col - half, 0), min(col + half + 1, width)
    edge = (top, bottom, left, right) != (row - half, row + half + 1, col - half, col + half + 1)
    data = array[top:bottom, left:right] if bottom > top and right > left else np.zeros((0, 0))
    valid = np.ones(data.shape, dtype=bool) if saturation_dn is None else data < saturation_dn
    saturated = bool(data.size) and not valid.all()
    su, sv = track_offsets(drift, sigma)
    theta0 = np.array([start[0], start[1], max(float(np.sum(data - background)), noise.sigma_n_dn + 1.0), background])
    failed, theta, cov, chi2_sum, dof = True, theta0, np.full((2, 2), np.nan), np.nan, 0
    if np.count_nonzero(valid) > 4:
        try:
            theta, J, chi2_sum, n, converged = _fit_window(data, valid, top + origin[0], left + origin[1], theta0, su,
                                                          sv, sigma, noise.variance_dn2, noise.inverse_gain)
            dof = n - 4
            shift = np.hypot(*(theta[:2] - start))
            inside = top - 0.5 <= theta[1] - origin[0] <= bottom - 0.5 and left - 0.5 <= theta[0] - origin[1] <= right - 0.5
            failed = not (converged and inside and theta[2] > 0.0 and shift <= MAX_SHIFT_PX + 0.5 * np.hypot(*drift))
            cov = np.linalg.inv(J)[:2, :2] if not failed else cov
        except np.linalg.LinAlgError:  # no star to fit (the flux collapsed to zero): nothing to estimate
            theta, failed = theta0, True
    outlier = bool(dof > 0 and not failed and chi2_sum > _outlier_chi2(dof))
    if outlier:
        cov = cov * chi2_sum / dof
    for name, value in (("uv", theta[:2]), ("cov", cov), ("flux", theta[2]), ("background", theta[3]),
                        ("chi2", chi2_sum), ("dof", dof), ("outlier", outlier), ("edge", edge),
                        ("saturated", saturated), ("failed", failed)):
        out[name].append(value)
