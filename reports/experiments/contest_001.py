"""Reproduce the optical-axis simulations of the contest paper 001 (ch. 2-3) with the Cramer-Rao bound beside them.

Set-up of 001 §2.1.3: 12 x 12 deg field, 512 x 512 pixels, f = 256 / tan 6 deg ~ 2435.7 px, Gaussian
centroid noise sigma = 0.05 px.  Each map: a random catalog star as the boresight (001 2.3.3 step 2),
a random roll, the Hipparcos stars of V <= 6 (5102 stars, about the size of the contest catalog) that
fall on the image.  Vector data: (X_i, Y_i) + N(0, sigma) each; scalar data: a_i = |(X_i, Y_i)| of the
same noisy coordinates (radial noise sigma; never negative for the star at the boresight).

Figures (reports/out/contest_001_*.png) and printed numbers, each beside the Cramer-Rao bound of the
boresight (known f; for the scalar model from the radial information only):
* error distribution of every triple solve (2.1.3, 2.2.2, 3.1.2, 3.2.2; 3 random stars of the map);
* error distribution of the all-star solves (2.3.3 (一), 3.3.3 (一)), with the casadi constrained fit
  with unknown f on the first maps;
* rank of the best triple (least |M|) and of OLS among all triples of the map, i.e. the share of
  triples whose error is larger ("beats"; 001: best triple ~86 % scalar / ~81 % vector, OLS ~97 % /
  ~90 %), with known f (scalar, vector) and without (vector model, f from the cubic of 3.2.1 (二)).

Run:  python reports/experiments/contest_001.py [--maps 1000] [--casadi-maps 200] [--seed 1] [--out reports/out]
"""

import argparse
import json
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from startrack import boresight as bs  # noqa: E402
from startrack.attitude_angles import matrix_from_radec_roll  # noqa: E402
from startrack.sphere import vector_to_radec  # noqa: E402
from startrack.star_catalog import load_star_catalog  # noqa: E402

ARCSEC = np.pi / 180.0 / 3600.0
FOCAL = 256.0 / np.tan(np.radians(6.0))
HALF = 255.5                       # image half-width [px] about the principal point
SIGMA_PX = 0.05
V_MAG_MAX = 6.0
FOCAL_BOUNDS = (0.5 * FOCAL, 2.0 * FOCAL)
PAPER_BEATS = {"scalar_known_f": {"best_triple": 86, "ols": 97}, "vector_known_f": {"best_triple": 81, "ols": 90}}


def angle(a, b):
    """Angles [rad] between direction arrays (..., 3)."""
    return np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.sum(a * b, axis=-1))


def draw_map(rng, stars):
    """(ref_I (n, 3), xy (n, 2) noiseless, boresight_I) of one random map with n >= 4 stars."""
    while True:
        ra, dec = vector_to_radec(stars[rng.integers(len(stars))])
        R_IS = matrix_from_radec_roll(ra, dec, rng.uniform(-np.pi, np.pi))
        v_S = stars @ R_IS
        front = v_S[:, 2] > 0
        xy = FOCAL * v_S[front, :2] / v_S[front, 2:]
        inside = np.all(np.abs(xy) <= HALF, axis=1)
        if inside.sum() >= 4:
            return stars[front][inside], xy[inside], R_IS[:, 2]


def crb_vector(xy):
    """RMS boresight error [rad] bound from vector data, f known: cross part of the attitude CRB."""
    c = bs.sensor_directions(xy, FOCAL)
    sigma = SIGMA_PX / FOCAL * c[:, 2] ** 1.5
    fisher = np.sum(sigma ** -2) * np.eye(3) - (c * sigma[:, None] ** -2).T @ c
    P = np.linalg.inv(fisher)
    return np.sqrt(P[0, 0] + P[1, 1])


