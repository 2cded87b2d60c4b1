"""``startrack detect`` on faint trailed stars (issue 64 item 6): the threshold detector against the trail's matched
filter (``--smear-px``), as the command line runs them.

Frames: 512 x 512 px drawn without the project's renderer (tests/star_images.py: a Gaussian PSF σ = 0.8 px
integrated over each pixel along a 256-point track, Poisson sky of 100 e- and star charge, read noise 5 e-, gain
1 e-/DN, bias 100 DN, whole DN), written as 16-bit PNG files; 100 stars of 600 e- a frame on a 10 x 10 grid (51 px
apart, ±10 px at random), all trailed 6 px along u (the issue's case).  Each frame through ``startrack detect
FRAME --json`` in this process: the threshold detector (``--psf-sigma-px 0.8 --gain-e-per-dn 1``: 004's
threshold, its stars fitted without the trail) and the matched filter (``--smear-px 6,0`` too).  A star is found
when a detection lies within 1.5 px + L/2 of its track centre; a detection near no star is false.

Per detector: the completeness with its Clopper-Pearson 95 % interval, the false detections per frame, the median
wall time per frame (the command's ``detect_ms``: detection and fit, the file read excluded; the first frame
pays the matched filter's threshold draws and is left out).  For the matched filter's usable fits: the RMS of
the errors normalised by the reported σ per axis, NEES/dof (Σ eᵀC⁻¹e / 2n), the mean and range of the reported σ
over the Cramér-Rao bound at the truth (:func:`startrack.image.psf_fit.centroid_bound`), the RMS error over the
RMS bound per axis.  Sky-only frames: the matched filter's false detections per frame at its default setting
(0.01) and at 2 per frame, beside eq. 4 of trail_detection (Gaussian noise) and that lifted by the Poisson
sky's skewness (Edgeworth, as tests/startrack/test_detect_trailed_command.py).

Writes benchmarks/results/detect_trailed_command.json; asserts nothing.

    .venv/bin/python benchmarks/detect_trailed_command.py [--frames 10] [--blank 100] [--seed 64]
"""

import argparse
import contextlib
import io
import json
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree
from scipy.stats import beta

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

from startrack import cli  # noqa: E402
from startrack.image.files import write_image  # noqa: E402
from startrack.image.psf_fit import PixelNoise, centroid_bound  # noqa: E402
from startrack.image.trail_detection import expected_false_peaks, snr_threshold, trail_template  # noqa: E402
from tests.star_images import noisy_frame, poisson_sky_lift  # noqa: E402

SIZE, GRID, SIGMA, CHARGE_E, TRAIL, SKY_E, READ_E = 512, 10, 0.8, 600.0, (6.0, 0.0), 100.0, 5.0
GATE_PX = 1.5 + 0.5 * np.hypot(*TRAIL)
NOISE = PixelNoise(np.sqrt(SKY_E + READ_E**2), gain_e_per_dn=1.0)
DETECTORS = {"threshold": ("--psf-sigma-px", "0.8", "--gain-e-per-dn", "1"),
             "matched_filter": ("--psf-sigma-px", "0.8", "--smear-px", "6,0", "--gain-e-per-dn", "1")}


def star_frame(rng):
    """(image [DN], true track centres (100, 2) [px]) (module text)."""
    centres = (np.stack(np.meshgrid(np.arange(GRID), np.arange(GRID)), -1).reshape(-1, 2) + 0.5) * SIZE / GRID
    centres = centres + rng.uniform(-10.0, 10.0, centres.shape)
    return noisy_frame(rng, (SIZE, SIZE), [(u, v, CHARGE_E, TRAIL) for u, v in centres], SIGMA, SKY_E, READ_E), centres


def detect_json(path, options):
    """``startrack detect path options --json``'s answer, run in this process."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        cli.main(["detect", str(path), *options, "--json"])
    return json.loads(out.getvalue())


def score(answer, centres):
    """(found per star (bool), false detections, [(error (2,), covariance (2, 2), bound (2, 2))] of usable fits)."""
    stars = answer["stars"]
    uv = np.array([[s["u"], s["v"]] for s in stars]).reshape(-1, 2)
    if not len(uv):
        return np.zeros(len(centres), bool), 0, []
    distance, nearest = cKDTree(uv).query(centres)
    fits = []
    for centre, d, k in zip(centres, distance, nearest):
        fit = stars[k]["psf_fit"]
        if d <= GATE_PX and not (fit["failed"] or fit["blended"]):
            fits.append((np.array([fit["u"], fit["v"]]) - centre, np.array(fit["cov_uv_px2"]),
                         centroid_bound(centre, CHARGE_E, SIGMA, NOISE, TRAIL)))
    return distance <= GATE_PX, int(np.sum(cKDTree(centres).query(uv)[0] > GATE_PX)), fits


def fit_statistics(fits):
    """The usable fits' normalised errors and σ against the bound (module text)."""
    errors, cov, bound = (np.array([f[i] for f in fits]) for i in range(3))
    sigma = np.sqrt(np.diagonal(cov, axis1=1, axis2=2))
    crb = np.sqrt(np.diagonal(bound, axis1=1, axis2=2))
    nees = np.einsum("ni,nij,nj->n", errors, np.linalg.inv(cov), errors)
    ratio = sigma / crb
    return {"fits": len(errors), "normalised_error_rms_uv": np.sqrt(np.mean((errors / sigma) ** 2, axis=0)).tolist(),
            "nees_per_dof": float(nees.mean() / 2.0), "sigma_over_crb_mean": float(ratio.mean()),
            "sigma_over_crb_range": [float(ratio.min()), float(ratio.max())],
            "rms_error_px_uv": np.sqrt(np.mean(errors**2, axis=0)).tolist(),
            "rms_error_over_rms_crb_uv": (np.sqrt(np.mean(errors**2, axis=0) / np.mean(crb**2, axis=0))).tolist(),
            "mean_error_px_uv": errors.mean(axis=0).tolist()}


