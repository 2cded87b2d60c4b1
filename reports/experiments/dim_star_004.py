"""Reproduce the dim-star experiments of document 004 (section 3) with startrack's image chain.

(1) Theory test: 1024 x 1024 px, 20 x 20 deg circular field, Gaussian radius
0.671 px, 12-bit full scale, 120 ms frames, 004's noise (b = 100 DN plus
white N(0, 10^2)), V_th = 150 (eq. 4), V_th' = 500 for 4 frames (eq. 5),
5 px windows, body rate (1, 2, 10) deg/s from boresight (45, 45) deg, roll 0.
50 samples of 4 stars (bright A, B, C: per-frame peak grey uniform in
[200, 240]; dim X: [115, 150]) at random places of the field, each with 32
noise draws.  In each frame the star's charge is set so that its noise-free
peak pixel has the drawn grey level (004 draws the peak of every frame: the
stacked peak of its real-star case, 562, is the sum of the four frame peaks
of Table 4).  Windows are rendered and processed in window mode.

(2) Real-star test near (195, 0) deg: the Hipparcos stars matching SAO
138917, 119674, 139189, 119899 (identified here by position and magnitude),
the four reference attitudes and per-frame peaks of Table 4.

Writes reports/out/dim_star_004.json and two PNG figures; prints our
numbers beside 004's.  Run: .venv/bin/python reports/experiments/dim_star_004.py
"""

import json
import sys
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

from startrack.base.units import DEG  # noqa: E402
from startrack.camera.model import Camera  # noqa: E402
from startrack.catalog.hipparcos import load_star_catalog  # noqa: E402
from startrack.geometry.attitude_angles import quaternion_from_radec_roll, radec_roll_from_quaternion  # noqa: E402
from startrack.geometry.sphere import angular_distance, radec_to_vector  # noqa: E402
from startrack.image.detection import detect, detect_windows  # noqa: E402
from startrack.image.render import SensorModel, Sources, Windows, expected_charge, render  # noqa: E402
from startrack.image.stacking import DimStarCache  # noqa: E402
from startrack.photometry.star_signal import (  # noqa: E402
    detection_threshold,
    snr,
    stackable_snr_range,
    stacked_snr,
    stacked_threshold,
)

ARCMIN = DEG / 60.0
OUT = Path(__file__).resolve().parents[1] / "out"

# Table 1 of 004 and section 3 text
WIDTH = HEIGHT = 1024
FOV = 20.0 * DEG
FRAME_S = 0.120
B, SIGMA_N, A_FACTOR, N_FRAMES, HALF = 100.0, 10.0, 5.0, 4, 2
RATE = np.array([1.0, 2.0, 10.0]) * DEG
BRIGHT_PEAK, DIM_PEAK = (200.0, 240.0), (115.0, 150.0)
N_SAMPLES, N_DRAWS = 50, 32
SEED = 2017

# 004's white-noise model: bias b, read noise sigma_n, unit gain, no shot or dark noise; 12-bit ADC
SENSOR = SensorModel(psf_sigma_px=0.671, exposure_s=FRAME_S, gain_e_per_dn=1.0, bias_dn=B, read_noise_e=SIGMA_N,
                     dark_e_per_px_s=0.0, sky_e_per_px_s=0.0, shot_noise=False, full_scale_dn=4096,
                     full_well_e=1e9)

TABLE2 = {  # frame: (alpha_r, delta_r, gamma_r) [deg]
    "m-3": (45.0, 45.0, 0.0),
    "m-2": (44 + 3 / 60 + 15 / 3600, 45 + 5 / 60 + 13 / 3600, 359 + 38 / 60 + 27 / 3600),
    "m-1": (43 + 6 / 60 + 28 / 3600, 45 + 10 / 60 + 41 / 3600, 359 + 16 / 60 + 59 / 3600),
    "m": (42 + 9 / 60 + 38 / 3600, 45 + 16 / 60 + 24 / 3600, 358 + 55 / 60 + 37 / 3600),
}
TABLE3 = {  # star: (SAO, RA, Dec [deg], magnitude)
    "A": (138917, 190 + 24 / 60 + 54 / 3600, -(1 + 31 / 60 + 5 / 3600), 2.9),
    "B": (119674, 193 + 54 / 60 + 3 / 3600, 3 + 23 / 60 + 51 / 3600, 3.7),
    "C": (139189, 197 + 29 / 60 + 15 / 3600, -(5 + 32 / 60 + 20 / 3600), 4.5),
    "X": (119899, 200 + 25 / 60 + 25 / 3600, 2 + 5 / 60 + 14 / 3600, 5.7),
}
TABLE4_ATTITUDE = [(196.0, 4.0, 0.0), (194.7878, 3.8005, 0.1798), (193.5764, 3.5972, 0.3553),
                   (192.3660, 3.3903, 0.5264)]  # reference (alpha, delta, gamma) [deg], frames m-3..m
