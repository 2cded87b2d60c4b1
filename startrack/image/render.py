"""Star-image rendering: one code path for a full frame and for windows.

Each source (star, planet, stray-light blob, cosmic-ray track) is a set of
positions along its image track during the exposure.  Its expected charge in
pixel (r, c) is the Gaussian PSF of radius sigma integrated over the pixel's
unit square (erf, separable) and averaged over the K track positions, i.e.
the time integral of the moving PSF by the midpoint rule:

    E[r, c] = N_e / K * sum_k  F(c - u_k) F(r - v_k),
    F(d) = [erf((d + 1/2)/(sqrt2 sigma)) - erf((d - 1/2)/(sqrt2 sigma))] / 2.

Only the (2h+1)^2 pixels near each source are evaluated; noise is then drawn
for the whole canvas in one vectorised pass:

    electrons = Poisson(E_sources + E_hot) + (sky + dark) t_exp
                + sqrt((sky + dark) t_exp + sigma_read^2) * z,   z ~ N(0, 1)

(the uniform sky/dark shot noise is merged with the read noise as a
Gaussian, exact for the read-noise-dominated sensors simulated here; the
charge of sources and hot pixels is drawn from the Poisson law).  With
``shot_noise=False`` the noise is 004's white Gaussian N(0, sigma_read^2).
The charge is converted to DN by the gain and offset by the bias; the grey
level is clipped at the saturation level (the full well or the ADC full
scale - 1, whichever is lower) and at 0, and rounded: uint16 output.  A full frame is the canvas (1, H, W) with origin (0, 0);
window mode is the canvas (M, s, s) with the windows' origins.
"""

from dataclasses import dataclass, field
from functools import lru_cache

import numpy as np
from scipy.special import erf

from startrack.base.errors import InputError
from startrack.photometry.star_signal import star_electrons

#: PSF half-extent in sigmas evaluated around each track point (flux beyond it < 1e-6).
PSF_EXTENT_SIGMA = 5.0
#: Track sampling step as a fraction of the PSF radius (midpoint rule of the smear integral).
SMEAR_STEP_SIGMA = 0.25
#: Upper bound on track sub-steps per exposure.
_MAX_SMEAR_STEPS = 512


@dataclass(frozen=True)
class SensorModel:
    """Detector and electronics of the star sensor (units in the names).

    Defaults: 004's Gaussian radius sigma_r = 0.671 px and 12-bit ADC (full
    scale 4096), bias 100 DN and read noise 10 DN as 004's b and sigma_n, and
    a zero point giving a magnitude-6 star about 25 sigma_n of peak.
    """

    psf_sigma_px: float = 0.671
    exposure_s: float = 0.1
    zero_point_e_per_s: float = 5.0e6
    transmission: float = 0.8
    gain_e_per_dn: float = 2.0
    bias_dn: float = 100.0
    read_noise_e: float = 20.0
    dark_e_per_px_s: float = 20.0
    sky_e_per_px_s: float = 0.0
    full_well_e: float = 60000.0
    full_scale_dn: int = 4096
    shot_noise: bool = True
    hot_pixel_count: int = 0
    hot_pixel_e_per_s: float = 5.0e4
    fixed_pattern_seed: int = 0

    def __post_init__(self):
        positive = ("psf_sigma_px", "zero_point_e_per_s", "gain_e_per_dn", "full_well_e", "full_scale_dn")
        for name in positive:
            value = getattr(self, name)
            if not np.isfinite(value) or value <= 0:
                raise InputError(f"sensor {name} must be positive, got {value!r}")
        non_negative = (
            "exposure_s", "bias_dn", "read_noise_e", "dark_e_per_px_s", "sky_e_per_px_s",
            "hot_pixel_count", "hot_pixel_e_per_s",
        )
        for name in non_negative:
            value = getattr(self, name)
            if not np.isfinite(value) or value < 0:
                raise InputError(f"sensor {name} must be >= 0, got {value!r}")
        if not 0 < self.transmission <= 1:
            raise InputError(f"sensor transmission must be in (0, 1], got {self.transmission!r}")
        if self.full_scale_dn > 65536:
            raise InputError(f"sensor full_scale_dn must fit 16 bits (<= 65536), got {self.full_scale_dn!r}")

    @property
    def background_e(self):
        """Mean uniform background charge per pixel [e-]: (sky + dark) t_exp."""
        return (self.sky_e_per_px_s + self.dark_e_per_px_s) * self.exposure_s

    @property
    def background_dn(self):
        """Mean background grey level b [DN]: bias + background charge / gain."""
        return self.bias_dn + self.background_e / self.gain_e_per_dn

    @property
    def noise_dn(self):
        """Background noise sigma_n [DN]: sqrt(read^2 + shot of background) / gain."""
        shot = self.background_e if self.shot_noise else 0.0
        return np.sqrt(self.read_noise_e**2 + shot) / self.gain_e_per_dn

    @property
    def saturation_dn(self):
        """Highest grey level a pixel can take [DN]: ADC full scale or full well, whichever first."""
        return float(min(self.full_scale_dn - 1, np.floor(self.bias_dn + self.full_well_e / self.gain_e_per_dn)))

    def star_electrons(self, v_mag):
        """Photoelectrons per exposure of stars of magnitude ``v_mag`` (Pogson, see photometry)."""
        return star_electrons(v_mag, self.zero_point_e_per_s, self.exposure_s, self.transmission)

    def hot_pixels(self, height, width):
        """(rows, cols) of the hot pixels of a height x width array (fixed pattern from its seed)."""
        return _hot_pixels(int(height), int(width), int(self.hot_pixel_count), int(self.fixed_pattern_seed))


