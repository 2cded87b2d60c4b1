"""Faint trailed stars: the matched filter for a star whose trail over the exposure is known.

A star of flux N [DN] at (u, v) adds N t_j(u, v) to pixel j, t the renderer's own pixel model
(:mod:`startrack.image.render`, eq. (1) of :mod:`startrack.image.psf_fit`): the Gaussian PSF of radius σ
integrated over each unit pixel and averaged over the track points of the trail (Δu, Δv) [px] about the
track's centre.  On a background b with white Gaussian noise of variance v = σ_n² per pixel (the sky's shot
noise and the read noise, as :func:`startrack.image.detection.detect` measures them), the likelihood ratio of
"a star of unknown N at this pixel" against "no star" is a monotone function of the correlation of the
background-subtracted frame with the template, normalised here so that it is the SNR of the maximum-likelihood
amplitude (Kay 1998, ch. 4: the matched filter, the detector of a known signal in white Gaussian noise; for
a streak of known length and angle, the PSF-broadened line of Nir, Zackay & Ofek 2018 and Dawson et al. 2016):

    S(x) = Σ_j t_j (I_{x+j} − b) / (σ_n √(Σ_j t_j²)),   N̂ = Σ_j t_j (I_{x+j} − b) / Σ_j t_j²,               (1)

S = N̂ / σ(N̂).  Without a star S(x) is N(0, 1) at every pixel, correlated over the template's extent.  With a
star of flux N whose track centre lies at the sub-pixel offset φ from pixel x (its profile p_j = t_j(φ)):

    E[S] = μ = N Σ t p / (σ_n √(Σ t²)),   Var[S] = s² = 1 + N Σ t² p / (g σ_n² Σ t²)                     (2)

(the star's own shot noise through the gain g [e-/DN]; s = 1 without a gain), so the probability that S at the
star's pixel exceeds the threshold u is the closed form the measurements are compared with

    P_D(φ) = Q((u − μ(φ)) / s(φ)),   averaged over the sub-pixel phase φ,                                  (3)

the matched filter's P_D = Q(Q⁻¹(P_FA) − √(ε/σ²)) of Kay 1998 ch. 4 with its SNR at φ = 0 (the template centred
on the star: μ = N √(Σ t²)/σ_n, the optimal SNR) and the scalloping loss of a template on the pixel grid
elsewhere.  (The local maximum over the neighbouring pixels lifts the measured P_D slightly above (3).)

The threshold comes from the false alarms allowed per frame.  On a blank frame S is a stationary Gaussian field
of unit variance whose correlation at the pixel lag Δ is ρ(Δ) = Σ_j t_j t_(j+Δ) / Σ t² (:func:`lattice_correlation`).
A false detection is a pixel whose S exceeds u and its 8 neighbours.  Given S_0 = x at a pixel, its neighbours are
Gaussian with means ρ_k x and covariance C − ρ ρᵀ (C their own correlations), so with Z_k the neighbours less
those means and M = max_k Z_k / (1 − ρ_k) the pixel is a maximum when M < x, and

    E[N_fa](u) = H W ∫_u^∞ φ(x) P(M < x) dx = H W E_M[Q(max(u, M))],                                      (4)

the expectation over draws of M (200 000 from a fixed seed: the threshold is the same on every run; the draws'
relative error on the rate is below 0.3 %).  u solves E[N_fa](u) = ``false_alarms`` (default 0.01 per frame).  The continuous
field's expected Euler characteristic (Adler 1981; Worsley et al. 1996, the EC density of a Gaussian field
in 2-D), A √det Λ (2π)^(-3/2) u e^(−u²/2) with Λ = Σ ∇t ∇tᵀ / Σ t², counts maxima of the field between the
pixels too: for σ = 0.8 px it overstated the rate of this pixel grid 1.4-2.9 times at u = 4-4.5 for trails of
0-12 px (20 noise frames of 1024 x 1024 each), where (4) is within the Poisson scatter (tests/startrack/test_trail_detection.py, reports/trailed_detection.py).  The detector keeps
one peak per box (below), which at these levels are the same peaks; the frame's border rows count as background
beyond the frame and lower S's variance there (fewer false peaks, not more).

Detections: the pixels where S exceeds u and is the largest in the template's box (side 2h + 1, h the half-width
of the fit window, :func:`startrack.image.psf_fit.half_width`: non-maximum suppression over the template's
extent, so one trail is one detection); each peak refined by the stationary point of the quadratic fitted
to the 3 x 3 values of S around it, then (``fit=True``) handed to the position fit at the Cramér-Rao bound
(:func:`startrack.image.psf_fit.fit_detections`, the same pixel model, the trail as its smear) whose position,
flux and covariance replace the peak's where the fit converged.  The result is the :class:`Detections` of
:func:`startrack.image.detection.detect`, so it plugs into identification (fields in :func:`detect_trailed`).
"""