def crb_scalar(xy):
    """RMS boresight error [rad] bound from the radii only (f known): a_i = f tan(gamma_i)."""
    rho = np.hypot(xy[:, 0], xy[:, 1])
    t = xy / rho[:, None]
    gain = FOCAL * (1.0 + (rho / FOCAL) ** 2) / SIGMA_PX          # d a_i / d gamma_i / sigma
    fisher = np.einsum("n,ni,nj->ij", gain ** 2, t, t)
    return np.sqrt(np.trace(np.linalg.inv(fisher)))


def rms(values):
    return float(np.sqrt(np.mean(np.square(values))))


def beats(error, all_errors):
    """Share [%] of the triples whose error is larger than `error`."""
    return 100.0 * float(np.mean(all_errors > error))


def run_map(rng, stars, casadi):
    ref, xy0, w = draw_map(rng, stars)
    n = len(ref)
    xy = xy0 + rng.normal(scale=SIGMA_PX, size=xy0.shape)
    radii = np.hypot(xy[:, 0], xy[:, 1])
    out = {"n": n, "crb_vector": crb_vector(xy0), "crb_scalar": crb_scalar(xy0)}

    # triple solves on a random triple (2.1.3, 2.2.2, 3.1.2, 3.2.2)
    t = rng.choice(n, 3, replace=False)
    for method, call in (
        ("scalar_known_f_normalised", lambda: bs.solve_scalar_known_f(ref[t], radii[t], FOCAL)),
        ("scalar_known_f_linearised", lambda: bs.solve_scalar_known_f(ref[t], radii[t], FOCAL, "linearised")),
        ("scalar_unknown_f_numeric", lambda: bs.solve_scalar_unknown_f(ref[t], radii[t], FOCAL_BOUNDS)),
        ("vector_known_f_svd", lambda: bs.solve_vector_known_f(ref[t], xy[t], FOCAL)),
        ("vector_unknown_f_analytic", lambda: bs.solve_vector_unknown_f(ref[t], xy[t])),
        ("vector_unknown_f_numeric", lambda: bs.solve_vector_unknown_f(ref[t], xy[t], "numeric", FOCAL_BOUNDS)),
    ):
        try:
            solution = call()
            out[method] = float(min(angle(c, w) for c in solution.candidates))
        except bs.InputError:
            out[method] = float("nan")          # counted as a failure (no root, degenerate triple)
    out["crb_vector_triple"] = crb_vector(xy0[t])
    out["crb_scalar_triple"] = crb_scalar(xy0[t])

    # all stars (2.3.2, 3.3.2)
    out["scalar_all_ols"] = float(angle(bs.solve_scalar_all_stars(ref, radii, FOCAL).boresight_I, w))
    out["scalar_all_constrained"] = float(angle(bs.solve_scalar_all_stars(ref, radii, FOCAL, "constrained").boresight_I, w))
    out["vector_all_ols"] = float(angle(bs.solve_vector_all_stars(ref, xy, FOCAL).boresight_I, w))
    vector_unknown = bs.solve_vector_all_stars(ref, xy)
    out["vector_all_ols_unknown_f"] = float(angle(vector_unknown.boresight_I, w))
    out["vector_all_procrustes"] = float(angle(bs.solve_vector_constrained(ref, xy, focal_px=FOCAL).boresight_I, w))
    if casadi:
        start = time.perf_counter()
        fit = bs.solve_vector_constrained(ref, xy)
        out["casadi_ms"] = 1e3 * (time.perf_counter() - start)
        out["vector_all_constrained_ipopt"] = float(angle(fit.boresight_I, w))

    # ranks among all triples (2.3.3 (二), 3.3.3 (二))
    triples = bs.all_triples(n)
    P_rows = ref[triples]
    well_posed = np.linalg.svd(P_rows, compute_uv=False)[:, 2] > 1e-9
    triples, P_rows = triples[well_posed], P_rows[well_posed]
    scalar_all = angle(bs.scalar_known_f_batch(P_rows, bs.cos_gamma(radii[triples], FOCAL)), w)
    _, vector_w = bs.vector_known_f_batch(P_rows, bs.sensor_directions(xy[triples], FOCAL))
    vector_all = angle(vector_w, w)
    f_triples, _ = bs.focal_cubic_batch(P_rows, xy[triples])
    ok = np.isfinite(f_triples)
    _, vector_w_unknown = bs.vector_known_f_batch(P_rows[ok], bs.sensor_directions(xy[triples[ok]], f_triples[ok][:, None]))
    vector_unknown_all = np.full(len(triples), np.inf)           # a triple without a root counts as worst
    vector_unknown_all[ok] = angle(vector_w_unknown, w)
    best_scalar = bs.best_triple(ref, FOCAL, radii_px=radii)
    best_vector = bs.best_triple(ref, FOCAL, xy_px=xy)
    best_vector_unknown = bs.best_triple(ref, vector_unknown.focal_px, xy_px=xy)

    def triple_error(best, errors):
        return errors[np.flatnonzero(np.all(triples == best, axis=1))[0]]

    out["rank"] = {
        "scalar_known_f": {"best_triple": beats(triple_error(best_scalar, scalar_all), scalar_all),
                           "ols": beats(out["scalar_all_ols"], scalar_all)},
        "vector_known_f": {"best_triple": beats(triple_error(best_vector, vector_all), vector_all),
                           "ols": beats(out["vector_all_ols"], vector_all)},
        "vector_unknown_f": {"best_triple": beats(triple_error(best_vector_unknown, vector_unknown_all), vector_unknown_all),
                             "ols": beats(out["vector_all_ols_unknown_f"], vector_unknown_all)},
    }
    out["triples"] = len(triples)
    return out


