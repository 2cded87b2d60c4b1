"""Image-chain speed and centroid accuracy, side by side with the ``sep`` package (Source Extractor).

Frames: 1024 x 1024 px, 20 deg field, Hipparcos-2 stars to V = 6.5 at
seeded random attitudes, default :class:`~startrack.render.SensorModel`
(0.671 px PSF, 12-bit ADC, b ~ 101 DN, sigma_n ~ 10 DN), 100 ms exposure,
body rate 0.5 deg/s (smear ~2.5 px).  Measured per frame (median ms):
render; detect + centroid (background estimated from the frame, and given);
window mode (8 windows of 11 x 11: render + detect).  Centroid error: RMS
distance to the true (track-averaged) centroid of the matched stars that are
neither saturated nor on the edge.  ``sep`` (if importable) runs on the
same frames: sep.Background + sep.extract at 5 sigma (isophotal barycentre
x, y), and sep.extract with the known background.

Writes benchmarks/results/image_chain.json; asserts nothing.
Run: .venv/bin/python benchmarks/image_chain.py
"""

import json
import platform
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

from startrack.camera import Camera
from startrack.detection import detect, detect_windows
from startrack.render import SensorModel, Windows, expected_charge, render, render_star_field, star_sources
from startrack.star_catalog import load_star_catalog
from startrack.units import DEG

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


def main():
    camera = Camera.from_fov(20 * DEG, 1024, 1024)
    sensor = SensorModel()
    omega = np.array([0.5, 0.0, 0.0]) * DEG
    stars = load_star_catalog(2000.0).brighter_than(6.5)
    seeds = np.random.SeedSequence(4).spawn(N_FRAMES)
    rows = {key: [] for key in ("render", "detect", "detect_given_b", "windows", "sep", "sep_given_b")}
    errors = {key: [] for key in ("grey", "threshold", "square", "sep")}
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
        # window mode: 8 windows of 11 x 11 around the 8 brightest predicted stars
        source, index = star_sources(camera, sensor, q, stars.vectors, stars.v_mag, omega)
        order = np.argsort(-source.electrons)[:8]
        windows = Windows.around(source.centroids[order], 5, 1024, 1024)

        def window_frame():
            w = render(sensor, 1024, 1024, [source], rng, windows)
            return detect_windows(w, windows.row0, windows.col0, sensor.background_dn, sensor.noise_dn)

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
        "goals_ms": {"render_plus_detect": 30.0, "window_mode_8x11x11": 2.0},
        "centroid_error": acc,
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
    print(f"  render + detect                 {result['render_plus_detect_ms']:7.2f} ms   (goal <= 30 ms)")
    print(f"  window mode, 8 x 11x11          {ms['windows']:7.3f} ms   (goal <= 2 ms)")
    if sep is not None:
        print(f"  sep {result['sep_version']}: Background + extract  {ms['sep']:7.2f} ms; extract with b given "
              f"{ms['sep_given_b']:7.2f} ms")
    else:
        print("  sep: not importable, no comparison")
    for key, value in acc.items():
        if value:
            print(f"  centroid {key:9s}: matched {value['matched_fraction']:6.1%}, RMS {value['rms_px']:.3f} px")
    print(f"wrote {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