import functools

import numpy as np
from scipy import ndimage, optimize, signal
from scipy.special import ndtr

from startrack.base.errors import InputError
from startrack.image.detection import Detections, frame_background, validated_frame
from startrack.image.psf_fit import PixelNoise, centroid_bound, fit_detections, half_width, track_offsets
from startrack.image.render import Sources, expected_charge

#: Expected false detections per frame the default threshold allows (eq. 4).
FALSE_ALARMS_PER_FRAME = 0.01
#: Longest trail the template is built for [px].
MAX_TRAIL_PX = 256.0
#: Draws of the neighbours' margin M of eq. (4), and their seed (the threshold is the same on every run).
_MARGIN_DRAWS, _MARGIN_SEED = 200_000, 53
#: Sub-pixel phases (per axis) the closed form (3) is averaged over: midpoints of 8 bins across a pixel.
_PHASES = (np.arange(8) + 0.5) / 8 - 0.5


def trail_vector(length_px, angle_rad):
    """(Δu, Δv) [px] of a trail of ``length_px`` at ``angle_rad`` from the +u axis (towards +v)."""
    if not (np.isfinite(length_px) and length_px >= 0.0):
        raise InputError(f"trail length {length_px!r} px must be a finite number >= 0")
    if not np.isfinite(angle_rad):
        raise InputError(f"trail angle {angle_rad!r} rad must be finite")
    return float(length_px * np.cos(angle_rad)), float(length_px * np.sin(angle_rad))


def _checked(psf_sigma_px, trail_px):
    """(σ, (Δu, Δv)) as floats, or InputError naming the bad one."""
    if not (np.isfinite(psf_sigma_px) and psf_sigma_px > 0.0):
        raise InputError(f"PSF radius {psf_sigma_px!r} px must be a positive number")
    trail = np.asarray(trail_px, dtype=float)
    if trail.shape != (2,) or not np.all(np.isfinite(trail)):
        raise InputError(f"trail {trail_px!r} must be a finite (du, dv) vector [px]")
    if np.hypot(*trail) > MAX_TRAIL_PX:
        raise InputError(f"trail of {np.hypot(*trail):.1f} px is longer than the {MAX_TRAIL_PX:g} px the template is built for")
    return float(psf_sigma_px), (float(trail[0]), float(trail[1]))


def star_profile(psf_sigma_px, trail_px, offset_px=(0.0, 0.0)):
    """p (2h+1, 2h+1): the charge fraction per pixel of a star whose track centre lies ``offset_px`` (u, v) [px]
    from the centre pixel of a box of half-width h (:func:`startrack.image.psf_fit.half_width`) -- the
    renderer's :func:`~startrack.image.render.expected_charge` of a unit star on the track points of eq. (1) of
    :mod:`startrack.image.psf_fit`; light beyond the box (beyond 3σ + 1 px of the track) is left out."""
    sigma, trail = _checked(psf_sigma_px, trail_px)
    half = half_width(sigma, trail)
    su, sv = track_offsets(trail, sigma)
    track = np.stack([half + offset_px[0] + su, half + offset_px[1] + sv], axis=-1)[None]
    # the source charge alone: expected_charge reads no property of the sensor (noise, gain, bias come later)
    return expected_charge(None, 2 * half + 1, 2 * half + 1, [Sources(track, [1.0], sigma)])


def trail_template(psf_sigma_px, trail_px):
    """The matched filter's template t of eq. (1): the profile of a star centred on the box's centre pixel."""
    return star_profile(psf_sigma_px, trail_px)


def lattice_correlation(psf_sigma_px, trail_px):
    """ρ (4h+1, 4h+1): the correlation of the SNR field S of eq. (1) on blank frames at the pixel lags (Δr, Δc)
    about the centre, Σ_j t_j t_(j+Δ) / Σ t² (white pixel noise correlated by the template)."""
    t = trail_template(psf_sigma_px, trail_px)
    return signal.correlate(t, t, mode="full") / np.sum(t * t)