def histogram(results, keys, crb_key, title, path):
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    finite = np.concatenate([np.array([r[k] for r in results if k in r]) for k in keys])
    finite = finite[np.isfinite(finite)] / ARCSEC
    bins = np.linspace(0.0, np.percentile(finite, 99), 50)
    for k in keys:
        values = np.array([r[k] for r in results if k in r]) / ARCSEC
        ax.hist(values[np.isfinite(values)], bins=bins, histtype="step", lw=1.5,
                label=f"{k} (RMS {rms(values[np.isfinite(values)]):.2f}\")")
    crb = np.sqrt(np.mean(np.square([r[crb_key] for r in results]))) / ARCSEC
    ax.axvline(crb, color="k", ls=":", label=f"Cramer-Rao RMS {crb:.2f}\" (known f)")
    ax.set_xlabel("boresight error [arcsec]")
    ax.set_ylabel("maps")
    ax.set_title(title)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", type=int, default=1000, help="random star maps (001: 1000)")
    parser.add_argument("--casadi-maps", type=int, default=200, help="maps that also run the Ipopt fit")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", type=Path, default=Path("reports/out"))
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    catalog = load_star_catalog().brighter_than(V_MAG_MAX)
    streams = np.random.SeedSequence(args.seed).spawn(args.maps)
    results = [run_map(np.random.default_rng(s), catalog.vectors, k < args.casadi_maps) for k, s in enumerate(streams)]

    summary = {"settings": {"maps": args.maps, "fov_deg": 12.0, "pixels": 512, "focal_px": FOCAL,
                            "sigma_px": SIGMA_PX, "v_mag_max": V_MAG_MAX, "catalog_stars": len(catalog),
                            "seed": args.seed},
               "stars_per_map": {"mean": float(np.mean([r["n"] for r in results])),
                                 "min": int(min(r["n"] for r in results)), "max": int(max(r["n"] for r in results))}}
    print(f"{args.maps} maps, {summary['stars_per_map']['mean']:.1f} stars per map on average "
          f"(V <= {V_MAG_MAX}, {len(catalog)} catalog stars); sigma = {SIGMA_PX} px = "
          f"{SIGMA_PX / FOCAL / ARCSEC:.2f}\"")

    triple_keys = ["scalar_known_f_normalised", "scalar_known_f_linearised", "scalar_unknown_f_numeric",
                   "vector_known_f_svd", "vector_unknown_f_analytic", "vector_unknown_f_numeric"]
    all_keys = ["scalar_all_ols", "scalar_all_constrained", "vector_all_ols", "vector_all_ols_unknown_f",
                "vector_all_procrustes", "vector_all_constrained_ipopt"]
    crb = {k: float(np.sqrt(np.mean(np.square([r[k] for r in results]))) / ARCSEC)
           for k in ("crb_scalar_triple", "crb_vector_triple", "crb_scalar", "crb_vector")}
    summary["crb_rms_arcsec"] = crb
    summary["rms_arcsec"] = {}
    summary["failures"] = {}
    print("\nboresight RMS error [arcsec] (failures = no admissible root) beside the Cramer-Rao RMS (known f):")
    for k in triple_keys + all_keys:
        values = np.array([r[k] for r in results if k in r])
        good = values[np.isfinite(values)]
        summary["rms_arcsec"][k] = rms(good) / ARCSEC
        summary["failures"][k] = int(np.sum(~np.isfinite(values)))
        bound = crb["crb_scalar_triple" if k.startswith("scalar") else "crb_vector_triple"] if k in triple_keys else \
            crb["crb_scalar" if k.startswith("scalar") else "crb_vector"]
        print(f"  {k:<30} {summary['rms_arcsec'][k]:8.3f}   median {np.median(good) / ARCSEC:7.3f}   "
              f"failures {summary['failures'][k]:3d}/{len(values)}   CRB {bound:7.3f}")
    casadi_ms = [r["casadi_ms"] for r in results if "casadi_ms" in r]
    summary["casadi_ms_median"] = float(np.median(casadi_ms))
    print(f"  casadi/Ipopt constrained fit: median {summary['casadi_ms_median']:.1f} ms per solve")

    summary["rank_beats_percent"] = {}
    print("\nshare of all triples beaten [%] (mean over maps; 001 in brackets):")
    for model in ("scalar_known_f", "vector_known_f", "vector_unknown_f"):
        entry = {}
        for method in ("best_triple", "ols"):
            values = np.array([r["rank"][model][method] for r in results])
            entry[method] = {"mean": float(values.mean()), "median": float(np.median(values))}
        summary["rank_beats_percent"][model] = entry
        paper = PAPER_BEATS.get(model)
        print(f"  {model:<17} best triple {entry['best_triple']['mean']:5.1f} "
              f"({paper['best_triple'] if paper else '-'})   OLS {entry['ols']['mean']:5.1f} ({paper['ols'] if paper else '-'})")

    histogram(results, triple_keys[:3], "crb_scalar_triple", "001 Fig. 2.3/2.4: scalar a, three stars",
              args.out / "contest_001_scalar_triple.png")
    histogram(results, triple_keys[3:], "crb_vector_triple", "001 Fig. 3.1/3.3: vector a, three stars",
              args.out / "contest_001_vector_triple.png")
    histogram(results, all_keys[:2], "crb_scalar", "001 Fig. 2.5: scalar a, all stars", args.out / "contest_001_scalar_all.png")
    histogram(results, all_keys[2:], "crb_vector", "001 Fig. 3.4: vector a, all stars", args.out / "contest_001_vector_all.png")
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), sharey=True)
    for ax, model in zip(axes, ("scalar_known_f", "vector_known_f", "vector_unknown_f")):
        for method in ("best_triple", "ols"):
            ax.hist([r["rank"][model][method] for r in results], bins=np.linspace(0, 100, 41), histtype="step",
                    lw=1.5, label=f"{method} (mean {summary['rank_beats_percent'][model][method]['mean']:.1f} %)")
        ax.set_title(model)
        ax.set_xlabel("share of triples beaten [%]")
        ax.legend(fontsize=8, loc="upper left")
    axes[0].set_ylabel("maps")
    fig.suptitle("001 Fig. 2.6/3.5: rank among all triples")
    fig.tight_layout()
    fig.savefig(args.out / "contest_001_rank.png", dpi=110)
    plt.close(fig)
    with open(args.out / "contest_001.json", "w") as handle:
        json.dump(summary, handle, indent=1)
    print(f"\nwrote {args.out / 'contest_001.json'} and 5 figures")


if __name__ == "__main__":
    main()
