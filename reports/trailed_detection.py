"""Detection completeness of faint trailed stars (issue 53 item 6): 004's threshold against the matched filter.

Frames "like the colleague's": 1024 x 1024 px rendered by :func:`startrack.image.render.render` (the project's
renderer: Gaussian PSF σ = 0.8 px integrated over each pixel and averaged along the track, sky 100 e-/px, read
noise 5 e-, gain 1 e-/DN, bias 100 DN, 16 bits, no saturation below 65535 DN; the sky's shot noise and the read
noise drawn as one Gaussian, the stars' charge from the Poisson law).  Each frame holds 100 stars on a 10 x 10
grid (100 px apart) at random offsets of ±20 px and random sub-pixel phases, 20 of each total charge 300, 600,
900, 1200 and 2400 e-, all with the same trail of 0, 3, 6 or 12 px at the frame's random angle (one body rate
smears every star alike); ``--frames`` frames per trail length.

Both detectors run with the background and noise estimated from the frame: 004's thresholded path
(:func:`startrack.image.detection.detect`, V_th = b + 5 σ_n, as it is; and, column "cli", as ``startrack detect``
runs it: the detections flagged ``single_pixel`` or ``extended`` dropped) and the matched filter
(:func:`startrack.image.trail_detection.detect_trailed`, the frame's trail known, threshold for 0.01 false
detections per frame by eq. 4 of that module).  A star is found when a detection lies within 1.5 px + L/2 of
its true track centre; a detection near no star is false.  Per (charge, trail): the completeness of each, the
closed form P_D (eq. 3 of the module, at the frame's angles) and the optimal SNR; the RMS position error of the
matched filter's detections per axis, from the refined peak (``fit=False``) and after the position fit
(``fit=True``), over the Cramér-Rao bound (:func:`startrack.image.psf_fit.centroid_variance`, both axes and the
phases pooled).  Blank frames (sky only): the false detections per frame and per megapixel of both, the matched
filter at its default threshold and at one set for 2 per frame, each beside eq. 4's expectation; the false
detections on the star frames.  Timing: the median of the matched filter per frame, the first call for the frame's
trail (``fit=False``, its threshold's draws made) and the second (``fit=True``, the threshold cached).

Writes reports/out/trailed_detection.json (git-ignored); prints the tables.
Run: PYTHONPATH=. .venv/bin/python reports/trailed_detection.py [--frames 20] [--blank 100]
"""

import argparse
import json
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from startrack.image.detection import detect
from startrack.image.psf_fit import centroid_variance, track_offsets
from startrack.image.render import SensorModel, Sources, render
from startrack.image.trail_detection import (
    FALSE_ALARMS_PER_FRAME,
    detect_trailed,
    detection_probability,
    expected_false_peaks,
    snr_threshold,
    trail_vector,
)

OUT = Path(__file__).resolve().parent / "out"
SIZE, GRID, JITTER_PX = 1024, 10, 20.0
CHARGES_E = (300.0, 600.0, 900.0, 1200.0, 2400.0)
TRAILS_PX = (0.0, 3.0, 6.0, 12.0)
SENSOR = SensorModel(psf_sigma_px=0.8, exposure_s=1.0, sky_e_per_px_s=100.0, dark_e_per_px_s=0.0, read_noise_e=5.0,
                     gain_e_per_dn=1.0, bias_dn=100.0, full_well_e=1.0e6, full_scale_dn=65536)
#: A pixel's variance without a star [DN²]: sky, read noise and the rounding to whole DN.
PIXEL_VARIANCE = SENSOR.noise_dn**2 + 1.0 / 12.0
GATE_PX = 1.5