_NEIGHBOURS = np.array([(dr, dc) for dr in (-1, 0, 1) for dc in (-1, 0, 1) if (dr, dc) != (0, 0)])


@functools.lru_cache(maxsize=32)
def _maximum_margins(psf_sigma_px, trail_px):
    """Sorted draws of M = max_k Z_k / (1 − ρ_k) (eq. 4): Z the 8 neighbours of a pixel given its value x, less
    their conditional mean ρ_k x, Z ~ N(0, C − ρ ρᵀ); the pixel is a local maximum when M < x."""
    rho = lattice_correlation(psf_sigma_px, trail_px)
    centre = rho.shape[0] // 2
    at = _NEIGHBOURS + centre
    r = rho[at[:, 0], at[:, 1]]
    lags = _NEIGHBOURS[:, None, :] - _NEIGHBOURS[None, :, :] + centre
    conditional = rho[lags[..., 0], lags[..., 1]] - np.outer(r, r)
    values, vectors = np.linalg.eigh(conditional)
    root = vectors * np.sqrt(np.clip(values, 0.0, None))
    z = np.random.default_rng(_MARGIN_SEED).standard_normal((_MARGIN_DRAWS, r.size)) @ root.T
    return np.sort(np.max(z / (1.0 - r), axis=1))


def expected_false_peaks(threshold_snr, shape, psf_sigma_px, trail_px):
    """E[N_fa] of eq. (4): the expected number of pixels of a blank frame of ``shape`` (H, W) whose S exceeds
    ``threshold_snr`` and its 8 neighbours (the lattice's local maxima; :func:`detect_trailed` keeps one per
    box, which at these levels are the same peaks)."""
    sigma, trail = _checked(psf_sigma_px, trail_px)
    margins = _maximum_margins(sigma, trail)
    u = np.atleast_1d(np.asarray(threshold_snr, dtype=float))
    counts = [shape[0] * shape[1] * np.mean(ndtr(-np.maximum(x, margins))) for x in u]
    return counts[0] if np.ndim(threshold_snr) == 0 else np.array(counts)


def snr_threshold(false_alarms, shape, psf_sigma_px, trail_px):
    """u with E[N_fa](u) = ``false_alarms`` per frame of ``shape`` (eq. 4), in [1, 30]."""
    if not (np.isfinite(false_alarms) and 0.0 < false_alarms < 1e4):
        raise InputError(f"false_alarms = {false_alarms!r} per frame must be a number in (0, 1e4)")

    def excess(u):
        return np.log(expected_false_peaks(u, shape, psf_sigma_px, trail_px)) - np.log(false_alarms)

    if excess(1.0) <= 0.0:
        return 1.0
    return float(optimize.brentq(excess, 1.0, 30.0, xtol=1e-6))


def detection_probability(flux_dn, psf_sigma_px, trail_px, sigma_n_dn, threshold_snr, gain_e_per_dn=None):
    """P_D of eq. (3): the probability that S at the pixel nearest a star of ``flux_dn`` [DN] (a number or an array)
    exceeds ``threshold_snr``, averaged over 8 x 8 sub-pixel phases; and the optimal SNR μ(0) = N √(Σ t²)/σ_n.
    Returns (P_D, SNR_opt), each shaped like ``flux_dn``."""
    flux = np.asarray(flux_dn, dtype=float)
    t = trail_template(psf_sigma_px, trail_px)
    energy = np.sum(t * t)
    inverse_gain = 0.0 if gain_e_per_dn is None else 1.0 / gain_e_per_dn
    total = np.zeros(flux.shape)
    for phase_u in _PHASES:
        for phase_v in _PHASES:
            p = star_profile(psf_sigma_px, trail_px, (phase_u, phase_v))
            mu = flux * np.sum(t * p) / (sigma_n_dn * np.sqrt(energy))
            s = np.sqrt(1.0 + flux * inverse_gain * np.sum(t * t * p) / (sigma_n_dn**2 * energy))
            total += ndtr((mu - threshold_snr) / s)
    return total / _PHASES.size**2, flux * np.sqrt(energy) / sigma_n_dn