@lru_cache(maxsize=16)
def _hot_pixels(height, width, count, seed):
    rng = np.random.default_rng(np.random.SeedSequence(seed).spawn(1)[0])
    flat = rng.choice(height * width, size=min(count, height * width), replace=False)
    rows, cols = np.divmod(flat, width)
    rows.setflags(write=False)
    cols.setflags(write=False)
    return rows, cols


@dataclass(frozen=True)
class Sources:
    """Light sources of one exposure: tracks (N, K, 2) [px, (u, v)], charge (N,) [e-], PSF radius [px]."""

    tracks: np.ndarray
    electrons: np.ndarray
    sigma_px: float
    kind: str = "star"

    def __post_init__(self):
        tracks = np.asarray(self.tracks, dtype=float)
        if tracks.ndim == 2:
            tracks = tracks[:, None, :]
        electrons = np.atleast_1d(np.asarray(self.electrons, dtype=float))
        if tracks.ndim != 3 or tracks.shape[2] != 2 or tracks.shape[0] != electrons.shape[0]:
            raise InputError(
                f"{self.kind} sources need tracks of shape (N, K, 2) and N charges, got {tracks.shape} and {electrons.shape}"
            )
        if not (np.all(np.isfinite(tracks)) and np.all(np.isfinite(electrons)) and np.all(electrons >= 0)):
            raise InputError(f"{self.kind} sources need finite positions and non-negative charges")
        if not self.sigma_px > 0:
            raise InputError(f"{self.kind} source radius must be positive, got {self.sigma_px!r} px")
        object.__setattr__(self, "tracks", tracks)
        object.__setattr__(self, "electrons", electrons)

    @property
    def centroids(self):
        """True image centroids (N, 2): time average of each track."""
        return self.tracks.mean(axis=1)


def stray_light(u, v, radius_px, electrons):
    """A stray-light blob: a wide Gaussian of radius ``radius_px`` holding ``electrons``."""
    return Sources(np.array([[[u, v]]], dtype=float), [electrons], radius_px, kind="stray light")


def planet(u, v, electrons, sigma_px):
    """A planet: a point source not in the star catalog, imaged by the same PSF."""
    return Sources(np.array([[[u, v]]], dtype=float), [electrons], sigma_px, kind="planet")