TABLE4_PEAK = {"A": [604, 566, 623, 621], "B": [337, 364, 356, 336], "C": [204, 232, 204, None],
               "X": [130, 146, 138, 148]}
TABLE4_UV = {"A": [(795.568, 787.879), (734.524, 776.846), (673.660, 766.141), (612.940, 755.646)],
             "B": [(617.638, 542.298), (556.668, 532.176), (495.716, 522.261), (434.690, 512.351)],
             "C": [(436.135, 997.313), (376.035, 987.761), (315.863, 978.295), None]}


def electrons_for_peak(uv, peak_dn, windows):
    """Charge [e-] whose noise-free peak pixel at ``uv`` is ``peak_dn`` (grey, background included)."""
    unit = expected_charge(SENSOR, HEIGHT, WIDTH, [Sources([uv], [1.0], SENSOR.psf_sigma_px)], windows)
    return (peak_dn - B) / unit.max()


def frame_attitudes(q0):
    """q_IS of frames m-3..m under the constant body rate (scalar-last, q(t) = q0 (x) exp(w t))."""
    return [(Rotation.from_quat(q0) * Rotation.from_rotvec(RATE * FRAME_S * k)).as_quat() for k in range(N_FRAMES)]


def random_field_directions(camera, attitudes, count, rng):
    """Directions inside the circular field (with 10 px margin) of all frames."""
    q_now = attitudes[-1]
    found = []
    while len(found) < count:
        uv = rng.uniform(0, WIDTH - 1, 2)
        v_I = Rotation.from_quat(q_now).apply(camera.unproject(uv))[0]
        ok = all(camera.stars_in_field(q, v_I[None], margin_px=-10.0).size == 1 for q in attitudes)
        if ok:
            found.append(v_I)
    return np.array(found)