def _levels(array, background, sigma_n, mesh_px):
    """(b, σ_n, median b, median σ_n): numbers, or per-pixel maps (H, W) for a mesh, of the frame's
    :func:`~startrack.image.detection.frame_background` (σ_n > 0: it divides eq. 1).  A mesh's cells are measured
    on every pixel, not on 004's subsample of 256: a level off by δb moves S by δb Σt / (σ_n √Σt²), 4.6 δb/σ_n
    for a 6 px trail, and the 256 pixels' error (σ_n/16, and σ_n's own 4 %) spread S on blank frames to a standard
    deviation of 1.02 and lifted the false detections 2.6 times at 2 per frame (issue 64)."""
    found = frame_background(array, background, sigma_n, mesh_px, every_pixel=True)
    if found.level.size == 1:
        b, s = found.median_level, found.median_sigma
    else:
        b = found.threshold(0.0)
        s = found.threshold(1.0) - b
    if not np.all(s > 0):
        raise InputError(f"sigma_n {found.median_sigma!r} DN must be > 0")
    return b, s, found.median_level, found.median_sigma


def snr_map(image, psf_sigma_px, trail_px=(0.0, 0.0), background=None, sigma_n=None, mesh_px=None):
    """S (H, W) float32 of eq. (1) for every pixel (FFT correlation; the frame beyond its border counts as
    background), with the background b and noise σ_n given, estimated for the frame, or on a mesh of ``mesh_px``
    cells (:mod:`startrack.image.background`).  Returns (S, N̂ [DN], b, σ_n) (b, σ_n numbers or maps)."""
    array = validated_frame(image).astype(np.float32)
    template = trail_template(psf_sigma_px, trail_px)
    b, s, _, _ = _levels(array, background, sigma_n, mesh_px)
    energy = float(np.sum(template * template))
    kernel = (template[::-1, ::-1] / energy).astype(np.float32)
    amplitude = signal.fftconvolve(array - np.float32(b) if np.ndim(b) == 0 else array - b, kernel, mode="same")
    snr = amplitude * np.float32(np.sqrt(energy)) / (np.float32(s) if np.ndim(s) == 0 else s)
    return snr.astype(np.float32), amplitude, b, s


