"""Image-chain speed and centroid accuracy against the Cramér-Rao bound, side by side with the ``sep``
package (Source Extractor).

Speed. Frames: 1024 x 1024 px, 20 deg field, Hipparcos-2 stars to V = 6.5 at seeded random attitudes,
default :class:`~startrack.image.render.SensorModel` (0.671 px PSF, 12-bit ADC, b ~ 101 DN, sigma_n ~ 10 DN),
100 ms exposure, body rate 0.5 deg/s (smear ~2.5 px).  Measured per frame (median ms): render; detect +
centroid (background estimated from the frame, and given); the position fit at the bound
(:mod:`startrack.image.psf_fit`) of the 12 brightest unsaturated stars (what a frame fuses: the scenario's
``max_identified_stars``); window mode (8 windows of 11 x 11: render + detect + fit).  Centroid error: RMS
distance to the true (track-averaged) centroid of the matched stars that are neither saturated nor on the
edge.  ``sep`` (if importable) runs on the same frames: sep.Background + sep.extract at 5 sigma (isophotal
barycentre x, y), and sep.extract with the known background.

Accuracy against the bound (``accuracy``). 256 x 256 frames of 16 stars on a grid at random sub-pixel
phases, rendered by :mod:`startrack.image.render` with a 16-bit sensor (gain 20 e-/DN, full well 2e6 e-: no star
saturates up to SNR 1000; 0.671 px PSF, read noise 20 e-, dark 2 e- per pixel), each star's smear |Δ| 0, 2,
5 or 10 px in a random direction. The charge of each star is log-uniform from SNR 5 to 1000 by either
definition of the SNR: 004's (eq. 1: the noise-free peak above the background over σ_n, as
:func:`startrack.image.detection.detect` reports it) and the flux SNR N/σ_N (the bound on the flux); both
tables are written. Per (SNR, smear) bin: the RMS error of each estimator over the RMS of the
bound at the true positions (both axes pooled; 1 is the bound); for the estimators that give a σ, the
variance of the normalised errors e/σ (1 for an honest σ) and the share beyond 3σ (0.27 % for a Gaussian).
Estimators: the fit of eq. (1)-(2) of startrack.image.psf_fit started from the detection where one was found,
and from a prediction 0.3 px off (a tracking window) for every star; the thresholded centroid of
:func:`startrack.image.detection.detect` with its σ; sep's isophotal barycentre with its errx2/erry2, and
sep.winpos (windowed centroid, σ_w = √(σ² + |Δ|²/12)) from the detection.

Writes benchmarks/results/image_chain.json; asserts nothing.
Run: .venv/bin/python benchmarks/image_chain.py [--accuracy-stars N]
"""

import argparse
import json
import platform
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from startrack.base.units import DEG
from startrack.camera.model import Camera
from startrack.catalog.hipparcos import load_star_catalog
from startrack.image.detection import detect, detect_windows
from startrack.image.psf_fit import PixelNoise, centroid_bound, fit_stars, information, track_offsets
from startrack.image.render import SensorModel, Sources, Windows, expected_charge, render, render_star_field, star_sources

N_FRAMES = 20
REPEATS = 5
MATCH_PX = 1.0
OUT = Path(__file__).resolve().parent / "results" / "image_chain.json"

try:
    import sep
except ImportError:  # reported in the JSON
    sep = None


def timed(function, repeats=REPEATS):
    """(median milliseconds, last result) of ``repeats`` calls."""
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = function()
        times.append(1000.0 * (time.perf_counter() - start))
    return float(np.median(times)), result


def centroid_error(uv_found, uv_true, usable):
    """(matched fraction of usable true stars, RMS error [px] of the matches)."""
    if len(uv_found) == 0:
        return 0.0, float("nan")
    dist, _ = cKDTree(uv_found).query(uv_true[usable])
    ok = dist < MATCH_PX
    return float(np.mean(ok)), float(np.sqrt(np.mean(dist[ok] ** 2)))


#: The accuracy study (module docstring): its sensor, SNR bins, smear lengths [px] and frames.
ACCURACY_SENSOR = SensorModel(gain_e_per_dn=20.0, full_well_e=2.0e6, full_scale_dn=65536)
SNR_EDGES = (5.0, 10.0, 20.0, 50.0, 100.0, 300.0, 1000.0)
SMEARS_PX = (0.0, 2.0, 5.0, 10.0)
FRAME_PX, GRID = 256, 4
PREDICTION_PX = 0.3
TRACK_POINTS = 64


