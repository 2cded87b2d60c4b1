"""Reproduce the attitude-precision simulation of 003 §3 (Zhang et al. 2008) with the Cramer-Rao bound beside it.

003's set-up: 16 x 16 deg field, 512 x 512 pixels (pixel resolution S = 113.24"), boresight
(alpha0, delta0) = (30, 40) deg, roll kappa0 = 10 deg, N stars uniform in the field, centroid noise
sigma_x = sigma_y (expressed as an angle, 1" unless stated), m = 300 trials; errors are the RMS over the
trials of alpha_p - alpha0, delta_p - delta0, kappa_p - kappa0 (RA, Dec, roll of 003 §1.1), computed
with 003's multi-reference-vector algorithm B (B^T B)^-1/2 (eq. 1).

Beside every simulated figure: our Monte Carlo of 003's algorithm (``multi_vector``), of the optimal
Wahba solution (``svd``), the first-order prediction of 003's algorithm (its own covariance) and the
Cramer-Rao bound, mapped from the attitude error in S axes to (alpha, delta, kappa) by the Jacobian of
the angle conversion (so the RA error carries the 1/cos(delta0) of a right-ascension difference).

Stars are drawn as 003 step 3 does: RA and Dec uniform in the eq. 2-5 window of the field (radius A/2)
and kept when they fall in the image square ("radec_window"); the focal-plane-uniform draw is shown
beside it at N = 3, 9, 21.  Noise is added to the image coordinates in pixels (sigma_px = sigma / S), as
003 does.  For the bound each star's direction noise
is sigma_px / f * cos(gamma)^1.5 (geometric mean of the radial cos^2 and tangential cos factors of a
pinhole at off-axis angle gamma; <= 4 % from sigma in this field).

Run:  python reports/experiments/precision_003.py [--trials 300] [--seed 3] [--out reports/out]
Writes precision_003.json and precision_003_*.png.
"""

import argparse
import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from startrack.attitude import cramer_rao_covariance, get_solver  # noqa: E402
from startrack.fov_select import radec_window  # noqa: E402
from startrack.sphere import radec_to_vector  # noqa: E402
from startrack.attitude_angles import (  # noqa: E402
    matrix_from_quaternion, quaternion_from_matrix, quaternion_from_radec_roll, radec_roll_from_quaternion,
)

ARCSEC = np.pi / 180.0 / 3600.0
RA0, DEC0, ROLL0 = np.radians(30.0), np.radians(40.0), np.radians(10.0)
PIXELS = 512
FOV_DEG = 16.0
PIXEL_ARCSEC = np.degrees(np.arctan(2.0 * np.tan(np.radians(FOV_DEG / 2)) / PIXELS)) * 3600.0  # 113.24"
ANGLES = ("alpha", "delta", "kappa")

PAPER_VS_N = {3: (8.78, 4.65, 122.60), 9: (0.56, 0.49, 4.08), 21: (0.34, 0.28, 2.47)}
PAPER_SLOPES_N9 = (0.558, 0.483, 4.077)
PAPER_SMALL_FOV = {"fov_deg": 4.0, "N": 3, "rms_arcsec": (14.37, 7.87, 560.41)}
PAPER_ALGORITHM_ERROR = "max 3.7e-4 arcsec at N = 3 (sigma = 0)"
HEAVY_TAIL_BATCHES = 20
TOLERANCE_PERCENT = 15.0


def angle_errors(q, q_true):
    """(alpha, delta, kappa) of q minus those of q_true, wrapped to [-pi, pi) [rad]; q (..., 4)."""
    a = np.array(radec_roll_from_quaternion(q))
    b = np.array(radec_roll_from_quaternion(q_true))
    return np.mod(a - b.reshape((3,) + (1,) * (a.ndim - 1)) + np.pi, 2 * np.pi) - np.pi


def angle_jacobian(q_true, step=1e-6):
    """d(alpha, delta, kappa)/d(dtheta) (3 x 3) with R = R_true exp([dtheta x]) (central differences)."""
    R = matrix_from_quaternion(q_true)
    J = np.zeros((3, 3))
    for k in range(3):
        columns = []
        for sign in (1.0, -1.0):
            angle = sign * step
            axis = np.eye(3)[k]
            K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
            R_k = R @ (np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K)
            columns.append(angle_errors(quaternion_from_matrix(R_k), q_true))
        J[:, k] = (columns[0] - columns[1]) / (2 * step)
    return J