def _quadratic_peak(snr, rows, cols):
    """(du, dv) [px] of the stationary point of the quadratic fitted to the 3 x 3 values of ``snr`` around each
    peak (least squares on the 9 points; within ±1 px; 0 at the frame border or where the quadratic has no
    maximum)."""
    height, width = snr.shape
    inside = (rows > 0) & (rows < height - 1) & (cols > 0) & (cols < width - 1)
    offsets = np.zeros((rows.size, 2))
    if not inside.any():
        return offsets
    r, c = rows[inside], cols[inside]
    y, x = np.mgrid[-1:2, -1:2]
    f = snr[r[:, None, None] + y, c[:, None, None] + x].astype(float)  # (n, 3, 3)
    b = np.sum(x * f, axis=(1, 2)) / 6.0
    cv = np.sum(y * f, axis=(1, 2)) / 6.0
    d = np.sum((x * x - 2.0 / 3.0) * f, axis=(1, 2)) / 2.0
    e = np.sum((y * y - 2.0 / 3.0) * f, axis=(1, 2)) / 2.0
    g = np.sum(x * y * f, axis=(1, 2)) / 4.0
    det = 4.0 * d * e - g * g
    maximum = (d < 0) & (det > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        du = np.where(maximum, (-2.0 * e * b + g * cv) / det, 0.0)
        dv = np.where(maximum, (-2.0 * d * cv + g * b) / det, 0.0)
    offsets[inside] = np.clip(np.stack([du, dv], axis=-1), -1.0, 1.0)
    return offsets


def detect_trailed(image, psf_sigma_px, trail_px=(0.0, 0.0), background=None, sigma_n=None, mesh_px=None,
                   false_alarms=FALSE_ALARMS_PER_FRAME, threshold_snr=None, saturation_dn=None, fit=True,
                   gain_e_per_dn=None):
    """Detect the stars of a frame whose trail (Δu, Δv) [px] over the exposure is known (module text).

    image: 2-D [DN]; psf_sigma_px: the Gaussian PSF radius [px]; trail_px: (Δu, Δv) [px] (0 for a still star;
    :func:`trail_vector` from a length and angle); background, sigma_n [DN]: given, or estimated as
    :func:`startrack.image.detection.detect` does (one level, or a mesh of ``mesh_px`` cells, each measured on
    all its pixels); false_alarms: expected false detections per frame (eq. 4) that set the SNR threshold, or
    ``threshold_snr`` given;
    saturation_dn: grey level of a saturated pixel (flag, and left out of the fit); fit: hand each peak to
    :func:`startrack.image.psf_fit.fit_detections` for its position at the bound; gain_e_per_dn: the star's own shot
    noise in the fit (None: left out).

    Returns :class:`~startrack.image.detection.Detections`, brightest first: u, v [px] (the fit's where it
    converged, else the refined peak); flux N̂ [DN] (the fit's, else eq. 1); peak: the grey level at the peak
    pixel; npix: pixels of S above the threshold in the peak's box; snr: S at the peak (eq. 1: the matched
    filter's SNR, not 004's peak SNR); saturated; edge (the box meets the frame border); background, sigma_n
    (medians for a mesh) and threshold: the noise-free peak grey level b + N_min max(t) of a star at the SNR
    threshold (N_min = u σ_n / √(Σ t²)), to set beside 004's V_th; sigma_u, sigma_v: the fit's σ, or the
    Cramér-Rao bound at N̂ where it failed (or without ``fit``); single_pixel, extended False and size,
    elongation NaN (no shape test: the template is the star's shape).
    """
    array = validated_frame(image).astype(np.float32)
    sigma, trail = _checked(psf_sigma_px, trail_px)
    if threshold_snr is None:
        threshold_snr = snr_threshold(false_alarms, array.shape, sigma, trail)
    elif not (np.isfinite(threshold_snr) and threshold_snr > 0):
        raise InputError(f"threshold_snr = {threshold_snr!r} must be a positive number")
    snr, amplitude, b, s = snr_map(array, sigma, trail, background, sigma_n, mesh_px)
    b_median, s_median = (float(np.median(x)) for x in (b, s))
    template = trail_template(sigma, trail)
    half = template.shape[0] // 2
    n_min = threshold_snr * s_median / np.sqrt(np.sum(template * template))
    level = b_median + n_min * float(template.max())
    box = 2 * half + 1
    rows, cols = np.nonzero((snr > threshold_snr) & (snr == ndimage.maximum_filter(snr, size=box, mode="constant",
                                                                                      cval=-np.inf)))
    if rows.size == 0:
        f, e = np.zeros(0), np.zeros(0, dtype=bool)
        return Detections(f, f, f, f, np.zeros(0, np.int64), f, e, e, b_median, s_median, level, f, f, e, f, f, e)
    offset = _quadratic_peak(snr, rows, cols)
    uv = np.stack([cols + offset[:, 0], rows + offset[:, 1]], axis=-1)
    flux = amplitude[rows, cols].astype(float)
    height, width = array.shape
    edge = (rows < half) | (rows >= height - half) | (cols < half) | (cols >= width - half)
    counts = ndimage.uniform_filter((snr > threshold_snr).astype(np.float32), size=box, mode="constant")
    npix = np.rint(counts[rows, cols] * box * box).astype(np.int64)
    peak = array[rows, cols].astype(float)
    saturated = peak >= saturation_dn if saturation_dn is not None else np.zeros(rows.size, dtype=bool)
    noise = PixelNoise(s_median, gain_e_per_dn=gain_e_per_dn, quantised=False)
    sigma_uv = np.full((rows.size, 2), np.nan)
    if fit:
        fits = fit_detections(array, uv, sigma, s_median, b_median, trail, gain_e_per_dn, saturation_dn)
        good = fits.usable
        uv[good], flux[good] = fits.uv[good], fits.flux[good]
        sigma_uv[good] = np.sqrt(np.diagonal(fits.cov[good], axis1=1, axis2=2))
    for k in np.flatnonzero(np.isnan(sigma_uv[:, 0]) & (flux > 0)):
        sigma_uv[k] = np.sqrt(np.diag(centroid_bound(uv[k], flux[k], sigma, noise, trail)))
    order = np.argsort(-flux, kind="stable")
    no = np.zeros(rows.size, dtype=bool)
    nan = np.full(rows.size, np.nan)
    return Detections(uv[order, 0], uv[order, 1], flux[order], peak[order], npix[order], snr[rows, cols][order].astype(float),
                      saturated[order], edge[order], b_median, s_median, level, sigma_uv[order, 0], sigma_uv[order, 1],
                      no, nan, nan, no)