def star_frames(folder, frames, seed):
    """Per detector: completeness, false detections, timing and (matched filter) the fits' statistics."""
    found = {name: [] for name in DETECTORS}
    false = dict.fromkeys(DETECTORS, 0)
    times = {name: [] for name in DETECTORS}
    fits = []
    for k, child in enumerate(np.random.SeedSequence(seed).spawn(frames)):
        image, centres = star_frame(np.random.default_rng(child))
        write_image(folder / "stars.png", image)
        for name, options in DETECTORS.items():
            answer = detect_json(folder / "stars.png", options)
            hit, unmatched, usable = score(answer, centres)
            found[name].append(hit)
            false[name] += unmatched
            times[name] += [answer["detect_ms"]] if k else []
            fits += usable if name == "matched_filter" else []
        print(f"frame {k + 1}/{frames}", file=sys.stderr, flush=True)
    out = {}
    for name in DETECTORS:
        hits = np.concatenate(found[name])
        n, k = hits.size, int(hits.sum())
        interval = [float(beta.ppf(0.025, k, n - k + 1)) if k else 0.0, float(beta.ppf(0.975, k + 1, n - k)) if k < n else 1.0]
        out[name] = {"stars": n, "found": k, "completeness": k / n, "completeness_95": interval,
                     "false_per_frame": false[name] / frames, "median_ms_per_frame": float(np.median(times[name]))}
    out["matched_filter"]["fits"] = fit_statistics(fits)
    return out


def blank_frames(folder, frames, seed):
    """The matched filter's false detections per sky-only frame at 0.01 and 2 per frame, beside eq. 4."""
    counts = {"0.01": 0, "2": 0}
    for k, child in enumerate(np.random.SeedSequence(seed).spawn(frames)):
        write_image(folder / "sky.png", noisy_frame(np.random.default_rng(child), (SIZE, SIZE), [], SIGMA, SKY_E, READ_E))
        for rate in counts:
            counts[rate] += len(detect_json(folder / "sky.png", (*DETECTORS["matched_filter"], "--false-alarms", rate))["stars"])
        if (k + 1) % 10 == 0:
            print(f"sky frame {k + 1}/{frames}", file=sys.stderr, flush=True)
    out = {}
    for rate, count in counts.items():
        u = snr_threshold(float(rate), (SIZE, SIZE), SIGMA, TRAIL)
        stated = float(expected_false_peaks(u, (SIZE, SIZE), SIGMA, TRAIL))
        out[rate] = {"frames": frames, "detections": count, "per_frame": count / frames, "threshold_snr": u,
                     "eq4_per_frame": stated, "eq4_with_poisson_skew_per_frame":
                         stated * poisson_sky_lift(trail_template(SIGMA, TRAIL), u, SKY_E, NOISE.variance_dn2)}
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=10, help="star frames (100 stars each)")
    parser.add_argument("--blank", type=int, default=100, help="sky-only frames")
    parser.add_argument("--seed", type=int, default=64)
    args = parser.parse_args()
    started = time.perf_counter()
    with tempfile.TemporaryDirectory() as folder:
        result = {"frames": args.frames, "stars_per_frame": GRID * GRID, "charge_e": CHARGE_E, "trail_px": list(TRAIL),
                  "psf_sigma_px": SIGMA, "sky_e": SKY_E, "read_noise_e": READ_E, "gain_e_per_dn": 1.0,
                  "gate_px": GATE_PX, "seed": args.seed,
                  "detectors": star_frames(Path(folder), args.frames, args.seed),
                  "blank_frames": blank_frames(Path(folder), args.blank, args.seed + 1)}
    result["seconds"] = time.perf_counter() - started
    print(json.dumps({k: result[k] for k in ("detectors", "blank_frames")}, indent=1))
    path = HERE / "results" / "detect_trailed_command.json"
    path.write_text(json.dumps(result, indent=1) + "\n")


if __name__ == "__main__":
    main()
