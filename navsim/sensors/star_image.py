"""Image-fidelity star sensor: every frame is rendered and processed (docs/design.md, fidelity ``image``).

Per frame (:meth:`ImageRun.observe`), given the filter's predicted attitude q̂_IS and rate:

1. the predicted boresight gives the sub-catalog address (eq. 7-8 of 000), logged every frame;
2. the frame is rendered from the true attitude (true mounting, smear from the true body rate) and,
   on a vehicle near the Earth, the stars' apparent directions (:mod:`navsim.earth.apparent`):
   windows around the predicted stars while tracking, the full frame otherwise — windows sized to
   hold the smear trail the predicted rate implies;
3. detection and centroids (full frames by the sensor's detector, :mod:`navsim.sensors.frame_detection`: 004's
   threshold, or the matched filter for the trail the predicted rate draws); identification
   with the prediction as prior — while tracking, the predicted attitude (tracking windows, then the predicted sub-catalog); after a lost track (an
   outage, a dropped frame, a rejected frame), the predicted boresight only: the predicted
   sub-catalog with its 4 redundant neighbours, then full-sky lost-in-space
   (:class:`startrack.identify.StarIdentifier`); while tracking, stars the identifier leaves are
   window-matched to their predictions;
4. with fewer than 3 stars identified while tracking, the brightest undetected predicted star is
   stacked over the last 4 frames (shifted-window superposition, eq. 13-18 of 004), its centroid
   corrected by the sub-pixel phases the predictions give (an extension of 004: integer shifts alone
   leave ~0.25 px per axis);
5. one unit vector per identified star, its position fitted at the Cramér-Rao bound with the smear the
   predicted rate gives (:mod:`startrack.image.psf_fit`) and its 2 x 2 covariance carried into the sensor frame
   (correlated along the trail; an outlier's scaled by its measured χ²/dof; a star whose fit failed, or
   whose window another catalog star's light reaches -- a blend, which overlapping trails of a turning
   camera hide from the χ² -- not fused), the stacked dim star last with its own measured σ; the
   identification's attitude for a re-initialisation when it came from the sub-catalog or full sky.

Faults acting on the sensor (outages, dropped frames, false-star storms) are applied here; the
tracking state follows the filter's verdict (:meth:`ImageRun.after_update`). A sensor with a light budget
sees each frame's sky (:class:`navsim.sensors.frame_sky.FrameSky`): its level in every pixel, with its shot
noise, and each star extinguished along its own line of sight (none through the ground).
"""

import dataclasses
from dataclasses import dataclass

import numpy as np

from navsim import kinematics
from navsim.earth.apparent import field_stars
from navsim.sensors.star_sensor import MODE_CODE, StarFrame, isotropic_covariance
from startrack import (
    DimStarCache,
    PixelNoise,
    Prior,
    Windows,
    concatenate_fits,
    cosmic_ray,
    detect_windows,
    fit_stars,
    neighbour_reach,
    render_star_field,
)
from startrack import rotation as rot

#: σ per axis of a stacked dim-star centroid [px]. The loop uses the phase-corrected centroid
#: (startrack.image.stacking: integer shifts average the 4 frames' sub-pixel phases, ~0.25 px per axis, and
#: the filter's predictions put the phase back); measured in scenarios/paper004_dim_star.toml over
#: 24 seeds (176 stacked frames): (0.35, 0.25) px RMS in (u, v), against (0.45, 0.38) px uncorrected.
STACKED_SIGMA_PX = 0.30

#: Per-frame log quantities: name -> (trailing shape, dtype, value before the frame is logged); the
#: identification time [ms] is a wall-clock measurement, kept apart from the reproducible log.
LOG_FIELDS = {
    "mode": ((), np.int8, 0), "n_detected": ((), np.int32, 0), "n_identified": ((), np.int32, 0),
    "n_stacked": ((), np.int32, 0), "boresight_radec": ((2,), np.float64, np.nan),
    "subcatalog_index": ((), np.int32, 0), "subcatalog_address": ((2,), np.int32, 0),
}
TIMING_FIELDS = {"id_ms": ((), np.float64, np.nan)}