def theory_experiment(seed=SEED):
    camera = Camera.from_fov(FOV, WIDTH, HEIGHT, circular_fov=True)
    q0 = quaternion_from_radec_roll(45 * DEG, 45 * DEG, 0.0)
    attitudes = frame_attitudes(q0)
    ours_table2 = [np.degrees(radec_roll_from_quaternion(q)).tolist() for q in attitudes]
    v_th = detection_threshold(B, SIGMA_N, A_FACTOR)
    v_th_stacked = stacked_threshold(B, SIGMA_N, N_FRAMES, A_FACTOR)
    sample_seeds = np.random.SeedSequence(seed).spawn(N_SAMPLES)
    samples = []
    for s, sample_seed in enumerate(sample_seeds):
        geometry_seed, noise_seed = sample_seed.spawn(2)
        rng = np.random.default_rng(geometry_seed)
        directions = random_field_directions(camera, attitudes, 4, rng)  # A, B, C, X
        peaks = np.empty((4, N_FRAMES))
        peaks[:3] = rng.uniform(*BRIGHT_PEAK, (3, N_FRAMES))
        peaks[3] = rng.uniform(*DIM_PEAK, N_FRAMES)
        uv_x = np.array([camera.project(q, directions[3:])[0][0] for q in attitudes])  # (frames, 2)
        windows = [Windows.around(uv, HALF, HEIGHT, WIDTH) for uv in uv_x]
        sources = [Sources([uv], [electrons_for_peak(uv, p, w)], SENSOR.psf_sigma_px)
                   for uv, p, w in zip(uv_x, peaks[3], windows)]
        noise_rng = np.random.default_rng(noise_seed)
        single_peak, stacked_peak, single_found, stacked_found, errors, corrected, identity = [], [], [], [], [], [], []
        for _ in range(N_DRAWS):
            cache = DimStarCache(HALF, N_FRAMES)
            for k in range(N_FRAMES):
                window = render(SENSOR, HEIGHT, WIDTH, [sources[k]], noise_rng, windows[k])
                cache.push_window(window[0], uv_x[k], star_id=s)
                if k == N_FRAMES - 1:
                    found = detect_windows(window, windows[k].row0, windows[k].col0, B, SIGMA_N, A_FACTOR)
                    single_found.append(len(found) > 0)
                    single_peak.append(float(window.max()))
            result = cache.stack(B, SIGMA_N, A_FACTOR)
            stacked_found.append(result.detected)
            stacked_peak.append(result.peak)
            identity.append(np.hypot(*np.subtract(result.grey_uv_direct, result.grey_uv_eq17)))
            if result.detected:
                errors.append(np.hypot(result.u - uv_x[-1, 0], result.v - uv_x[-1, 1]))
                corrected.append(np.hypot(result.u_corrected - uv_x[-1, 0], result.v_corrected - uv_x[-1, 1]))
        a_p0, a_p = float(np.mean(single_peak)), float(np.mean(stacked_peak))
        samples.append({
            "peaks_X_noise_free_dn": peaks[3].tolist(),
            "mean_single_peak_dn": a_p0,
            "mean_stacked_peak_dn": a_p,
            "single_detection_rate": float(np.mean(single_found)),
            "stacked_detection_rate": float(np.mean(stacked_found)),
            "snr_single": float(snr(a_p0, B, SIGMA_N)),
            "snr_stacked": float(stacked_snr(a_p, B, SIGMA_N, N_FRAMES)),
            "stacked_centroid_rms_px": float(np.sqrt(np.mean(np.square(errors)))) if errors else None,
            "stacked_centroid_corrected_rms_px": float(np.sqrt(np.mean(np.square(corrected)))) if corrected else None,
            "eq17_identity_max_px": float(np.max(identity)),
        })
    a_p0 = np.array([s["mean_single_peak_dn"] for s in samples])
    a_p = np.array([s["mean_stacked_peak_dn"] for s in samples])
    noise_free_current = np.array([s["peaks_X_noise_free_dn"][-1] for s in samples])
    noise_free_sum = np.array([np.sum(s["peaks_X_noise_free_dn"]) for s in samples])
    gain = np.array([s["snr_stacked"] / s["snr_single"] for s in samples])
    gain_noise_free = (noise_free_sum - N_FRAMES * B) / (np.sqrt(N_FRAMES) * (noise_free_current - B))
    centroid_rms = [s["stacked_centroid_rms_px"] for s in samples if s["stacked_centroid_rms_px"] is not None]
    corrected_rms = [s["stacked_centroid_corrected_rms_px"] for s in samples
                     if s["stacked_centroid_corrected_rms_px"] is not None]
    return {
        "parameters": {
            "width_px": WIDTH, "height_px": HEIGHT, "fov_deg": 20.0, "psf_sigma_px": SENSOR.psf_sigma_px,
            "full_scale_dn": SENSOR.full_scale_dn, "frame_s": FRAME_S, "b_dn": B, "sigma_n_dn": SIGMA_N,
            "a": A_FACTOR, "n_frames": N_FRAMES, "window_px": 2 * HALF + 1, "rate_deg_s": [1.0, 2.0, 10.0],
            "samples": N_SAMPLES, "noise_draws": N_DRAWS, "seed": SEED,
            "V_th_dn": v_th, "V_th_stacked_dn": v_th_stacked,
            "stackable_snr_range_eq7": list(stackable_snr_range(N_FRAMES, A_FACTOR)),
        },
        "attitudes_deg": {"ours_body_rate": ours_table2, "004_table2": list(TABLE2.values())},
        "detection": {
            "single_frame_per_sample_mean_peak": float(np.mean(a_p0 >= v_th)),
            "stacked_per_sample_mean_peak": float(np.mean(a_p >= v_th_stacked)),
            "single_frame_noise_free_peak": float(np.mean(noise_free_current >= v_th)),
            "stacked_noise_free_peak_sum": float(np.mean(noise_free_sum >= v_th_stacked)),
            "single_frame_per_draw": float(np.mean([s["single_detection_rate"] for s in samples])),
            "stacked_per_draw": float(np.mean([s["stacked_detection_rate"] for s in samples])),
            "004": {"single_frame": 0.0, "stacked": 0.92},
        },
        "snr_gain": {"mean": float(np.mean(gain)), "median": float(np.median(gain)),
                     "mean_noise_free_peaks": float(np.mean(gain_noise_free)),
                     "004_mean": 2.283, "static_sqrt_n_eq3": float(np.sqrt(N_FRAMES))},
        "stacked_centroid_rms_px": float(np.sqrt(np.mean(np.square(centroid_rms)))),
        "stacked_centroid_phase_corrected_rms_px": float(np.sqrt(np.mean(np.square(corrected_rms)))),
        "eq17_identity_max_px": float(max(s["eq17_identity_max_px"] for s in samples)),
        "samples": samples,
    }