def cosmic_ray(u0, v0, u1, v1, electrons, width_px=0.35):
    """A cosmic-ray track: charge spread evenly along the segment (u0, v0)-(u1, v1), no optics."""
    length = float(np.hypot(u1 - u0, v1 - v0))
    steps = max(2, int(np.ceil(length / (SMEAR_STEP_SIGMA * width_px))))
    s = (np.arange(steps) + 0.5) / steps
    track = np.stack([u0 + s * (u1 - u0), v0 + s * (v1 - v0)], axis=-1)
    return Sources(track[None], [electrons], width_px, kind="cosmic ray")


@dataclass(frozen=True)
class Windows:
    """Square windows of side ``size`` px with top-left pixels (row0, col0) (M,)."""

    row0: np.ndarray
    col0: np.ndarray
    size: int

    @classmethod
    def around(cls, uv, half_width, height, width):
        """Windows of side 2l+1 centred on the pixels nearest ``uv`` (M, 2), moved inside the image."""
        uv = np.atleast_2d(np.asarray(uv, dtype=float))
        size = 2 * int(half_width) + 1
        if size > min(height, width):
            raise InputError(f"window side {size} px does not fit a {width} x {height} image")
        col0 = np.clip(np.rint(uv[:, 0]).astype(np.int64) - half_width, 0, width - size)
        row0 = np.clip(np.rint(uv[:, 1]).astype(np.int64) - half_width, 0, height - size)
        return cls(row0, col0, size)


@dataclass(frozen=True)
class _Canvas:
    """Pixels being rendered: M arrays of h x w with their image origins."""

    row0: np.ndarray
    col0: np.ndarray
    height: int
    width: int

    @classmethod
    def full_frame(cls, height, width):
        return cls(np.zeros(1, np.int64), np.zeros(1, np.int64), int(height), int(width))

    @classmethod
    def from_windows(cls, windows):
        return cls(np.asarray(windows.row0, np.int64), np.asarray(windows.col0, np.int64), windows.size, windows.size)


def _patch_geometry(tracks, sigma_px):
    """Anchor pixels (N, 2) [col, row] of the sources and the common patch half-size h."""
    anchor = np.rint(tracks.mean(axis=1)).astype(np.int64)
    extent = np.max(np.abs(tracks - anchor[:, None, :]))
    return anchor, int(np.ceil(extent + PSF_EXTENT_SIGMA * sigma_px))


def _source_patches(tracks, electrons, sigma_px, anchor, half):
    """Expected charge on the (2h+1)^2 pixels around each source (erf pixel integral, track average).

    Returns (rows (N, P), cols (N, P), patches (N, P, P)) with P = 2h + 1.
    """
    offsets = np.arange(-half, half + 1)
    edges = np.arange(-half, half + 2) - 0.5  # P + 1 pixel edges relative to the anchor
    scale = 1.0 / (np.sqrt(2.0) * sigma_px)
    rel = anchor[:, None, :] - tracks  # (N, K, 2): anchor minus track point
    cdf_u = 0.5 * erf((edges[None, None, :] + rel[:, :, 0, None]) * scale)  # (N, K, P+1)
    cdf_v = 0.5 * erf((edges[None, None, :] + rel[:, :, 1, None]) * scale)
    fu = np.diff(cdf_u, axis=-1)
    fv = np.diff(cdf_v, axis=-1)
    patches = np.einsum("nkj,nki->nji", fv, fu) * (electrons / tracks.shape[1])[:, None, None]
    return anchor[:, 1, None] + offsets, anchor[:, 0, None] + offsets, patches


def _touching(canvas, anchor, half):
    """Sources whose (2h+1)^2 patch overlaps at least one canvas array."""
    col, row = anchor[:, 0, None], anchor[:, 1, None]
    overlap = ((row + half >= canvas.row0) & (row - half < canvas.row0 + canvas.height)
               & (col + half >= canvas.col0) & (col - half < canvas.col0 + canvas.width))
    return np.flatnonzero(overlap.any(axis=1))