@dataclass(frozen=True)
class ImageStarSensor:
    """The seed-free image-fidelity sensor, built once per scenario (:func:`navsim.build.star_sensor.star_sensor`):
    camera and detector model, the identifier over the navigation catalog, the stars drawn into the
    frames (unit vectors in I, V magnitudes, HIP), detection threshold a of V_th = b + a σ_n (the readout windows'),
    the full frame's ``detection`` (a strategy of :mod:`navsim.sensors.frame_detection`),
    tracking window half-width [px], dim-star stacking on/off, whether the first frame is already
    tracked (004's set-up), the true mounting and the faults; with a light budget (``photometry``) the frames'
    sky (``sky``). Each fused star's direction and its covariance come from its position fit
    (:mod:`startrack.image.psf_fit`); the drawn stars are also the catalog the fit's neighbours come from. On a spacecraft:
    the particle hits of its orbit (``radiation``, a :class:`navsim.sensors.radiation_hits.RadiationHits`) and the
    stars the Earth hides (``occultation``, a :class:`navsim.orbit.earth_disc.EarthDisc` of the frames)."""

    camera: object
    model: object
    identifier: object
    stars_I: np.ndarray
    stars_mag: np.ndarray
    stars_hip: np.ndarray
    detection_sigmas: float
    window_half_px: int
    stacking: bool
    start_tracking: bool
    q_BS_true: np.ndarray
    faults: object
    detection: object
    photometry: object = None
    sky: object = None
    radiation: object = None
    occultation: object = None

    @property
    def catalog(self):
        return self.identifier.catalog

    @property
    def field_radius(self):
        """Angle [rad] from the boresight within which a star may fall on the detector: the half
        diagonal, plus 1 deg for the smear and the aberration."""
        c = self.camera
        return float(np.arctan(0.5 * np.hypot(c.width, c.height) / c.focal_px) + np.radians(1.0))

    def drawn_stars(self, q_IS_true, v_I, frame, air=None):
        """(directions (N, 3), magnitudes (N,)) of the stars drawn into frame ``frame`` of true attitude
        q_IS_true: the catalog's, or near the boresight their apparent directions for the observer
        velocity ``v_I`` [m/s] (None: no aberration) refracted by the frame's ``air`` (up_I, A, B) (None: none);
        extinguished by the frame's air when it has a sky."""
        if v_I is None:
            directions, mags = self.stars_I, self.stars_mag
        else:
            index, directions = field_stars(self.stars_I, rot.rotate(q_IS_true, np.array([0.0, 0.0, 1.0])),
                                            self.field_radius, v_I, air)
            mags = self.stars_mag[index]
        if self.occultation is not None:
            seen = ~self.occultation.hides(directions, np.full(len(directions), frame))
            directions, mags = directions[seen], mags[seen]
        if self.sky is None:
            return directions, mags
        return directions, self.sky.extinguished(np.full(len(mags), frame), mags, directions)

    def frame_model(self, frame):
        """The detector model of frame ``frame``: with a sky, its level in every pixel."""
        if self.sky is None:
            return self.model
        return dataclasses.replace(self.model, sky_e_per_px_s=float(self.sky.sky_e_per_px_s[frame]))

    def start(self, storm_rng, render_rng, n_frames, full_frames=frozenset()):
        """A run's sensor; ``full_frames``: frame indices read in full whatever the mode (observers')."""
        return ImageRun(self, storm_rng, render_rng, n_frames, full_frames)