def identify_table3(catalog):
    """HIP star nearest to each SAO entry of Table 3 among stars brighter than V = 7."""
    bright = catalog.brighter_than(7.0)
    rows = {}
    for name, (sao, ra, dec, mag) in TABLE3.items():
        target = radec_to_vector(ra * DEG, dec * DEG)
        sep = angular_distance(bright.vectors, target)
        order = np.argsort(sep)
        best, second = order[0], order[1]
        rows[name] = {
            "sao": sao, "hip": int(bright.hip[best]), "sep_arcmin": float(sep[best] / ARCMIN),
            "v_mag": float(bright.v_mag[best]), "table3_mag": mag,
            "next_star_sep_arcmin": float(sep[second] / ARCMIN), "next_star_v_mag": float(bright.v_mag[second]),
            "index": int(np.flatnonzero(catalog.hip == bright.hip[best])[0]),
        }
    return rows


def real_star_experiment(catalog, n_noise=200):
    ident = identify_table3(catalog)
    camera = Camera.from_fov(FOV, WIDTH, HEIGHT, circular_fov=True)
    names = list(TABLE3)
    vectors = catalog.vectors[[ident[n]["index"] for n in names]]
    attitudes = [quaternion_from_radec_roll(a * DEG, d * DEG, g * DEG) for a, d, g in TABLE4_ATTITUDE]
    projected, visible = zip(*(camera.project(q, vectors) for q in attitudes))
    projected, visible = np.array(projected), np.array(visible)  # (frames, stars, 2), (frames, stars)
    flip = WIDTH - 1 - projected  # 004's image axes are ours turned by 180 deg about the centre
    residual = {n: [None if TABLE4_UV.get(n, [None] * 4)[k] is None else
                    np.subtract(TABLE4_UV[n][k], flip[k, j]).tolist() for k in range(N_FRAMES)]
                for j, n in enumerate(names) if n in TABLE4_UV}
    rng = np.random.default_rng(np.random.SeedSequence(SEED).spawn(2)[1])
    detected_sets = []
    single_x, stacked_x, centroid_err, corrected_err, ap = [], [], [], [], []
    frame_sources = []
    for k in range(N_FRAMES):
        uvs, charges = [], []
        for j, n in enumerate(names):
            peak = TABLE4_PEAK[n][k]
            if peak is None or not visible[k, j]:
                continue
            uvs.append(projected[k, j])
            charges.append(electrons_for_peak(projected[k, j], peak, None))
        frame_sources.append(Sources(np.array(uvs), charges, SENSOR.psf_sigma_px))
    example = None
    for draw in range(n_noise):
        cache = DimStarCache(HALF, N_FRAMES)
        seen = []
        frames = []
        for k in range(N_FRAMES):
            frame = render(SENSOR, HEIGHT, WIDTH, [frame_sources[k]], rng)
            frames.append(frame)
            found = detect(frame, background=B, sigma_n=SIGMA_N, a=A_FACTOR)
            names_found = []
            for j, n in enumerate(names):
                if visible[k, j] and len(found) and np.min(np.hypot(found.u - projected[k, j, 0],
                                                                    found.v - projected[k, j, 1])) < 1.5:
                    names_found.append(n)
            seen.append("".join(names_found))
            cache.push(frame, projected[k, 3], star_id=TABLE3["X"][0])
        single_x.append("X" in seen[-1])
        result = cache.stack(B, SIGMA_N, A_FACTOR)
        stacked_x.append(result.detected)
        ap.append(result.peak)
        if result.detected:
            centroid_err.append(np.hypot(result.u - projected[-1, 3, 0], result.v - projected[-1, 3, 1]))
            corrected_err.append(np.hypot(result.u_corrected - projected[-1, 3, 0],
                                          result.v_corrected - projected[-1, 3, 1]))
        detected_sets.append(seen)
        if example is None:
            example = {"frames": frames, "result": result, "seen": seen}
    most_common = max(set(map(tuple, detected_sets)), key=lambda s: sum(tuple(d) == s for d in detected_sets))
    result = example["result"]
    return {
        "identification": {n: {k: v for k, v in r.items() if k != "index"} for n, r in ident.items()},
        "projected_uv_ours": {n: projected[:, j].tolist() for j, n in enumerate(names)},
        "in_circular_field": {n: visible[:, j].tolist() for j, n in enumerate(names)},
        "table4_minus_ours_turned_180deg_px": residual,
        "detected_stars_most_common": list(most_common),
        "004_detected": ["ABC", "ABC", "ABC", "AB"],
        "X_single_frame_detection_rate": float(np.mean(single_x)),
        "X_stacked_detection_rate": float(np.mean(stacked_x)),
        "X_stacked_peak_mean_dn": float(np.mean(ap)),
        "X_stacked_peak_noise_free_dn": float(np.sum(TABLE4_PEAK["X"])),
        "004_X_stacked_peak_dn": 562,
        "X_stacked_centroid_rms_px": float(np.sqrt(np.mean(np.square(centroid_err)))) if centroid_err else None,
        "X_stacked_centroid_phase_corrected_rms_px":
            float(np.sqrt(np.mean(np.square(corrected_err)))) if corrected_err else None,
        "noise_draws": n_noise,
        "example": {"detected": example["seen"], "X_stacked_peak_dn": result.peak, "X_detected": result.detected,
                    "X_uv": [result.u, result.v], "X_uv_true": projected[-1, 3].tolist(),
                    "eq14_uv": list(result.grey_uv_direct), "eq17_uv": list(result.grey_uv_eq17)},
    }, example