class Sensor:
    """Square-field pinhole of 003 with a pixel resolution kept at PIXEL_ARCSEC."""

    def __init__(self, fov_deg):
        self.fov = np.radians(fov_deg)
        self.pixels = 2.0 * np.tan(self.fov / 2) / np.tan(PIXEL_ARCSEC * ARCSEC)
        self.focal = 1.0 / np.tan(PIXEL_ARCSEC * ARCSEC)          # px, so one pixel = S at the centre
        self.half = self.focal * np.tan(self.fov / 2)

    def directions(self, xy):
        v = np.concatenate([xy, np.full(xy.shape[:-1] + (1,), self.focal)], axis=-1)
        return v / np.linalg.norm(v, axis=-1, keepdims=True)


def star_field(rng, sensor, n, distribution, R_IS):
    """(xy (n, 2) [px], ref_I (n, 3)) of 003's star distributions (Table 1).

    radec_window (003 step 3, the default): RA, Dec uniform in the eq. 2-5 window of radius A/2, kept
    inside the image square; uniform: uniform on the image square; clustered: a square a quarter of the field wide at a random place;
    line: on the declination circle through the boresight (RA uniform in the eq. 3 span), which is how
    a "line" arises when stars are drawn in RA/Dec as 003 does; stars leaving the square are redrawn.
    """
    h = sensor.half
    if distribution == "uniform":
        xy = rng.uniform(-h, h, size=(n, 2))
    elif distribution == "radec_window":
        dec_min, dec_max, half_span = radec_window(RA0, DEC0, sensor.fov / 2)
        xy = np.empty((0, 2))
        while len(xy) < n:
            ra = RA0 + rng.uniform(-half_span, half_span, n)
            dec = rng.uniform(dec_min, dec_max, n)
            v_S = radec_to_vector(ra, dec) @ R_IS
            candidate = sensor.focal * v_S[:, :2] / v_S[:, 2:]
            xy = np.vstack([xy, candidate[np.all(np.abs(candidate) <= h, axis=1)]])[:n]
    elif distribution == "clustered":
        xy = rng.uniform(-0.75 * h, 0.75 * h, size=2) + rng.uniform(-h / 4, h / 4, size=(n, 2))
    else:
        span = np.arcsin(np.sin(sensor.fov / 2) / np.cos(DEC0))
        xy = np.empty((0, 2))
        while len(xy) < n:
            ra = RA0 + rng.uniform(-span, span, n)
            v_S = np.column_stack([np.cos(DEC0) * np.cos(ra), np.cos(DEC0) * np.sin(ra), np.full(n, np.sin(DEC0))]) @ R_IS
            candidate = sensor.focal * v_S[:, :2] / v_S[:, 2:]
            xy = np.vstack([xy, candidate[np.all(np.abs(candidate) <= h, axis=1)]])[:n]
    return xy, sensor.directions(xy) @ R_IS.T


def simulate(rng, sensor, n, sigma_arcsec, trials, solvers=("multi_vector", "svd"), distribution="radec_window"):
    """Monte Carlo of 003 §3.1; returns per solver the RMS (alpha, delta, kappa) ["] and the predictions."""
    q_true = quaternion_from_radec_roll(RA0, DEC0, ROLL0)
    R_IS = matrix_from_quaternion(q_true)
    J = angle_jacobian(q_true)
    sigma_px = sigma_arcsec / PIXEL_ARCSEC
    errors = {name: [] for name in solvers}
    predicted = {name: [] for name in solvers}
    crb = []
    for _ in range(trials):
        xy, ref = star_field(rng, sensor, n, distribution, R_IS)
        obs = sensor.directions(xy + rng.normal(scale=sigma_px, size=xy.shape))
        exact = sensor.directions(xy)
        unit_sigma = exact[:, 2] ** 1.5 / (PIXEL_ARCSEC * sensor.focal)    # [rad] per 1" of centroid noise
        scale = sigma_arcsec ** 2
        crb.append(scale * np.diag(J @ cramer_rao_covariance(exact, unit_sigma) @ J.T))
        for name in solvers:
            solver = get_solver(name)
            errors[name].append(angle_errors(solver.solve(ref, obs, unit_sigma).q_IS, q_true))
            predicted[name].append(scale * np.diag(J @ solver.solve(ref, exact, unit_sigma).P @ J.T))
    result = {"crb_rms_arcsec": (np.sqrt(np.mean(crb, axis=0)) / ARCSEC).tolist()}
    for name in solvers:
        e = np.array(errors[name])
        result[name] = {
            "rms_arcsec": (np.sqrt(np.mean(e ** 2, axis=0)) / ARCSEC).tolist(),
            "max_abs_arcsec": (np.abs(e).max(axis=0) / ARCSEC).tolist(),
            "predicted_rms_arcsec": (np.sqrt(np.mean(predicted[name], axis=0)) / ARCSEC).tolist(),
        }
    return result