class ImageRun:
    """The per-run state of an :class:`ImageStarSensor`: tracking flag, the 4-frame stacking cache,
    the random streams of rendering and false stars, and one full frame kept for the report."""

    log_fields = LOG_FIELDS
    timing_fields = TIMING_FIELDS
    uses_prediction = True
    uses_prior = False

    def __init__(self, sensor, storm_rng, render_rng, n_frames, full_frames):
        self.sensor = sensor
        self._storm_rng, self._render_rng = storm_rng, render_rng
        self._tracking = sensor.start_tracking  # previous frame identified: read windows around predicted stars
        self._cache = DimStarCache(half_width=2, depth=4)
        self._full_frames = frozenset(full_frames)
        self._sample_at, self._last = n_frames // 2, n_frames - 1
        self._R_SB_true = rot.to_matrix(sensor.q_BS_true).T
        self.sample = None
        self.last_hits = 0  # the particle hits drawn into the last frame

    def record(self):
        return None

    def lose_track(self):
        self._tracking = False
        self._cache.reset()

    def after_update(self, update, posterior):
        """Tracking continues while the filter accepts two stars (one, once tracking)."""
        accepted = 0 if update is None else update.n_accepted
        self._tracking = accepted >= 2 or (self._tracking and accepted >= 1)

    def observe(self, request):
        info = self._address(request.q_IS_pred)
        lost = self.sensor.faults.status(request.t)
        if lost is not None:
            self.lose_track()
            return StarFrame(mode=lost[0], reason=lost[1], info=info | {"mode": MODE_CODE[lost[0]]})
        s = self.sensor
        q_IS_true = rot.multiply(request.truth.q_IB, s.q_BS_true)
        uv_pred, visible = s.camera.project(request.q_IS_pred, s.stars_I)
        predicted = np.flatnonzero(visible)
        full = (not self._tracking or len(predicted) == 0 or request.index == self._sample_at
                or request.index in self._full_frames)
        image, windows, found = self._read(request, q_IS_true, uv_pred[predicted], full)
        result = s.identifier.solve(found.uv, found.flux, prior=self._prior(request, info))
        ref_I, _, detected, mode, reason = self._identified(result, found, uv_pred, predicted)
        fits = self._fit(image, windows, found.uv[detected], ref_I, request)
        ref_I, uv, cov_uv = ref_I[fits.usable], fits.uv[fits.usable], fits.cov[fits.usable]
        obs_S, cov_S = s.camera.unproject(uv), s.camera.unproject_covariance(uv, cov_uv)
        info |= {"n_detected": len(found), "n_identified": len(ref_I), "id_ms": result.solve_ms}
        centroided = detected[fits.usable]  # the same stars as 004 measures them: the thresholded centre of gravity
        diagnostics = {"q_IS_true": q_IS_true, "detections": found, "fits": fits,
                       "centroids_004": {"obs_S": s.camera.unproject(found.uv[centroided]),
                                         "sigma": np.hypot(found.sigma_u[centroided], found.sigma_v[centroided])
                                         / np.sqrt(2.0) / s.camera.focal_px}}
        stacked = (self._stack(image, windows, found, uv_pred, predicted, full, len(ref_I), request.index)
                   if self._stacks(predicted) else None)
        if stacked is not None:
            stacked["uv_true"] = s.camera.project(q_IS_true, s.stars_I[stacked["index"]][None])[0][0]
            diagnostics["stacked"] = stacked
            ref_I, obs_S = np.vstack([ref_I, stacked["ref_I"]]), np.vstack([obs_S, stacked["obs_S"]])
            cov_S = np.concatenate([cov_S, isotropic_covariance(stacked["obs_S"][None], stacked["sigma"])])
            mode, reason = "stacked", f"{len(ref_I) - 1} stars and the stacked dim star HIP {stacked['hip']}"
        if not len(ref_I):
            mode = "no_fix"
        if self.sample is None and full and (request.index >= self._sample_at or request.index == self._last):
            self.sample = _sample_frame(image, found, result)
        return StarFrame(mode=mode, reason=reason, ref_I=ref_I, obs_S=obs_S, cov_S=cov_S,
                         n_stacked=int(stacked is not None),
                         fix_q_IS=result.q_IS if mode in ("subcatalog", "lost_in_space") else None,
                         info=info | {"mode": MODE_CODE[mode], "n_stacked": int(stacked is not None)},
                         diagnostics=diagnostics)

    def _prior(self, request, info):
        """The identification's prior: while tracking, the predicted attitude (tracking windows, then the
        sub-catalog); after a lost track, only the predicted boresight (re-acquisition through its
        sub-catalog and 4 redundant neighbours, then lost-in-space; 000 §3)."""
        if self._tracking:
            return Prior(q_IS=request.q_IS_pred)
        return Prior(boresight=info["boresight_radec"])

    def _address(self, q_IS_pred):
        """Predicted boresight (RA, Dec) [rad] and its sub-catalog address and flat index (eq. 7-8 of 000)."""
        ra, dec = kinematics.boresight_radec(q_IS_pred)
        catalog = self.sensor.catalog
        return {"boresight_radec": (ra, dec), "subcatalog_address": catalog.address(ra, dec),
                "subcatalog_index": catalog.sub_catalog_index(ra, dec)}

    def _read(self, request, q_IS_true, uv_predicted, full):
        """(image, windows or None, detections) of the frame: rendered from the truth, read in full
        or in windows around the predicted stars sized to the smear the predicted rate implies."""
        s, camera, model = self.sensor, self.sensor.camera, self.sensor.frame_model(request.index)
        windows = None
        if not full:
            smear_px = np.hypot(request.omega_S_pred[0], request.omega_S_pred[1]) * model.exposure_s * camera.focal_px
            half = max(s.window_half_px, int(np.ceil(0.5 * smear_px + 3.0 * model.psf_sigma_px)) + 1)
            windows = Windows.around(uv_predicted, half, camera.height, camera.width)
        stars_I, stars_mag = s.drawn_stars(q_IS_true, request.truth.v_I, request.index, request.truth.air)
        frame = render_star_field(camera, model, q_IS_true, stars_I, stars_mag, self._render_rng,
                                  omega_S=self._R_SB_true @ request.truth.omega_B, windows=windows,
                                  extra_sources=self._false_stars(request.t) + self._hits(request.index))
        if full:
            found = s.detection.find(frame.image, model, lambda: self._boresight_trail(request))
        else:
            found = _unique(detect_windows(frame.image, windows.row0, windows.col0, model.background_dn, model.noise_dn,
                                           a=s.detection_sigmas, saturation_dn=model.saturation_dn))
        return frame.image, windows, found

    def _boresight_trail(self, request):
        """(Δu, Δv) [px]: the trail the predicted attitude and rate draw over the exposure at the boresight (what a
        full-frame detector of :mod:`navsim.sensors.frame_detection` may use)."""
        camera, exposure = self.sensor.camera, self.sensor.frame_model(request.index).exposure_s
        boresight_I = rot.rotate(request.q_IS_pred, np.array([0.0, 0.0, 1.0]))
        track = camera.angular_velocity_track(request.q_IS_pred, request.omega_S_pred, (-0.5 * exposure, 0.5 * exposure),
                                              boresight_I[None])
        return np.nan_to_num(track[0, 1] - track[0, 0])

    def _fit(self, image, windows, uv, ref_I, request):
        """The PSF fits (:func:`startrack.image.psf_fit.fit_stars`) of the identified stars' detections ``uv`` (N, 2)
        in the full frame or in the readout window holding each, with the smear the predicted attitude and
        rate give each star over the exposure: positions at the Cramér-Rao bound with their covariance."""
        s, model = self.sensor, self.sensor.frame_model(request.index)
        half_exposure = 0.5 * model.exposure_s
        track = s.camera.angular_velocity_track(request.q_IS_pred, request.omega_S_pred, (-half_exposure, half_exposure),
                                                ref_I)
        smear = np.nan_to_num(track[:, 1] - track[:, 0])
        near = self._neighbours(request.q_IS_pred, ref_I, np.abs(smear).max(initial=0.0))
        noise = PixelNoise(model.noise_dn, gain_e_per_dn=model.gain_e_per_dn)
        common = {"psf_sigma_px": model.psf_sigma_px, "noise": noise, "background_dn": model.background_dn,
                  "saturation_dn": model.saturation_dn}
        if windows is None:
            return fit_stars(image, uv, smear_px=smear, neighbours=near, **common)
        centres = np.stack([windows.col0, windows.row0], axis=1) + 0.5 * (windows.size - 1)
        holder = np.argmin(np.abs(uv[:, None, :] - centres[None]).max(axis=2), axis=1) if len(uv) else np.zeros(0, int)
        fits = [fit_stars(image[w], uv[k:k + 1], smear_px=smear[k], origin=(windows.row0[w], windows.col0[w]),
                          neighbours=near[k:k + 1], **common) for k, w in enumerate(holder)]
        return concatenate_fits(fits) if fits else fit_stars(image[0], np.zeros((0, 2)), **common)

    def _neighbours(self, q_IS_pred, ref_I, smear_px):
        """For each identified star of catalog direction ``ref_I`` (N, 3), the predicted centres (M, 2) [px] of
        the other catalog stars drawn into the frame that lie near the image (``smear_px`` the largest smear
        [px]): what the sensor's catalog knows lies beside it, for the fit's ``blended`` flag. A catalog star
        within 1 px of the star's own prediction is the star itself."""
        s = self.sensor
        margin = float(neighbour_reach(s.model.psf_sigma_px, (smear_px, smear_px)).max())
        boresight_I = rot.rotate(q_IS_pred, np.array([0.0, 0.0, 1.0]))
        cone = s.stars_I[s.stars_I @ boresight_I > np.cos(s.field_radius + margin / s.camera.focal_px)]
        field = s.camera.project(q_IS_pred, cone[s.camera.stars_in_field(q_IS_pred, cone, margin_px=margin)])[0]
        own = s.camera.project(q_IS_pred, ref_I)[0] if len(ref_I) else np.zeros((0, 2))
        near = []
        for p in own:
            d = np.hypot(*(field - p).T)
            near.append(np.delete(field, np.argmin(d), axis=0) if d.size and d.min() < 1.0 else field)
        return near

    def _false_stars(self, t):
        """Cosmic-ray tracks of a false-star storm at t [s] (none outside a storm)."""
        count = self.sensor.faults.storm_count(t)
        if not count:
            return ()
        camera, rng = self.sensor.camera, self._storm_rng
        u0 = rng.uniform(0, camera.width - 1, count)
        v0 = rng.uniform(0, camera.height - 1, count)
        du, dv = rng.normal(0, 3.0, (2, count))
        return tuple(cosmic_ray(a, b, a + c, b + d, 4.0e4) for a, b, c, d in zip(u0, v0, du, dv))

    def _hits(self, frame):
        """The particle hits of frame ``frame`` (:class:`~navsim.sensors.radiation_hits.RadiationHits`; none without
        radiation), drawn from the false-star stream after the storms'."""
        if self.sensor.radiation is None:
            return ()
        hits = self.sensor.radiation.draw(frame, self._storm_rng, self.sensor.camera.width, self.sensor.camera.height)
        self.last_hits = len(hits[0])
        return self.sensor.radiation.sources(hits)

    def _identified(self, result, found, uv_pred, predicted):
        """(ref_I, obs_S, detection index of each, mode, reason) of the identification; while tracking,
        stars it did not identify are matched to their predicted positions instead (mode None: nothing)."""
        s = self.sensor
        if result.ok:
            return (result.ref_I, result.obs_S, result.matches[:, 0], result.method,
                    f"{len(result.ref_I)} stars identified")
        if self._tracking:
            det, pred = _match_predicted(found.uv, uv_pred[predicted], 3.0 * s.window_half_px / 2)
            if det.size:
                return (s.stars_I[predicted[pred]], s.camera.unproject(found.uv[det]), det, "tracking",
                        f"{det.size} stars matched to their predictions")
        return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, dtype=np.int64), None, result.reason

    def _stacks(self, predicted):
        return self.sensor.stacking and self._tracking and len(predicted) > 0

    def _stack(self, image, windows, found, uv_pred, predicted, full, n_identified, frame):
        """004 §3: push the brightest undetected predicted star's window into the 4-frame cache and,
        with fewer than 3 stars identified and a full cache, stack it (eq. 13-18 of 004). Returns the
        stacked star (its catalog and measured vectors, σ, centroid and true position, HIP) or None."""
        s = self.sensor
        _, pred_match = _match_predicted(found.uv, uv_pred[predicted], 3.0)
        undetected = np.setdiff1d(np.arange(len(predicted)), pred_match)
        if not undetected.size:
            return None
        candidate = predicted[undetected[np.argmin(s.stars_mag[predicted[undetected]])]]
        self._push(image, windows, uv_pred[candidate], int(candidate), full, predicted)
        if n_identified >= 3 or not self._cache.full:
            return None
        model = s.frame_model(frame)
        stacked = self._cache.stack(model.background_dn, model.noise_dn, a=s.detection_sigmas)
        if not stacked.detected:
            return None
        uv = np.array([[stacked.u_corrected, stacked.v_corrected]])
        return {"ref_I": s.stars_I[candidate], "obs_S": s.camera.unproject(uv)[0], "uv": uv[0],
                "sigma": STACKED_SIGMA_PX / s.camera.focal_px, "hip": s.stars_hip[candidate], "index": int(candidate)}

    def _push(self, image, windows, uv, candidate, full, predicted):
        """The candidate's l = 2 window into the cache: cut from the full frame or from its readout window."""
        if full:
            self._cache.push(image, uv, star_id=candidate)
            return
        w = int(np.flatnonzero(predicted == candidate)[0])
        centre = np.rint(uv[::-1]).astype(int) - (windows.row0[w], windows.col0[w])
        window = image[w][centre[0] - 2 : centre[0] + 3, centre[1] - 2 : centre[1] + 3]
        if window.shape == (5, 5):
            self._cache.push_window(window, uv, star_id=candidate)
        else:
            self._cache.reset()