def figures(theory, real_example):
    OUT.mkdir(parents=True, exist_ok=True)
    samples = theory["samples"]
    x = np.arange(1, len(samples) + 1)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4))
    axes[0].plot(x, [s["mean_single_peak_dn"] for s in samples], "o", label="A_p0 (current frame, mean of 32)")
    axes[0].axhline(theory["parameters"]["V_th_dn"], color="r", label="V_th = 150")
    axes[0].set(xlabel="sample", ylabel="peak grey [DN]", title="004 Fig. 3: single frame")
    axes[1].plot(x, [s["mean_stacked_peak_dn"] for s in samples], "s", label="A_p (4 frames stacked)")
    axes[1].axhline(theory["parameters"]["V_th_stacked_dn"], color="r", label="V_th' = 500")
    axes[1].set(xlabel="sample", ylabel="peak grey [DN]", title="004 Fig. 4: stacked")
    axes[2].hist([s["snr_stacked"] / s["snr_single"] for s in samples], bins=15)
    axes[2].axvline(2.283, color="r", label="004 mean 2.283")
    axes[2].axvline(theory["snr_gain"]["mean"], color="k", ls="--", label="ours mean")
    axes[2].set(xlabel="SNR gain R'_SNR / R_SNR", ylabel="samples", title="SNR gain (eq. 1-3)")
    for ax in axes:
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "dim_star_004_theory.png", dpi=110)
    plt.close(fig)
    frames, result = real_example["frames"], real_example["result"]
    fig, axes = plt.subplots(1, 5, figsize=(16, 3.4))
    for k, (frame, centre) in enumerate(zip(frames, result.centres[::-1])):
        r, c = centre
        axes[k].imshow(frame[r - 6 : r + 7, c - 6 : c + 7], cmap="gray", vmin=80, vmax=170)
        axes[k].set_title(f"X, frame m-{3 - k}" if k < 3 else "X, frame m")
    axes[4].imshow(result.window, cmap="gray")
    axes[4].set_title(f"stacked 5x5, peak {result.peak:.0f} DN")
    fig.tight_layout()
    fig.savefig(OUT / "dim_star_004_real.png", dpi=110)
    plt.close(fig)