def peak_snr(uv, electrons, smear, sensor=ACCURACY_SENSOR):
    """004's SNR (eq. 1) of a star: its noise-free peak above the background over σ_n."""
    half = int(np.ceil(5 * sensor.psf_sigma_px + 0.5 * np.hypot(*smear))) + 1
    s = (np.arange(TRACK_POINTS) + 0.5) / TRACK_POINTS - 0.5
    track = (half + np.asarray(uv) - np.rint(uv)) + s[:, None] * np.asarray(smear)
    charge = expected_charge(sensor, 2 * half + 1, 2 * half + 1, [Sources(track[None], [electrons], sensor.psf_sigma_px)])
    return float(charge.max() / sensor.gain_e_per_dn / sensor.noise_dn)


def flux_snr(electrons, smear_px, sensor=ACCURACY_SENSOR):
    """N/σ_N of a star of ``electrons`` [e-] with a smear of ``smear_px`` (the bound on the flux, at a pixel centre)."""
    noise = PixelNoise(sensor.noise_dn, gain_e_per_dn=sensor.gain_e_per_dn)
    su, sv = track_offsets((smear_px, 0.0), sensor.psf_sigma_px)
    flux = electrons / sensor.gain_e_per_dn
    half = int(np.ceil(5 * sensor.psf_sigma_px + smear_px / 2)) + 1
    J = information(np.array([30.0, 30.0, flux, 0.0]), 30 - half, 30 - half, 2 * half + 1, 2 * half + 1, su, sv,
                    sensor.psf_sigma_px, noise.variance_dn2, noise.inverse_gain)
    return flux / np.sqrt(np.linalg.inv(J)[2, 2])


def _frame_stars(rng, smear_px, electrons_range):
    """(u, v, electrons, smear (2,)) of the 16 stars of one accuracy frame, the charge log-uniform in
    ``electrons_range``."""
    spacing = FRAME_PX / GRID
    stars = []
    for i in range(GRID):
        for j in range(GRID):
            angle = rng.uniform(0.0, np.pi)
            electrons = np.exp(rng.uniform(*np.log(electrons_range)))
            stars.append((spacing * (j + 0.5) + rng.uniform(-0.5, 0.5), spacing * (i + 0.5) + rng.uniform(-0.5, 0.5),
                          float(electrons), smear_px * np.array([np.cos(angle), np.sin(angle)])))
    return stars


def _electrons_range(smear_px):
    """The charge [e-] from the faintest star at SNR 5 to the brightest at SNR 1000, by either definition."""
    grid = np.logspace(1.0, 8.0, 120)
    flux = np.array([flux_snr(e, smear_px) for e in grid])
    peak = np.array([peak_snr((0.0, 0.0), e, (smear_px, 0.0)) for e in grid])
    low = min(np.interp(np.log(SNR_EDGES[0]), np.log(x), grid) for x in (flux, peak))
    high = max(np.interp(np.log(SNR_EDGES[-1]), np.log(x), grid) for x in (flux, peak))
    return low, high


def _nearest(uv_found, uv, gate):
    """Index of the found point nearest ``uv`` within ``gate`` [px], or None."""
    if len(uv_found) == 0:
        return None
    distance = np.hypot(*(np.asarray(uv_found) - uv).T)
    i = int(np.argmin(distance))
    return i if distance[i] <= gate else None


def accuracy(stars_per_bin):
    """The accuracy study of the module docstring: per smear and SNR bin, each estimator's RMS over the bound's
    and its normalised errors."""
    sensor = ACCURACY_SENSOR
    noise = PixelNoise(sensor.noise_dn, gain_e_per_dn=sensor.gain_e_per_dn)
    sigma, gain, b = sensor.psf_sigma_px, sensor.gain_e_per_dn, sensor.background_dn
    out = {"peak_snr": {}, "flux_snr": {}}
    for smear_px in SMEARS_PX:
        electrons_range = _electrons_range(smear_px)
        decades = np.log10(electrons_range[1] / electrons_range[0])
        frames = int(np.ceil(stars_per_bin * (len(SNR_EDGES) - 1) * decades / np.log10(SNR_EDGES[-1] / SNR_EDGES[0])
                             / GRID**2))
        rng = np.random.default_rng(np.random.SeedSequence([27, int(smear_px * 10)]))
        records = []
        for _ in range(frames):
            stars = _frame_stars(rng, smear_px, electrons_range)
            s = (np.arange(TRACK_POINTS) + 0.5) / TRACK_POINTS - 0.5
            tracks = np.array([[(u + t * d[0], v + t * d[1]) for t in s] for u, v, _, d in stars])
            image = render(sensor, FRAME_PX, FRAME_PX, [Sources(tracks, [e for _, _, e, _ in stars], sigma)], rng)
            found = detect(image, background=b, sigma_n=sensor.noise_dn, saturation_dn=sensor.saturation_dn)
            objects = sep.extract(image.astype(float) - b, 5.0, err=sensor.noise_dn, minarea=1) if sep else None
            for u, v, electrons, d in stars:
                records.append(_star_record(image, found, objects, (u, v), electrons, d, sigma, noise, b, gain, rng))
        for snr in out:
            out[snr][f"{smear_px:g}"] = _bin_statistics(records, snr)
    return out