def percent(ours, paper):
    return [round(100.0 * (o - p) / p, 1) for o, p in zip(ours, paper)]


def plot_three(x, curves, xlabel, title, path, paper=None, logy=False, batch_range=None):
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for k, ax in enumerate(axes):
        for label, (values, style) in curves.items():
            ax.plot(x, [v[k] for v in values], style, label=label)
        if paper:
            ax.plot(paper[0], [p[k] for p in paper[1]], "k*", ms=11, label="003 (printed)")
        if batch_range:
            at, spread = batch_range
            ax.errorbar([at], [spread["median"][k]], yerr=[[spread["median"][k] - spread["min"][k]],
                                                           [spread["max"][k] - spread["median"][k]]],
                        fmt="D", color="tab:purple", capsize=4, label="003 alg.: batch RMS min/median/max")
        ax.set_xlabel(xlabel)
        ax.set_ylabel(f"RMS error of {ANGLES[k]} [arcsec]")
        if logy:
            ax.set_yscale("log")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def curves_of(rows):
    return {
        "003 algorithm, Monte Carlo": ([r["multi_vector"]["rms_arcsec"] for r in rows], "o-"),
        "003 algorithm, first-order prediction": ([r["multi_vector"]["predicted_rms_arcsec"] for r in rows], "--"),
        "optimal (SVD), Monte Carlo": ([r["svd"]["rms_arcsec"] for r in rows], "s-"),
        "Cramer-Rao bound": ([r["crb_rms_arcsec"] for r in rows], ":"),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=300, help="Monte Carlo trials per point (003: 300)")
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("--out", type=Path, default=Path("reports/out"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    streams = iter(np.random.default_rng(s) for s in np.random.SeedSequence(args.seed).spawn(256))
    sensor = Sensor(FOV_DEG)
    out = {"settings": {"fov_deg": FOV_DEG, "pixels": PIXELS, "pixel_arcsec": PIXEL_ARCSEC,
                        "boresight_deg": [30.0, 40.0], "roll_deg": 10.0, "trials": args.trials, "seed": args.seed}}

    # 3.2.1 algorithm error, sigma = 0
    ns = list(range(3, 22))
    algorithm = {n: simulate(next(streams), sensor, n, 0.0, args.trials, ("multi_vector",)) for n in ns}
    worst = {n: max(r["multi_vector"]["max_abs_arcsec"]) for n, r in algorithm.items()}
    out["algorithm_error_sigma0"] = {"max_abs_arcsec_by_N": worst, "paper": PAPER_ALGORITHM_ERROR}
    print(f"3.2.1 algorithm error (sigma = 0): largest |error| over N = 3..21: {max(worst.values()):.2e}\" "
          f"(003: {PAPER_ALGORITHM_ERROR}; ours is at double-precision rounding, 003's was presumably "
          "an iterative (B^T B)^-1/2)")

    # 3.2.2 error versus N, sigma = 1"
    rows = [simulate(next(streams), sensor, n, 1.0, args.trials) for n in ns]
    out["error_vs_N"] = {"N": ns, "rows": rows, "paper": {str(k): v for k, v in PAPER_VS_N.items()}}
    print("\n3.2.2 RMS error vs N at sigma = 1\" [arcsec] (alpha, delta, kappa)")
    print(f"{'N':>3} | {'003 printed':>22} | {'003 alg. MC':>22} | {'003 alg. predicted':>22} | "
          f"{'optimal MC':>22} | {'CRB':>22}")
    fmt = lambda v: "(" + ", ".join(f"{x:6.2f}" for x in v) + ")"  # noqa: E731
    comparison = {}
    for n, row in zip(ns, rows):
        paper = PAPER_VS_N.get(n)
        print(f"{n:>3} | {fmt(paper) if paper else '':>22} | {fmt(row['multi_vector']['rms_arcsec']):>22} | "
              f"{fmt(row['multi_vector']['predicted_rms_arcsec']):>22} | {fmt(row['svd']['rms_arcsec']):>22} | "
              f"{fmt(row['crb_rms_arcsec']):>22}")
        if paper:
            comparison[n] = {"ours_vs_003_percent": percent(row["multi_vector"]["rms_arcsec"], paper),
                             "crb_vs_003_percent": percent(row["crb_rms_arcsec"], paper)}
    out["error_vs_N"]["comparison"] = comparison
    for n, c in comparison.items():
        print(f"  N = {n}: our 003-algorithm MC vs 003: {c['ours_vs_003_percent']} %; CRB vs 003: "
              f"{c['crb_vs_003_percent']} %")
    focal_plane = {n: simulate(next(streams), sensor, n, 1.0, args.trials, distribution="uniform") for n in PAPER_VS_N}
    out["error_vs_N"]["focal_plane_uniform"] = focal_plane
    for n, row in focal_plane.items():
        print(f"  N = {n}: stars uniform on the focal plane instead: 003 algorithm MC {fmt(row['multi_vector']['rms_arcsec'])}"
              f" ({percent(row['multi_vector']['rms_arcsec'], PAPER_VS_N[n])} % vs 003)")
    batches = np.array([simulate(next(streams), sensor, 3, 1.0, args.trials, ("multi_vector",))["multi_vector"]["rms_arcsec"]
                        for _ in range(HEAVY_TAIL_BATCHES)])
    spread = {"min": batches.min(axis=0).tolist(), "median": np.median(batches, axis=0).tolist(),
              "max": batches.max(axis=0).tolist(),
              "share_below_003_percent": (100.0 * np.mean(batches < np.array(PAPER_VS_N[3]), axis=0)).tolist()}
    out["error_vs_N"]["N3_batch_rms_spread"] = spread
    print(f"  N = 3: RMS of {HEAVY_TAIL_BATCHES} independent batches of {args.trials} trials (003 algorithm): "
          f"min {fmt(spread['min'])}, median {fmt(spread['median'])}, max {fmt(spread['max'])}")
    plot_three(ns, curves_of(rows), "stars N", "003 Fig. 6: error vs N (sigma = 1\")",
               args.out / "precision_003_vs_N.png", paper=(list(PAPER_VS_N), list(PAPER_VS_N.values())), logy=True,
               batch_range=(3.3, spread))

    # 3.2.3 linear dependence on the centroid error, N = 9
    sigmas = [0.25, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0]
    rows_sigma = [simulate(next(streams), sensor, 9, s, args.trials) for s in sigmas]
    slopes = {key: [float(np.polyfit(sigmas, [r[key]["rms_arcsec"][k] for r in rows_sigma], 1)[0]) for k in range(3)]
              for key in ("multi_vector", "svd")}
    slopes["crb"] = [float(np.polyfit(sigmas, [r["crb_rms_arcsec"][k] for r in rows_sigma], 1)[0]) for k in range(3)]
    out["linearity_N9"] = {"sigma_arcsec": sigmas, "rows": rows_sigma, "slopes": slopes, "paper_slopes": PAPER_SLOPES_N9,
                           "ours_vs_003_percent": percent(slopes["multi_vector"], PAPER_SLOPES_N9)}
    print(f"\n3.2.3 slope d(RMS)/d(sigma) at N = 9: 003 {PAPER_SLOPES_N9}; 003 algorithm MC "
          f"{tuple(round(s, 3) for s in slopes['multi_vector'])} ({percent(slopes['multi_vector'], PAPER_SLOPES_N9)} %); "
          f"optimal MC {tuple(round(s, 3) for s in slopes['svd'])}; CRB {tuple(round(s, 3) for s in slopes['crb'])}")
    plot_three(sigmas, curves_of(rows_sigma), "centroid error sigma [arcsec]",
               "003 Fig. 7: error vs centroid error (N = 9)", args.out / "precision_003_vs_sigma.png")

    # 3.2.4 field of view at constant pixel resolution
    fovs = [4.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0]
    out["fov"] = {"fov_deg": fovs, "by_N": {}, "paper": PAPER_SMALL_FOV}
    fig_rows = {}
    for n in (3, 6, 9):
        fig_rows[n] = [simulate(next(streams), Sensor(a), n, 1.0, args.trials) for a in fovs]
        out["fov"]["by_N"][n] = fig_rows[n]
    small = fig_rows[3][0]
    out["fov"]["small_fov_vs_003_percent"] = percent(small["multi_vector"]["rms_arcsec"], PAPER_SMALL_FOV["rms_arcsec"])
    print(f"\n3.2.4 FOV at constant pixel resolution ({PIXEL_ARCSEC:.2f}\"/px): A = 4 deg, N = 3: 003 "
          f"{PAPER_SMALL_FOV['rms_arcsec']}; 003 algorithm MC {fmt(small['multi_vector']['rms_arcsec'])} "
          f"({percent(small['multi_vector']['rms_arcsec'], PAPER_SMALL_FOV['rms_arcsec'])} %); CRB {fmt(small['crb_rms_arcsec'])}")
    for n in (3, 9):
        print(f"  N = {n}: roll RMS (003 algorithm MC) over A = {fovs}: "
              f"{[round(r['multi_vector']['rms_arcsec'][2], 2) for r in fig_rows[n]]}; CRB "
              f"{[round(r['crb_rms_arcsec'][2], 2) for r in fig_rows[n]]}")
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    for n, style in zip((3, 6, 9), ("o", "s", "^")):
        for k in range(3):
            axes[k].plot(fovs, [r["multi_vector"]["rms_arcsec"][k] for r in fig_rows[n]], style + "-", label=f"N={n} MC (003 alg.)")
            axes[k].plot(fovs, [r["crb_rms_arcsec"][k] for r in fig_rows[n]], style + ":", label=f"N={n} CRB")
    for k, ax in enumerate(axes):
        ax.set_yscale("log")
        ax.set_xlabel("field of view A [deg]")
        ax.set_ylabel(f"RMS error of {ANGLES[k]} [arcsec]")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.suptitle("003 Fig. 8: field of view at constant pixel resolution (sigma = 1\")")
    fig.tight_layout()
    fig.savefig(args.out / "precision_003_vs_fov.png", dpi=110)
    plt.close(fig)

    # 3.2.5 star distributions (Table 1), N = 9
    table = {d: simulate(next(streams), sensor, 9, 1.0, args.trials, distribution=d)
             for d in ("line", "clustered", "radec_window", "uniform")}
    out["distribution_N9"] = table
    print("\n3.2.5 Table 1, N = 9, sigma = 1\" (003's numbers were lost in the text extraction):")
    for d, r in table.items():
        print(f"  {d:>9}: 003 algorithm MC {fmt(r['multi_vector']['rms_arcsec'])}, optimal MC "
              f"{fmt(r['svd']['rms_arcsec'])}, CRB {fmt(r['crb_rms_arcsec'])}")
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    names = list(table)
    for k, ax in enumerate(axes):
        x = np.arange(len(names))
        ax.bar(x - 0.2, [table[d]["multi_vector"]["rms_arcsec"][k] for d in names], 0.4, label="003 alg. MC")
        ax.bar(x + 0.2, [table[d]["svd"]["rms_arcsec"][k] for d in names], 0.4, label="optimal MC")
        ax.plot(x, [table[d]["crb_rms_arcsec"][k] for d in names], "k_", ms=30, mew=2, label="CRB")
        ax.set_xticks(x, names)
        ax.set_yscale("log")
        ax.set_ylabel(f"RMS error of {ANGLES[k]} [arcsec]")
    axes[0].legend(fontsize=8)
    fig.suptitle("003 Table 1: star distribution (N = 9, sigma = 1\")")
    fig.tight_layout()
    fig.savefig(args.out / "precision_003_distribution.png", dpi=110)
    plt.close(fig)

    explanation = explain(out)
    out["explanation"] = explanation
    print("\nWhy ours and 003 differ where they do:\n" + "\n".join("  - " + line for line in explanation))
    with open(args.out / "precision_003.json", "w") as handle:
        json.dump(out, handle, indent=1, default=float)
    print(f"\nwrote {args.out / 'precision_003.json'} and 4 figures")


def explain(out):
    """Sentences on every comparison with 003 that differs by more than TOLERANCE_PERCENT."""
    lines = []
    trials = out["settings"]["trials"]
    standard_error = 100.0 / np.sqrt(2.0 * trials)
    spread = out["error_vs_N"]["N3_batch_rms_spread"]
    for n, c in out["error_vs_N"]["comparison"].items():
        off = [a for a, p in zip(ANGLES, c["ours_vs_003_percent"]) if abs(p) > TOLERANCE_PERCENT]
        if not off:
            continue
        if n == 3:
            inside = all(lo <= p <= hi for lo, p, hi in zip(spread["min"], PAPER_VS_N[3], spread["max"]))
            lines.append(
                f"N = 3 ({', '.join(off)}: {c['ours_vs_003_percent']} %): with three stars 003's algorithm solves "
                "B = R^-1 G exactly, and its error grows like 1/(area of the star triangle); for random "
                "triangles that error has no finite variance, so the RMS over a few hundred trials does not converge "
                f"and is set by the worst trial. Over {HEAVY_TAIL_BATCHES} independent batches of {trials} trials "
                f"the RMS ranges from {[round(v, 1) for v in spread['min']]} to {[round(v, 1) for v in spread['max']]}\" "
                f"(median {[round(v, 1) for v in spread['median']]}\"); 003's {PAPER_VS_N[3]}\" "
                + ("lies inside that range" if inside else "lies at or just below its low end in some angle")
                + f" (003 exceeds {[round(v) for v in spread['share_below_003_percent']]} % of our batch RMS values, "
                "i.e. 003 drew a mild sample or discarded degenerate triangles). The optimal (SVD/QUEST) "
                "solution has no such tail and follows the Cramer-Rao bound.")
        else:
            lines.append(
                f"N = {n} ({', '.join(off)}: {c['ours_vs_003_percent']} %): the RMS of {trials} trials has a "
                f"relative standard error of ~{standard_error:.0f} % (2 sigma ~{2 * standard_error:.0f} %), and the "
                "roll error scales with 1/(RMS star distance from the boresight), which depends on how the stars "
                "fill the field (compare the focal-plane-uniform draw).")
    slope_off = [a for a, p in zip(ANGLES, out["linearity_N9"]["ours_vs_003_percent"]) if abs(p) > TOLERANCE_PERCENT]
    if slope_off:
        lines.append(f"slopes at N = 9 ({', '.join(slope_off)}: {out['linearity_N9']['ours_vs_003_percent']} %): "
                     "each fitted from RMS values of the same size of sample, see the standard error above.")
    small = out["fov"]["small_fov_vs_003_percent"]
    if any(abs(p) > TOLERANCE_PERCENT for p in small):
        lines.append(f"A = 4 deg, N = 3 ({small} %): the same three-star heavy tail as at N = 3 in the 16 deg field.")
    rows = [r for n, r in zip(out["error_vs_N"]["N"], out["error_vs_N"]["rows"]) if n >= 9]
    excess = np.array([[100.0 * (p / c - 1.0) for p, c in zip(r["multi_vector"]["predicted_rms_arcsec"], r["crb_rms_arcsec"])]
                       for r in rows])
    lines.append(f"Everywhere, 003's multi-vector algorithm is not efficient: at N = 9-21 its first-order RMS lies "
                 f"{excess.min():.0f} to {excess.max():.0f} % above the Cramer-Rao bound (which the SVD/QUEST solution "
                 "attains), and that first-order covariance (startrack.attitude.MultiVector) predicts its Monte Carlo "
                 "error; so the CRB alone differs from 003 by more than 15 % for that reason, not because of the "
                 "simulation.")
    return lines


if __name__ == "__main__":
    main()