def main():
    start = time.perf_counter()
    theory = theory_experiment()
    catalog = load_star_catalog(2000.0)
    real, example = real_star_experiment(catalog)
    figures(theory, example)
    OUT.mkdir(parents=True, exist_ok=True)
    notes = [
        "004 Table 2 is not reproduced by q(t) = q0 exp(w t) with w = (1, 2, 10) deg/s over 120 ms frames for any of the "
        "7 sign and axis assignments tried; ours follows the body-rate kinematics (docs/design.md) and both are listed.",
        "Table 3 prints Dec -1 31' 05\" for SAO 138917 (gamma Vir); Hipparcos HIP 61941 is at -1 26' 58\" (4.1'), "
        "yet projecting HIP 61941 reproduces 004's Table 4 centroid of A to ~1 px, so Table 3's Dec is a misprint.",
        "004's image axes are ours turned by 180 deg about the centre: its (x, y) = (W - 1 - u, H - 1 - v).",
        "Only the four stars of Table 3 are rendered, as in 004; Hipparcos has about 22-25 stars with V < 6 in "
        "this 20 deg circular field.",
        "Detection rates are given three ways: 004 judges the peak grey per sample (noise-free or averaged), "
        "the detector sees each noisy frame, where a peak of 140-150 DN crosses V_th = 150 by noise.",
    ]
    report = {"theory": theory, "real_stars": real, "notes": notes, "seconds": time.perf_counter() - start}
    (OUT / "dim_star_004.json").write_text(json.dumps(report, indent=1))
    d, g = theory["detection"], theory["snr_gain"]
    print("004 theory test (50 samples x 32 noise draws)             ours      004")
    print(f"  single-frame detection, per sample (mean peak >= V_th)  {d['single_frame_per_sample_mean_peak']:6.1%}    0 %")
    print(f"  single-frame detection, noise-free peak >= V_th         {d['single_frame_noise_free_peak']:6.1%}")
    print(f"  single-frame detection, per noise draw (detector)       {d['single_frame_per_draw']:6.1%}")
    print(f"  stacked detection, per sample (mean peak >= V_th')      {d['stacked_per_sample_mean_peak']:6.1%}   92 %")
    print(f"  stacked detection, per noise draw (detector)            {d['stacked_per_draw']:6.1%}")
    print(f"  stacked detection, noise-free peak sum >= V_th'         {d['stacked_noise_free_peak_sum']:6.1%}")
    print(f"  mean SNR gain, eq. 1 with noise-free peaks              {g['mean_noise_free_peaks']:6.3f}    2.283  (sqrt(n) = 2)")
    print(f"  mean SNR gain, eq. 1 with measured peaks (mean of 32)   {g['mean']:6.3f}")
    print(f"  stacked centroid RMS error [px] (eq. 14-18)             {theory['stacked_centroid_rms_px']:6.3f}")
    print(f"  ... with the predicted sub-pixel phase correction [px]  {theory['stacked_centroid_phase_corrected_rms_px']:6.3f}")
    print(f"  max |eq. 14 - eq. 17| [px]                              {theory['eq17_identity_max_px']:.1e}")
    print("  attitudes (RA, Dec, roll) [deg]: ours from the body rate | 004 Table 2")
    for ours, table in zip(theory["attitudes_deg"]["ours_body_rate"], theory["attitudes_deg"]["004_table2"]):
        print(f"    ({ours[0]:8.4f}, {ours[1]:8.4f}, {ours[2]:8.4f}) | ({table[0]:8.4f}, {table[1]:8.4f}, {table[2]:8.4f})")
    print("004 real-star test near (195, 0) deg")
    for name, row in real["identification"].items():
        print(f"  {name}: SAO {row['sao']} = HIP {row['hip']} (V {row['v_mag']:.2f}, Table 3: {row['table3_mag']}), "
              f"{row['sep_arcmin']:.2f}' from Table 3's position; next V<7 star {row['next_star_sep_arcmin']:.1f}' away")
    print(f"  detected stars per frame (most common): {real['detected_stars_most_common']}   004: {real['004_detected']}")
    for name, res in real["table4_minus_ours_turned_180deg_px"].items():
        text = ", ".join("-" if r is None else f"({r[0]:+.2f}, {r[1]:+.2f})" for r in res)
        print(f"  Table 4 centroid minus ours turned 180 deg, {name}: {text} px")
    print(f"  X single-frame detection rate over {real['noise_draws']} draws: {real['X_single_frame_detection_rate']:.1%}"
          f"  (004: not detectable)")
    print(f"  X stacked detection rate: {real['X_stacked_detection_rate']:.1%}; stacked peak mean "
          f"{real['X_stacked_peak_mean_dn']:.1f} DN (noise-free sum {real['X_stacked_peak_noise_free_dn']:.0f}; 004: 562)")
    print(f"  X stacked centroid RMS error: {real['X_stacked_centroid_rms_px']:.3f} px "
          f"({real['X_stacked_centroid_phase_corrected_rms_px']:.3f} px with the sub-pixel phase correction)")
    for note in notes:
        print(f"  note: {note}")
    print(f"wrote {OUT / 'dim_star_004.json'} and figures in {report['seconds']:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