def _scatter(canvas, expected, rows, cols, values):
    """Add values at image pixels (rows, cols) (broadcast together: a leading axis of sources, then each source's
    pixels) to every canvas array containing them. Only the (array, source) pairs whose bounding boxes overlap are
    formed, in the order of the full product (array, then source, then pixel), so every pixel's sum is the one the
    full product gives, to the bit, for a fraction of the work when a frame's windows are many."""
    rows, cols, values = np.broadcast_arrays(rows, cols, values)
    n = rows.shape[0] if rows.ndim else 1
    rows, cols, values = rows.reshape(n, -1), cols.reshape(n, -1), values.reshape(n, -1)
    lo_r, hi_r, lo_c, hi_c = rows.min(axis=1), rows.max(axis=1), cols.min(axis=1), cols.max(axis=1)
    r0, c0 = canvas.row0[:, None], canvas.col0[:, None]
    m, k = np.nonzero((hi_r >= r0) & (lo_r < r0 + canvas.height) & (hi_c >= c0) & (lo_c < c0 + canvas.width))
    lr, lc = rows[k] - canvas.row0[m, None], cols[k] - canvas.col0[m, None]
    inside = (lr >= 0) & (lr < canvas.height) & (lc >= 0) & (lc < canvas.width)
    flat = (np.broadcast_to(m[:, None], lr.shape)[inside] * canvas.height + lr[inside]) * canvas.width + lc[inside]
    np.add.at(expected.reshape(-1), flat, values[k][inside])


def expected_charge(sensor, height, width, sources=(), windows=None):
    """Noise-free source charge [e-] on the canvas: (H, W) full frame or (M, s, s) windows.

    Sums the pixel-integrated, track-averaged PSF of every source (module
    docstring); background, hot pixels and noise are not included.
    """
    canvas = _Canvas.full_frame(height, width) if windows is None else _Canvas.from_windows(windows)
    expected = np.zeros((len(canvas.row0), canvas.height, canvas.width))
    for group in sources:
        if len(group.electrons) == 0:
            continue
        anchor, half = _patch_geometry(group.tracks, group.sigma_px)
        near = _touching(canvas, anchor, half)
        if near.size == 0:
            continue
        rows, cols, patches = _source_patches(group.tracks[near], group.electrons[near], group.sigma_px,
                                              anchor[near], half)
        _scatter(canvas, expected, rows[:, :, None], cols[:, None, :], patches)
    return expected[0] if windows is None else expected


def render(sensor, height, width, sources, rng, windows=None):
    """Noisy uint16 frame (H, W), or windows (M, s, s), of the given sources.

    ``sources`` is a sequence of :class:`Sources` (stars, planets, stray
    light, cosmic rays); ``rng`` a seeded numpy Generator; ``windows`` a
    :class:`Windows` or None for the full frame.  Noise model in the module
    docstring.
    """
    if not isinstance(rng, np.random.Generator):
        raise InputError("render needs a seeded numpy.random.Generator as rng")
    canvas = _Canvas.full_frame(height, width) if windows is None else _Canvas.from_windows(windows)
    signal = expected_charge(sensor, height, width, sources, windows)
    signal = signal.reshape(len(canvas.row0), canvas.height, canvas.width)
    if sensor.hot_pixel_count:
        hot_r, hot_c = sensor.hot_pixels(height, width)
        _scatter(canvas, signal, hot_r, hot_c, np.full(hot_r.shape, sensor.hot_pixel_e_per_s * sensor.exposure_s))
    lit = np.flatnonzero(signal)
    charge_lit = signal.reshape(-1)[lit]
    if sensor.shot_noise:
        charge_lit = rng.poisson(charge_lit).astype(float)
        sigma_e = np.sqrt(sensor.background_e + sensor.read_noise_e**2)
    else:
        sigma_e = sensor.read_noise_e
    # one Gaussian draw per pixel, in DN, float32 for speed
    dn = rng.standard_normal(signal.shape, dtype=np.float32)
    dn *= np.float32(sigma_e / sensor.gain_e_per_dn)
    dn += np.float32(sensor.background_dn)
    flat = dn.reshape(-1)
    flat[lit] += (charge_lit / sensor.gain_e_per_dn).astype(np.float32)
    np.minimum(dn, np.float32(sensor.saturation_dn), out=dn)
    np.maximum(dn, np.float32(0.0), out=dn)
    np.rint(dn, out=dn)
    out = dn.astype(np.uint16)
    return out[0] if windows is None else out