def _star_record(image, found, objects, uv, electrons, smear, sigma, noise, background, gain, rng):
    """One star's errors [px] and σ (2,) per estimator, its CRB and flux SNR."""
    uv = np.asarray(uv)
    crb = centroid_bound(uv, electrons / gain, sigma, noise, smear)
    record = {"flux_snr": flux_snr(electrons, float(np.hypot(*smear))), "peak_snr": peak_snr(uv, electrons, smear),
              "crb": np.diag(crb), "errors": {}}
    gate = 1.5 + 0.5 * float(np.hypot(*smear))
    predicted = fit_stars(image, [uv + rng.normal(0.0, PREDICTION_PX, 2)], sigma, noise, background, smear_px=smear)
    if not predicted.failed[0]:
        record["errors"]["fit_from_prediction"] = (predicted.uv[0] - uv, np.sqrt(np.diag(predicted.cov[0])))
    i = _nearest(found.uv, uv, gate)
    record["detected"] = i is not None
    if i is not None:
        record["errors"]["threshold_centroid"] = (found.uv[i] - uv, np.array([found.sigma_u[i], found.sigma_v[i]]))
        fit = fit_stars(image, found.uv[i:i + 1], sigma, noise, background, smear_px=smear)
        if not fit.failed[0]:
            record["errors"]["fit_from_detection"] = (fit.uv[0] - uv, np.sqrt(np.diag(fit.cov[0])))
    if objects is not None:
        j = _nearest(np.column_stack([objects["x"], objects["y"]]), uv, gate)
        if j is not None:
            record["errors"]["sep_isophotal"] = (np.array([objects["x"][j], objects["y"][j]]) - uv,
                                                 np.sqrt([objects["errx2"][j], objects["erry2"][j]]))
            sig = np.sqrt(sigma**2 + float(np.hypot(*smear)) ** 2 / 12.0)
            x, y, flag = sep.winpos(image.astype(float) - background, [objects["x"][j]], [objects["y"][j]], [sig])
            if flag[0] == 0:
                record["errors"]["sep_winpos"] = (np.array([x[0], y[0]]) - uv, None)
    return record


def _bin_statistics(records, definition):
    """Per bin of the SNR ``definition`` (peak_snr, flux_snr): stars, detected share, and per estimator RMS/CRB
    and the normalised errors."""
    snr = np.array([r[definition] for r in records])
    out = {}
    for lo, hi in zip(SNR_EDGES[:-1], SNR_EDGES[1:]):
        members = [r for r, x in zip(records, snr) if lo <= x < hi]
        row = {"stars": len(members), "detected": float(np.mean([r["detected"] for r in members])) if members else None}
        for name in ("fit_from_detection", "fit_from_prediction", "threshold_centroid", "sep_isophotal", "sep_winpos"):
            used = [r for r in members if name in r["errors"]]
            if len(used) < 10:
                continue
            errors = np.array([r["errors"][name][0] for r in used])
            bound = np.array([r["crb"] for r in used])
            entry = {"stars": len(used), "rms_over_crb": float(np.sqrt(np.sum(errors**2) / np.sum(bound)))}
            if used[0]["errors"][name][1] is not None:
                z = (errors / np.array([r["errors"][name][1] for r in used])).ravel()
                entry |= {"normalised_variance": float(np.var(z)), "beyond_3_sigma": float(np.mean(np.abs(z) > 3.0))}
            row[name] = entry
        out[f"{lo:g}-{hi:g}"] = row
    return out