def _match_predicted(uv, uv_predicted, gate_px):
    """One-to-one nearest matches (detection index, predicted index) within ``gate_px``."""
    if len(uv) == 0 or len(uv_predicted) == 0:
        return np.zeros(0, int), np.zeros(0, int)
    d = np.linalg.norm(uv[:, None, :] - uv_predicted[None, :, :], axis=2)
    pairs = []
    used_d, used_p = set(), set()
    for flat in np.argsort(d, axis=None):
        i, k = divmod(int(flat), d.shape[1])
        if d[i, k] > gate_px:
            break
        if i not in used_d and k not in used_p:
            pairs.append((i, k))
            used_d.add(i)
            used_p.add(k)
    if not pairs:
        return np.zeros(0, int), np.zeros(0, int)
    det, pred = np.array(pairs).T
    return det, pred


def _unique(found):
    """Windows around close stars overlap: keep one detection per star image (1 px)."""
    if len(found) < 2:
        return found
    uv = found.uv
    keep = np.ones(len(found), bool)
    for i in range(len(found)):
        if keep[i]:
            close = np.linalg.norm(uv[i + 1 :] - uv[i], axis=1) < 1.0
            keep[i + 1 :][close] = False
    return found.select(keep)


def _sample_frame(image, found, result):
    hip = {int(c): int(h) for c, h in result.matches} if result.ok else {}
    return {
        "image": np.asarray(image),
        "detections": [{"u": float(u), "v": float(v), "hip": hip.get(i)} for i, (u, v) in enumerate(found.uv)],
    }