def star_frame(rng, trail):
    """(image, true centres (100, 2), charges (100,)): the module's frame with every star trailed by ``trail``."""
    spacing = SIZE / GRID
    centres = (np.stack(np.meshgrid(np.arange(GRID), np.arange(GRID)), -1).reshape(-1, 2) + 0.5) * spacing
    centres = centres + rng.uniform(-JITTER_PX, JITTER_PX, centres.shape)
    charges = rng.permutation(np.repeat(CHARGES_E, GRID * GRID // len(CHARGES_E)))
    su, sv = track_offsets(trail, SENSOR.psf_sigma_px)
    tracks = centres[:, None, :] + np.stack([su, sv], -1)[None]
    image = render(SENSOR, SIZE, SIZE, [Sources(tracks, charges, SENSOR.psf_sigma_px)], rng)
    return image, centres, charges


def matches(found_uv, centres, gate):
    """(index of the nearest detection of each star or -1, number of detections near no star)."""
    if len(found_uv) == 0:
        return np.full(len(centres), -1), 0
    distance, nearest = cKDTree(found_uv).query(centres)
    hit = np.where(distance <= gate, nearest, -1)
    star_distance, _ = cKDTree(centres).query(found_uv)
    return hit, int(np.count_nonzero(star_distance > gate))


def run_trail(length, frames, rng):
    """Per-star records of the frames with trails of ``length``: found by each detector, errors, P_D."""
    rec = {k: [] for k in ("charge", "detect", "detect_cli", "mf", "pd", "snr_opt", "err_peak", "err_fit")}
    false = {"detect": 0, "detect_cli": 0, "mf": 0}
    timing, timing_fit = [], []
    for _ in range(frames):
        trail = trail_vector(length, rng.uniform(0.0, np.pi))
        image, centres, charges = star_frame(rng, trail)
        gate = GATE_PX + 0.5 * length
        hit_t, false_t = matches(detect(image).uv, centres, gate)
        hit_c, false_c = matches(detect(image, reject_single_pixels=True, reject_extended=True).uv, centres, gate)
        start = time.perf_counter()
        peaks = detect_trailed(image, SENSOR.psf_sigma_px, trail, fit=False)
        timing.append(time.perf_counter() - start)
        start = time.perf_counter()
        fitted = detect_trailed(image, SENSOR.psf_sigma_px, trail, gain_e_per_dn=SENSOR.gain_e_per_dn)
        timing_fit.append(time.perf_counter() - start)
        hit_m, false_m = matches(fitted.uv, centres, gate)
        hit_p, _ = matches(peaks.uv, centres, gate)
        false["detect"] += false_t
        false["detect_cli"] += false_c
        false["mf"] += false_m
        threshold = snr_threshold(FALSE_ALARMS_PER_FRAME, image.shape, SENSOR.psf_sigma_px, trail)
        pd, snr = detection_probability(np.array(CHARGES_E) / SENSOR.gain_e_per_dn, SENSOR.psf_sigma_px, trail,
                                        np.sqrt(PIXEL_VARIANCE), threshold, SENSOR.gain_e_per_dn)
        level = {c: k for k, c in enumerate(CHARGES_E)}
        for i, charge in enumerate(charges):
            rec["charge"].append(charge)
            rec["detect"].append(hit_t[i] >= 0)
            rec["detect_cli"].append(hit_c[i] >= 0)
            rec["mf"].append(hit_m[i] >= 0)
            rec["pd"].append(pd[level[charge]])
            rec["snr_opt"].append(snr[level[charge]])
            rec["err_peak"].append(peaks.uv[hit_p[i]] - centres[i] if hit_p[i] >= 0 else (np.nan, np.nan))
            rec["err_fit"].append(fitted.uv[hit_m[i]] - centres[i] if hit_m[i] >= 0 else (np.nan, np.nan))
    return {k: np.array(v) for k, v in rec.items()}, false, (timing, timing_fit)


def blank_frames(count, rng):
    """False detections on sky-only frames: 004's, the matched filter's at its default threshold and at one set
    for 2 per frame (trail 6 px at random angles), each beside eq. 4."""
    counts = {"detect": 0, "mf_default": 0, "mf_2_per_frame": 0}
    expected = {"mf_default": 0.0, "mf_2_per_frame": 0.0}
    for _ in range(count):
        trail = trail_vector(6.0, rng.uniform(0.0, np.pi))
        image = render(SENSOR, SIZE, SIZE, [], rng)
        counts["detect"] += len(detect(image))
        counts["mf_default"] += len(detect_trailed(image, SENSOR.psf_sigma_px, trail, fit=False))
        counts["mf_2_per_frame"] += len(detect_trailed(image, SENSOR.psf_sigma_px, trail, false_alarms=2.0, fit=False))
        for name, rate in (("mf_default", FALSE_ALARMS_PER_FRAME), ("mf_2_per_frame", 2.0)):
            u = snr_threshold(rate, image.shape, SENSOR.psf_sigma_px, trail)
            expected[name] += float(expected_false_peaks(u, image.shape, SENSOR.psf_sigma_px, trail))
    megapixels = SIZE * SIZE / 1e6
    return {name: {"frames": count, "detections": n, "per_frame": n / count, "per_megapixel": n / count / megapixels,
                   "expected_per_frame": expected[name] / count if name in expected else None}
            for name, n in counts.items()}


def rms_over_bound(errors, charges, length):
    """RMS per axis of the errors (m, 2) [px] over the RMS of the Cramér-Rao bound (mean of both axes)."""
    good = np.all(np.isfinite(errors), axis=1)
    if not good.any():
        return None, None, 0
    bound = centroid_variance(charges[good], PIXEL_VARIANCE, SENSOR.psf_sigma_px, length)
    rms = float(np.sqrt(np.mean(errors[good] ** 2)))
    return rms, rms / float(np.sqrt(np.mean(bound))), int(good.sum())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20, help="star frames per trail length (100 stars each)")
    parser.add_argument("--blank", type=int, default=100, help="sky-only frames for the false-detection rate")
    parser.add_argument("--seed", type=int, default=53)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    started = time.perf_counter()
    table, false_on_stars, timing, timing_fit = [], {}, [], []
    for length in TRAILS_PX:
        rec, false, times = run_trail(length, args.frames, rng)
        false_on_stars[str(length)] = {k: {"detections": v, "per_frame": v / args.frames} for k, v in false.items()}
        timing += times[0]
        timing_fit += times[1]
        for charge in CHARGES_E:
            sel = rec["charge"] == charge
            n = int(sel.sum())
            peak = rms_over_bound(rec["err_peak"][sel], rec["charge"][sel], length)
            fit = rms_over_bound(rec["err_fit"][sel], rec["charge"][sel], length)
            table.append({"charge_e": charge, "trail_px": length, "stars": n,
                          "detect": float(rec["detect"][sel].mean()),
                          "detect_cli": float(rec["detect_cli"][sel].mean()), "matched_filter": float(rec["mf"][sel].mean()),
                          "closed_form_pd": float(rec["pd"][sel].mean()), "snr_opt": float(rec["snr_opt"][sel].mean()),
                          "binomial_sigma": float(np.sqrt(max(rec["mf"][sel].mean() * (1 - rec["mf"][sel].mean()), 0.25 / n) / n)),
                          "peak_rms_px": peak[0], "peak_rms_over_bound": peak[1],
                          "fit_rms_px": fit[0], "fit_rms_over_bound": fit[1], "fit_stars": fit[2]})
    blank = blank_frames(args.blank, rng)
    report = {"sensor": {"psf_sigma_px": SENSOR.psf_sigma_px, "sky_e": 100.0, "read_noise_e": 5.0, "gain_e_per_dn": 1.0,
                         "pixel_variance_dn2": PIXEL_VARIANCE},
              "frames_per_trail": args.frames, "stars_per_frame": GRID * GRID, "gate_px": "1.5 + L/2",
              "false_alarms_per_frame_setting": FALSE_ALARMS_PER_FRAME, "table": table,
              "false_on_star_frames": false_on_stars, "blank_frames": blank,
              "matched_filter_ms_median": 1e3 * float(np.median(timing)),
              "matched_filter_fit_warm_ms_median": 1e3 * float(np.median(timing_fit)), "seconds": time.perf_counter() - started}
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / "trailed_detection.json").write_text(json.dumps(report, indent=1))
    print(f"completeness ({args.frames} frames x 100 stars per trail; gate 1.5 px + L/2)")
    print(f"{'N_e':>6} {'L':>4} {'n':>5} {'detect':>7} {'cli':>6} {'MF':>7} {'P_D(3)':>7} {'SNRopt':>7} "
          f"{'peak rms':>9} {'/CRB':>5} {'fit rms':>8} {'/CRB':>5}")
    for row in table:
        fmt = (lambda x, f: "   -" if x is None else format(x, f))
        print(f"{row['charge_e']:6.0f} {row['trail_px']:4.0f} {row['stars']:5d} {row['detect']:7.3f} {row['detect_cli']:6.3f} "
              f"{row['matched_filter']:7.3f} {row['closed_form_pd']:7.3f} {row['snr_opt']:7.2f} "
              f"{fmt(row['peak_rms_px'], '9.3f')} {fmt(row['peak_rms_over_bound'], '5.2f')} "
              f"{fmt(row['fit_rms_px'], '8.3f')} {fmt(row['fit_rms_over_bound'], '5.2f')}")
    print("false detections on star frames (per frame):",
          {k: {d: round(v[d]["per_frame"], 3) for d in v} for k, v in false_on_stars.items()})
    for name, row in blank.items():
        expected = "" if row["expected_per_frame"] is None else f", eq. 4 expects {row['expected_per_frame']:.3f}"
        print(f"blank {name}: {row['detections']} in {row['frames']} frames = {row['per_frame']:.3f} per frame, "
              f"{row['per_megapixel']:.3f} per Mpx{expected}")
    print(f"matched filter per 1024x1024 frame, median: {report['matched_filter_ms_median']:.0f} ms (fit=False, the "
          f"frame's trail new: its threshold drawn), {report['matched_filter_fit_warm_ms_median']:.0f} ms (fit=True, "
          f"same trail again); wrote {OUT / 'trailed_detection.json'} in {report['seconds']:.0f} s")


if __name__ == "__main__":
    main()