def main(stars_per_bin=300):
    camera = Camera.from_fov(20 * DEG, 1024, 1024)
    sensor = SensorModel()
    omega = np.array([0.5, 0.0, 0.0]) * DEG
    stars = load_star_catalog(2000.0).brighter_than(6.5)
    seeds = np.random.SeedSequence(4).spawn(N_FRAMES)
    rows = {key: [] for key in ("render", "detect", "detect_given_b", "fit_12", "windows", "sep", "sep_given_b")}
    errors = {key: [] for key in ("grey", "threshold", "square", "fit", "sep")}
    noise = PixelNoise(sensor.noise_dn, gain_e_per_dn=sensor.gain_e_per_dn)
    n_stars = []
    for seed in seeds:
        rng = np.random.default_rng(seed)
        q = Rotation.random(random_state=rng).as_quat()
        ms, frame = timed(lambda: render_star_field(camera, sensor, q, stars.vectors, stars.v_mag, rng, omega))
        rows["render"].append(ms)
        image = frame.image
        inside = ((frame.uv_true[:, 0] > 3) & (frame.uv_true[:, 0] < 1020)
                  & (frame.uv_true[:, 1] > 3) & (frame.uv_true[:, 1] < 1020))
        noise_free = expected_charge(sensor, 1024, 1024, [star_sources(camera, sensor, q, stars.vectors,
                                                                       stars.v_mag, omega)[0]])
        r, c = np.clip(np.rint(frame.uv_true[:, ::-1]).astype(int), 0, 1023).T
        peak_dn = sensor.background_dn + noise_free[r, c] / sensor.gain_e_per_dn
        usable = inside & (peak_dn < 0.9 * sensor.saturation_dn)  # not saturated
        n_stars.append(int(inside.sum()))
        ms, found = timed(lambda: detect(image, saturation_dn=sensor.saturation_dn))
        rows["detect"].append(ms)
        ms, _ = timed(lambda: detect(image, background=sensor.background_dn, sigma_n=sensor.noise_dn))
        rows["detect_given_b"].append(ms)
        for name in ("grey", "threshold", "square"):
            found = detect(image, centroider=name, saturation_dn=sensor.saturation_dn)
            errors[name].append(centroid_error(found.uv, frame.uv_true, usable))
        tracks = star_sources(camera, sensor, q, stars.vectors, stars.v_mag, omega)[0].tracks
        fused = np.flatnonzero(~found.saturated & ~found.edge)[:12]
        nearest = cKDTree(frame.uv_true).query(found.uv[fused])[1]
        smear = tracks[nearest, -1] - tracks[nearest, 0]
        ms, fits = timed(lambda: fit_stars(image, found.uv[fused], sensor.psf_sigma_px, noise, sensor.background_dn,
                                           smear_px=smear, saturation_dn=sensor.saturation_dn))
        rows["fit_12"].append(ms)
        all_fits = fit_stars(image, found.uv[~found.saturated], sensor.psf_sigma_px, noise, sensor.background_dn,
                             smear_px=np.median(tracks[:, -1] - tracks[:, 0], axis=0), saturation_dn=sensor.saturation_dn)
        errors["fit"].append(centroid_error(all_fits.uv[all_fits.usable], frame.uv_true, usable))
        # window mode: 8 windows of 11 x 11 around the 8 brightest predicted stars
        source, index = star_sources(camera, sensor, q, stars.vectors, stars.v_mag, omega)
        order = np.argsort(-source.electrons)[:8]
        windows = Windows.around(source.centroids[order], 5, 1024, 1024)

        window_smear = np.median(source.tracks[order, -1] - source.tracks[order, 0], axis=0)

        def window_frame():
            w = render(sensor, 1024, 1024, [source], rng, windows)
            found_w = detect_windows(w, windows.row0, windows.col0, sensor.background_dn, sensor.noise_dn)
            for k in range(len(order)):  # each window's brightest detection, fitted in its window
                inside = ((found_w.u >= windows.col0[k]) & (found_w.u < windows.col0[k] + windows.size)
                          & (found_w.v >= windows.row0[k]) & (found_w.v < windows.row0[k] + windows.size))
                if inside.any():
                    fit_stars(w[k], found_w.uv[np.flatnonzero(inside)[:1]], sensor.psf_sigma_px, noise,
                              sensor.background_dn, smear_px=window_smear, origin=(windows.row0[k], windows.col0[k]))
            return found_w

        ms, _ = timed(window_frame, repeats=20)
        rows["windows"].append(ms)
        if sep is not None:
            data = image.astype(np.float64)

            def run_sep():
                background = sep.Background(data)
                return sep.extract(data - background.back(), 5.0, err=background.globalrms, minarea=1)

            ms, objects = timed(run_sep)
            rows["sep"].append(ms)
            ms, _ = timed(lambda: sep.extract(data - sensor.background_dn, 5.0, err=sensor.noise_dn, minarea=1))
            rows["sep_given_b"].append(ms)
            errors["sep"].append(centroid_error(np.column_stack([objects["x"], objects["y"]]),
                                                frame.uv_true, usable))
    ms = {key: float(np.median(v)) if v else None for key, v in rows.items()}
    acc = {key: {"matched_fraction": float(np.mean([e[0] for e in v])),
                 "rms_px": float(np.sqrt(np.nanmean([e[1] ** 2 for e in v])))} if v else None
           for key, v in errors.items()}
    result = {
        "frames": N_FRAMES,
        "image": "1024 x 1024 px, 20 deg, V <= 6.5, 100 ms exposure, 0.5 deg/s body rate",
        "stars_per_frame_median": float(np.median(n_stars)),
        "ms_per_frame_median": ms,
        "render_plus_detect_ms": ms["render"] + ms["detect"],
        "render_detect_fit_ms": ms["render"] + ms["detect"] + ms["fit_12"],
        "goals_ms": {"render_detect_fit": 30.0, "window_mode_8x11x11": 2.0},
        "centroid_error": acc,
        "accuracy_against_the_bound": accuracy(stars_per_bin),
        "sep_version": getattr(sep, "__version__", None),
        "sep_note": None if sep is not None else "sep not importable in this environment",
        "machine": {"python": platform.python_version(), "numpy": np.__version__, "processor": platform.machine()},
    }
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(json.dumps(result, indent=1))
    print(f"image chain, {N_FRAMES} frames of 1024 x 1024 px, median {result['stars_per_frame_median']:.0f} stars/frame")
    print(f"  render full frame               {ms['render']:7.2f} ms")
    print(f"  detect + centroid (b estimated) {ms['detect']:7.2f} ms")
    print(f"  detect + centroid (b given)     {ms['detect_given_b']:7.2f} ms")
    print(f"  position fit, 12 stars          {ms['fit_12']:7.2f} ms")
    print(f"  render + detect + fit           {result['render_detect_fit_ms']:7.2f} ms   (goal <= 30 ms)")
    print(f"  window mode, 8 x 11x11 + fit    {ms['windows']:7.3f} ms   (goal <= 2 ms)")
    if sep is not None:
        print(f"  sep {result['sep_version']}: Background + extract  {ms['sep']:7.2f} ms; extract with b given "
              f"{ms['sep_given_b']:7.2f} ms")
    else:
        print("  sep: not importable, no comparison")
    for key, value in acc.items():
        if value:
            print(f"  centroid {key:9s}: matched {value['matched_fraction']:6.1%}, RMS {value['rms_px']:.3f} px")
    _print_accuracy(result["accuracy_against_the_bound"])
    print(f"wrote {OUT}")
    return 0


def _print_accuracy(studies):
    for definition, study in studies.items():
        _print_study(definition, study)


def _print_study(definition, study):
    names = ("fit_from_detection", "fit_from_prediction", "threshold_centroid", "sep_isophotal", "sep_winpos")
    print(f"accuracy against the Cramér-Rao bound by {definition}: RMS/CRB (normalised variance, share beyond 3σ)")
    print(f"{'smear':>5} {'SNR':>9} {'stars':>5} {'det':>5}  " + "  ".join(f"{n:>24}" for n in names))
    for smear, bins in study.items():
        for snr, row in bins.items():
            cells = []
            for name in names:
                e = row.get(name)
                cells.append(f"{'-':>24}" if e is None else f"{e['rms_over_crb']:6.2f}" + (
                    f" ({e['normalised_variance']:5.2f}, {100 * e['beyond_3_sigma']:4.1f}%)" if "normalised_variance" in e
                    else " " * 17) + " ")
            print(f"{smear:>5} {snr:>9} {row['stars']:>5} {100 * (row['detected'] or 0):4.0f}%  " + "  ".join(cells))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--accuracy-stars", type=int, default=300, help="stars per SNR bin and smear of the accuracy study")
    sys.exit(main(parser.parse_args().accuracy_stars))