def _smear_times(exposure_s, omega_S, sigma_px, focal_px, fov_radius_px):
    """Sub-step times (K,) [s] from mid-exposure for the midpoint rule of the smear integral.

    K is set so that the fastest image point (rotation about the boresight
    at the field edge plus cross-boresight rate) moves at most
    SMEAR_STEP_SIGMA * sigma between samples.
    """
    omega = np.asarray(omega_S, dtype=float)
    speed = focal_px * np.hypot(omega[0], omega[1]) + abs(omega[2]) * fov_radius_px  # px/s, first order
    length = speed * exposure_s
    k = int(min(_MAX_SMEAR_STEPS, max(1, np.ceil(length / (SMEAR_STEP_SIGMA * sigma_px)))))
    return ((np.arange(k) + 0.5) / k - 0.5) * exposure_s


def star_sources(camera, sensor, q_IS, vectors_I, v_mag, omega_S=(0.0, 0.0, 0.0)):
    """Sources of the catalog stars that can touch the image during the exposure.

    ``q_IS`` is the attitude at mid-exposure and ``omega_S`` the body rate in
    the sensor frame [rad/s]; returns (Sources, catalog indices).
    """
    vectors_I = np.atleast_2d(np.asarray(vectors_I, dtype=float))
    v_mag = np.atleast_1d(np.asarray(v_mag, dtype=float))
    if vectors_I.shape[0] != v_mag.shape[0]:
        raise InputError(f"got {vectors_I.shape[0]} star directions but {v_mag.shape[0]} magnitudes")
    fov_radius_px = 0.5 * np.hypot(camera.width, camera.height)
    times = _smear_times(sensor.exposure_s, omega_S, sensor.psf_sigma_px, camera.focal_px, fov_radius_px)
    smear_px = np.linalg.norm(np.asarray(omega_S, float)) * sensor.exposure_s * (camera.focal_px + fov_radius_px)
    margin = PSF_EXTENT_SIGMA * sensor.psf_sigma_px + smear_px + 1.0
    index = camera.stars_in_field(q_IS, vectors_I, margin_px=margin)
    tracks = camera.angular_velocity_track(q_IS, omega_S, times, vectors_I[index])
    keep = np.all(np.isfinite(tracks), axis=(1, 2))
    index = index[keep]
    return Sources(tracks[keep], sensor.star_electrons(v_mag[index]), sensor.psf_sigma_px), index


@dataclass(frozen=True)
class RenderedFrame:
    """A rendered exposure and its truth: image (uint16), catalog indices and true centroids."""

    image: np.ndarray
    star_index: np.ndarray
    uv_true: np.ndarray
    electrons: np.ndarray
    windows: Windows | None = None
    extra_sources: tuple = field(default=())


def render_star_field(camera, sensor, q_IS, vectors_I, v_mag, rng, omega_S=(0.0, 0.0, 0.0),
                      windows=None, extra_sources=()):
    """Render the catalog stars (directions ``vectors_I``, magnitudes ``v_mag``) for attitude q_IS.

    Full frame or windows; ``extra_sources`` adds false stars (planet,
    stray light, cosmic ray).  Returns a :class:`RenderedFrame`.
    """
    stars, index = star_sources(camera, sensor, q_IS, vectors_I, v_mag, omega_S)
    image = render(sensor, camera.height, camera.width, (stars, *extra_sources), rng, windows)
    return RenderedFrame(image, index, stars.centroids, stars.electrons, windows, tuple(extra_sources))
