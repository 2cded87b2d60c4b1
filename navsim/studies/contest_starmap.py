"""Static study ``contest_starmap``: the star-map experiments of the contest paper 001.

Set-up of 001 §2.1.3: a 12 x 12 deg field, 512 x 512 pixels, f = 256 / tan 6 deg ≈ 2435.7 px,
Gaussian centroid noise σ = 0.05 px. Two parts, each on random maps of the Hipparcos stars of V ≤ 6
(5102 stars, about the size of the contest catalog):

* Optical axis (001 ch. 2-3). Each map: a random catalog star as the boresight (001 2.3.3 step 2), a
  random roll, every star on the image. Vector data (X_i, Y_i) + N(0, σ); scalar data a_i = |(X_i, Y_i)|
  of the same noisy coordinates. Boresight errors of the triple solves (2.1.3, 2.2.2, 3.1.2, 3.2.2), the
  all-star solves (2.3.2, 3.3.2: OLS, the constrained 6th-degree solution, the Procrustes/SVD fit, the
  casadi/Ipopt fit with unknown f on the first ``casadi_maps`` maps), each beside the Cramér-Rao bound
  of the boresight (known f; for the scalar model from the radial information only); and the rank of
  the best triple (least ‖M‖) and of OLS among all triples of the map — the share of triples whose
  error is larger (001: best triple ≈ 86 % scalar / 81 % vector, OLS ≈ 97 % / 90 %).
* Identification (001 §5.4). Every star of V ≤ 6 on the image at a uniformly random attitude, 1 to 3
  false stars, identified by startrack's full-sky lost-in-space search (:class:`StarIdentifier`) with
  the angular-distance gate δ at each of ``gate_sigmas`` × σ (001 uses δ = 0.05 px as a hard bound);
  001 reports 1000 of 1000 maps recognised. A recognition is false when any matched HIP is wrong or the
  boresight is more than 1 arcmin off.
"""

import time

import numpy as np
from scipy.spatial.transform import Rotation

from navsim.scenario.schema import Table, Value
from navsim.studies.common import progress_bar
from startrack import (
    Camera,
    NavigationCatalogParams,
    StarIdentifier,
    angular_distance,
    centroid_frame,
    load_navigation_catalog,
    load_star_catalog,
    matrix_from_radec_roll,
    random_attitude,
    units,
    vector_to_radec,
)
from startrack import boresight as bs

FALSE_MATCH_ARCSEC = 60.0
TRIPLE_METHODS = ("scalar_known_f_normalised", "scalar_known_f_linearised", "scalar_unknown_f_numeric",
                  "vector_known_f_svd", "vector_unknown_f_analytic", "vector_unknown_f_numeric")
ALL_STAR_METHODS = ("scalar_all_ols", "scalar_all_constrained", "vector_all_ols", "vector_all_ols_unknown_f",
                    "vector_all_procrustes", "vector_all_constrained_ipopt")
RANK_MODELS = ("scalar_known_f", "vector_known_f", "vector_unknown_f")
RANK_METHODS = ("best_triple", "ols")

PAPER_SETUP = {"fov_deg": 12.0, "width_px": 512, "centroid_sigma_px": 0.05, "mag_limit": 6.0}
PAPER_BEATS = {"scalar_known_f": {"best_triple": 86, "ols": 97}, "vector_known_f": {"best_triple": 81, "ols": 90}}
PAPER_RECOGNISED_PERCENT = 100.0
PAPER_MAPS = 1000

PARAMETERS = Table(
    {
        "fov_deg": Value("float", default=12.0, exclusive_minimum=0.0, maximum=40.0, doc="square field"),
        "width_px": Value("int", default=512, minimum=16, maximum=8192),
        "centroid_sigma_px": Value("float", default=0.05, exclusive_minimum=0.0, maximum=5.0),
        "mag_limit": Value("float", default=6.0, minimum=0.0, maximum=8.0, doc="faintest star on the maps"),
        "maps": Value("int", default=1000, minimum=0, doc="maps of the optical-axis part (001: 1000)"),
        "casadi_maps": Value("int", default=200, minimum=0, doc="first maps that also run the Ipopt fit"),
        "focal_bounds": Value("vector", size=2, default=[0.5, 2.0], exclusive_minimum=0.0,
                              doc="search interval of the unknown focal length, in units of the true f"),
        "identification_maps": Value("int", default=1000, minimum=0, doc="maps of the identification part (001: 1000)"),
        "false_stars": Value("ints", default=[1, 3], minimum=0, min_length=2,
                             doc="least and most false stars per map"),
        "gate_sigmas": Value("list", default=[3.0, 1.0], exclusive_minimum=0.0, min_length=1,
                             doc="angular-distance gates δ in units of σ (1.0 is 001's δ = 0.05 px)"),
    }
)


def paper_setup_matches(p):
    return all(p[k] == v for k, v in PAPER_SETUP.items())


class MapGeometry:
    """The square pinhole of 001: focal length f [px] and the image half-width about the centre [px]."""

    def __init__(self, p):
        self.focal = 0.5 * p["width_px"] / np.tan(np.radians(p["fov_deg"]) / 2)
        self.half = 0.5 * (p["width_px"] - 1)
        self.sigma = p["centroid_sigma_px"]
        self.focal_bounds = tuple(b * self.focal for b in p["focal_bounds"])

    def draw(self, rng, stars):
        """(ref_I (n, 3), noiseless xy (n, 2) [px], boresight_I) of a random map with n ≥ 4 stars."""
        while True:
            ra, dec = vector_to_radec(stars[rng.integers(len(stars))])
            R_IS = matrix_from_radec_roll(ra, dec, rng.uniform(-np.pi, np.pi))
            v_S = stars @ R_IS
            front = v_S[:, 2] > 0
            xy = self.focal * v_S[front, :2] / v_S[front, 2:]
            inside = np.all(np.abs(xy) <= self.half, axis=1)
            if inside.sum() >= 4:
                return stars[front][inside], xy[inside], R_IS[:, 2]

    def crb_vector(self, xy):
        """RMS boresight error bound [rad] from vector data with f known: the cross part of the attitude CRB."""
        c = bs.sensor_directions(xy, self.focal)
        sigma = self.sigma / self.focal * c[:, 2] ** 1.5
        fisher = np.sum(sigma ** -2) * np.eye(3) - (c * sigma[:, None] ** -2).T @ c
        P = np.linalg.inv(fisher)
        return np.sqrt(P[0, 0] + P[1, 1])

    def crb_scalar(self, xy):
        """RMS boresight error bound [rad] from the radii only (f known): a_i = f tan γ_i."""
        rho = np.hypot(xy[:, 0], xy[:, 1])
        t = xy / rho[:, None]
        gain = self.focal * (1.0 + (rho / self.focal) ** 2) / self.sigma     # ∂a_i/∂γ_i / σ
        return np.sqrt(np.trace(np.linalg.inv(np.einsum("n,ni,nj->ij", gain ** 2, t, t))))


def beats(error, all_errors):
    """Share [%] of the triples whose error is larger than ``error``."""
    return 100.0 * float(np.mean(all_errors > error))


def optical_axis_map(rng, stars, geometry, casadi):
    """Every boresight solve of 001 ch. 2-3 on one random map; errors [rad], NaN when a solve fails."""
    g = geometry
    ref, xy0, w = g.draw(rng, stars)
    n = len(ref)
    xy = xy0 + rng.normal(scale=g.sigma, size=xy0.shape)
    radii = np.hypot(xy[:, 0], xy[:, 1])
    out = {"stars": n, "crb_vector": g.crb_vector(xy0), "crb_scalar": g.crb_scalar(xy0)}
    t = rng.choice(n, 3, replace=False)
    for method, call in (
        ("scalar_known_f_normalised", lambda: bs.solve_scalar_known_f(ref[t], radii[t], g.focal)),
        ("scalar_known_f_linearised", lambda: bs.solve_scalar_known_f(ref[t], radii[t], g.focal, "linearised")),
        ("scalar_unknown_f_numeric", lambda: bs.solve_scalar_unknown_f(ref[t], radii[t], g.focal_bounds)),
        ("vector_known_f_svd", lambda: bs.solve_vector_known_f(ref[t], xy[t], g.focal)),
        ("vector_unknown_f_analytic", lambda: bs.solve_vector_unknown_f(ref[t], xy[t])),
        ("vector_unknown_f_numeric", lambda: bs.solve_vector_unknown_f(ref[t], xy[t], "numeric", g.focal_bounds)),
    ):
        try:
            out[method] = float(min(angular_distance(c, w) for c in call().candidates))
        except bs.InputError:
            out[method] = np.nan              # no admissible root, or a degenerate triple
    out["crb_vector_triple"] = g.crb_vector(xy0[t])
    out["crb_scalar_triple"] = g.crb_scalar(xy0[t])
    out["scalar_all_ols"] = float(angular_distance(bs.solve_scalar_all_stars(ref, radii, g.focal).boresight_I, w))
    out["scalar_all_constrained"] = float(angular_distance(bs.solve_scalar_all_stars(ref, radii, g.focal, "constrained").boresight_I, w))
    out["vector_all_ols"] = float(angular_distance(bs.solve_vector_all_stars(ref, xy, g.focal).boresight_I, w))
    unknown = bs.solve_vector_all_stars(ref, xy)
    out["vector_all_ols_unknown_f"] = float(angular_distance(unknown.boresight_I, w))
    out["vector_all_procrustes"] = float(angular_distance(bs.solve_vector_constrained(ref, xy, focal_px=g.focal).boresight_I, w))
    out["vector_all_constrained_ipopt"] = np.nan
    out["casadi_ms"] = np.nan
    if casadi:
        start = time.perf_counter()
        fit = bs.solve_vector_constrained(ref, xy)
        out["casadi_ms"] = 1e3 * (time.perf_counter() - start)
        out["vector_all_constrained_ipopt"] = float(angular_distance(fit.boresight_I, w))

    # rank among all triples (2.3.3 (二), 3.3.3 (二))
    triples = bs.all_triples(n)
    P_rows = ref[triples]
    well_posed = np.linalg.svd(P_rows, compute_uv=False)[:, 2] > 1e-9
    triples, P_rows = triples[well_posed], P_rows[well_posed]
    scalar_all = angular_distance(bs.scalar_known_f_batch(P_rows, bs.cos_gamma(radii[triples], g.focal)), w)
    _, vector_w = bs.vector_known_f_batch(P_rows, bs.sensor_directions(xy[triples], g.focal))
    vector_all = angular_distance(vector_w, w)
    f_triples, _ = bs.focal_cubic_batch(P_rows, xy[triples])
    ok = np.isfinite(f_triples)
    _, vector_w_unknown = bs.vector_known_f_batch(P_rows[ok], bs.sensor_directions(xy[triples[ok]], f_triples[ok][:, None]))
    vector_unknown_all = np.full(len(triples), np.inf)           # a triple without a root counts as worst
    vector_unknown_all[ok] = angular_distance(vector_w_unknown, w)

    def triple_error(best, errors):
        return errors[np.flatnonzero(np.all(triples == best, axis=1))[0]]

    best = {"scalar_known_f": (bs.best_triple(ref, g.focal, radii_px=radii), scalar_all, out["scalar_all_ols"]),
            "vector_known_f": (bs.best_triple(ref, g.focal, xy_px=xy), vector_all, out["vector_all_ols"]),
            "vector_unknown_f": (bs.best_triple(ref, unknown.focal_px, xy_px=xy), vector_unknown_all,
                                 out["vector_all_ols_unknown_f"])}
    for model, (triple, errors, ols) in best.items():
        out[f"rank_{model}_best_triple"] = beats(triple_error(triple, errors), errors)
        out[f"rank_{model}_ols"] = beats(ols, errors)
    return out


def identification_maps(identifier, camera, stars, maps, false_stars, sigma_px, rng, progress, label):
    """Per-map outcome of the full-sky identification: arrays ok, false, error (S axes) [rad], CRB σ [rad], ms."""
    rows = {"ok": [], "false": [], "ms": [], "stars": [], "matched": [], "error": [], "crb": []}
    for _ in progress_bar(range(maps), progress, label):
        frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(rng), rng, sigma_px,
                               n_false=int(rng.integers(false_stars[0], false_stars[1] + 1)))
        result = identifier.solve(frame.uv, frame.flux)
        error, crb, false, matched = np.full(3, np.nan), np.full(3, np.nan), False, 0
        if result.ok:
            error = (Rotation.from_quat(result.q_IS).inv() * Rotation.from_quat(frame.q_IS)).as_rotvec()
            crb = np.sqrt(np.diag(result.covariance))
            wrong_ids = bool(np.any(frame.hip[result.matches[:, 0]] != result.matches[:, 1]))
            false = wrong_ids or np.hypot(error[0], error[1]) > FALSE_MATCH_ARCSEC * units.ARCSEC
            matched = len(result.matches)
        for key, value in (("ok", result.ok and not false), ("false", false), ("ms", result.solve_ms),
                           ("stars", int(np.count_nonzero(frame.hip))), ("matched", matched), ("error", error),
                           ("crb", crb)):
            rows[key].append(value)
    return {key: np.array(value) for key, value in rows.items()}


def rms(values):
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    return float(np.sqrt(np.mean(np.square(values)))) if values.size else float("nan")


def run(params, seed, progress=False):
    """Run both parts; returns (summary, per-map arrays for the figures)."""
    p = params
    geometry = MapGeometry(p)
    stars = load_star_catalog().brighter_than(p["mag_limit"])
    optical_seed, identification_seed = np.random.SeedSequence(seed).spawn(2)
    summary = {"focal_px": geometry.focal, "sigma_arcsec": p["centroid_sigma_px"] / geometry.focal / units.ARCSEC,
               "catalog_stars": len(stars)}
    arrays = {}
    if p["maps"]:
        streams = optical_seed.spawn(p["maps"])
        rows = [optical_axis_map(np.random.default_rng(s), stars.vectors, geometry, k < p["casadi_maps"])
                for k, s in enumerate(progress_bar(streams, progress, "001 optical-axis maps"))]
        arrays |= {f"optical_{key}": np.array([r[key] for r in rows], dtype=float) for key in rows[0]}
        summary["optical_axis"] = optical_summary(arrays)
    if p["identification_maps"]:
        camera = Camera.from_fov(np.radians(p["fov_deg"]), p["width_px"], p["width_px"])
        catalog = load_navigation_catalog(NavigationCatalogParams(fov=np.radians(p["fov_deg"]), mag_limit=p["mag_limit"]),
                                          progress=progress)
        summary["identification"] = {}
        for gate, stream in zip(p["gate_sigmas"], identification_seed.spawn(len(p["gate_sigmas"]))):
            identifier = StarIdentifier(catalog, camera, centroid_sigma_px=p["centroid_sigma_px"], delta_sigmas=gate)
            warm_up = np.random.default_rng(0)          # compile and load the kernels before anything is timed
            frame = centroid_frame(camera, stars.vectors, stars.hip, stars.v_mag, random_attitude(warm_up), warm_up,
                                   p["centroid_sigma_px"])
            identifier.solve(frame.uv, frame.flux)
            rows = identification_maps(identifier, camera, stars, p["identification_maps"], p["false_stars"],
                                       p["centroid_sigma_px"], np.random.default_rng(stream), progress,
                                       f"001 identification, δ = {gate:g} σ")
            name = f"gate_{gate:g}_sigma"
            arrays |= {f"id_{name}_{key}": value for key, value in rows.items()}
            summary["identification"][name] = identification_summary(rows, gate, p["centroid_sigma_px"])
    summary["paper_comparison"] = comparison(summary, p)
    summary["notes"] = explain(summary, p)
    return summary, arrays


def optical_summary(arrays):
    n = arrays["optical_stars"]
    out = {"maps": int(n.size), "stars_per_map": {"mean": float(n.mean()), "min": int(n.min()), "max": int(n.max())},
           "crb_rms_arcsec": {key: rms(arrays[f"optical_{key}"]) / units.ARCSEC
                              for key in ("crb_scalar_triple", "crb_vector_triple", "crb_scalar", "crb_vector")},
           "rms_arcsec": {}, "median_arcsec": {}, "failures": {}}
    for method in TRIPLE_METHODS + ALL_STAR_METHODS:
        values = arrays[f"optical_{method}"]
        attempted = values if method != "vector_all_constrained_ipopt" else values[np.isfinite(arrays["optical_casadi_ms"])]
        out["rms_arcsec"][method] = rms(attempted) / units.ARCSEC
        out["median_arcsec"][method] = float(np.nanmedian(attempted) / units.ARCSEC) if np.isfinite(attempted).any() else None
        out["failures"][method] = int(np.count_nonzero(~np.isfinite(attempted)))
    casadi = arrays["optical_casadi_ms"][np.isfinite(arrays["optical_casadi_ms"])]
    out["casadi_maps"] = int(casadi.size)
    out["casadi_ms_median"] = float(np.median(casadi)) if casadi.size else None
    n_stars = arrays["optical_stars"]
    out["best_triple_rank_by_stars"] = {}
    for low, high in ((4, 10), (11, 25), (26, 10 ** 6)):
        chosen = (n_stars >= low) & (n_stars <= high)
        out["best_triple_rank_by_stars"][f"{low}-{high}" if high < 10 ** 6 else f">={low}"] = {
            "maps": int(chosen.sum()),
            **{model.split("_")[0]: float(np.mean(arrays[f"optical_rank_{model}_best_triple"][chosen])) if chosen.any()
               else None for model in ("scalar_known_f", "vector_known_f")}}
    out["rank_beats_percent"] = {model: {method: float(np.mean(arrays[f"optical_rank_{model}_{method}"]))
                                         for method in RANK_METHODS} for model in RANK_MODELS}
    return out


def identification_summary(rows, gate, sigma_px):
    ok = rows["ok"]
    error, crb = rows["error"][ok] / units.ARCSEC, rows["crb"][ok] / units.ARCSEC
    ms = rows["ms"]
    return {
        "gate_sigmas": gate, "gate_px": gate * sigma_px, "maps": int(ok.size),
        "recognised_percent": 100.0 * float(np.mean(ok)), "false_matches": int(np.count_nonzero(rows["false"])),
        "cross_boresight_rms_arcsec": rms(error[:, :2]), "cross_boresight_crb_rms_arcsec": rms(crb[:, :2]),
        "roll_rms_arcsec": rms(error[:, 2]), "roll_crb_rms_arcsec": rms(crb[:, 2]),
        "matched_stars_mean": float(np.mean(rows["matched"][ok])) if ok.any() else 0.0,
        "stars_per_map_mean": float(np.mean(rows["stars"])),
        "solve_ms": {"median": float(np.median(ms)), "p95": float(np.percentile(ms, 95)), "max": float(ms.max())},
    }


def comparison(summary, p):
    """Rows (quantity, ours, paper, source) where our set-up is 001's; none otherwise."""
    if not paper_setup_matches(p):
        return []
    rows = []
    optical = summary.get("optical_axis")
    if optical:
        for model, paper in PAPER_BEATS.items():
            for method, label in (("best_triple", "best triple (least ‖M‖)"), ("ols", "OLS over all stars")):
                rows.append({"quantity": f"{model.replace('_', ' ')}: {label} beats [% of triples]",
                             "ours": f"{optical['rank_beats_percent'][model][method]:.1f}", "paper": f"{paper[method]}",
                             "source": "001 §2.3.3, §3.3.3"})
    for name, s in summary.get("identification", {}).items():
        rows.append({"quantity": f"maps recognised, δ = {s['gate_px']:.2f} px ({s['maps']} maps, 1-3 false stars) [%]",
                     "ours": f"{s['recognised_percent']:.1f} ({s['false_matches']} false)",
                     "paper": f"{PAPER_RECOGNISED_PERCENT:.0f} of {PAPER_MAPS} maps", "source": "001 §5.4"})
    return rows


def explain(summary, p):
    """What the comparison shows and why ours differs where it does."""
    if not paper_setup_matches(p):
        return ["The set-up differs from 001's (12 deg, 512 px, σ = 0.05 px, V ≤ 6), so 001's printed figures are "
                "not shown beside ours."]
    lines = []
    optical = summary.get("optical_axis")
    if optical:
        crb = optical["crb_rms_arcsec"]
        r = optical["rms_arcsec"]
        excess = {m: 100.0 * (r[m] / crb["crb_vector"] - 1.0)
                  for m in ("vector_all_ols", "vector_all_procrustes", "vector_all_constrained_ipopt")}
        lines.append(f"All-star solves against the bound (vector data): OLS {r['vector_all_ols']:.2f}\", Procrustes "
                     f"(f known) {r['vector_all_procrustes']:.2f}\", Ipopt (f unknown, first {optical['casadi_maps']} maps) "
                     f"{r['vector_all_constrained_ipopt']:.2f}\"; Cramér-Rao RMS (f known) {crb['crb_vector']:.2f}\", i.e. "
                     + ", ".join(f"{m} {v:+.0f} %" for m, v in excess.items())
                     + ". OLS ignores the orthogonality of R and pays for it.")
        lines.append(f"Triple solves have heavy tails (vector SVD triple: RMS {r['vector_known_f_svd']:.0f}\" against a "
                     f"median of {optical['median_arcsec']['vector_known_f_svd']:.1f}\"): nearly collinear triples, which is "
                     "why 001 picks the triple of least ‖M‖ and then prefers all stars.")
        ranks = optical["rank_beats_percent"]
        by_stars = optical["best_triple_rank_by_stars"]
        lines.append(f"Rank of the best triple: ours {ranks['scalar_known_f']['best_triple']:.0f} % (scalar) and "
                     f"{ranks['vector_known_f']['best_triple']:.0f} % (vector) against 001's 86 % and 81 %; OLS "
                     f"{ranks['scalar_known_f']['ols']:.0f} % and {ranks['vector_known_f']['ols']:.0f} % against 97 % and "
                     "90 %. The best-triple share does not depend on the stars per map ("
                     + ", ".join(f"{k} stars: {v['scalar']:.0f} % / {v['vector']:.0f} % over {v['maps']} maps"
                                 for k, v in by_stars.items() if v["maps"])
                     + "), so the gap is not our larger Hipparcos maps; 001 does not say which norm ‖M‖ is (ours: the "
                     "spectral norm of the first-order error map) nor how its contest catalog and maps were drawn.")
    for name, s in summary.get("identification", {}).items():
        lines.append(f"Identification with δ = {s['gate_px']:.2f} px: {s['recognised_percent']:.1f} % recognised, "
                     f"{s['false_matches']} false; cross-boresight error {s['cross_boresight_rms_arcsec']:.3f}\" RMS "
                     f"against a Cramér-Rao RMS of {s['cross_boresight_crb_rms_arcsec']:.3f}\", roll "
                     f"{s['roll_rms_arcsec']:.2f}\" against {s['roll_crb_rms_arcsec']:.2f}\"; median solve "
                     f"{s['solve_ms']['median']:.2f} ms.")
    return lines


def text(summary, params):
    """The printed tables: 001's figures beside ours."""
    del params
    lines = [f"f = {summary['focal_px']:.1f} px, σ = {summary['sigma_arcsec']:.2f}\", {summary['catalog_stars']} catalog stars"]
    optical = summary.get("optical_axis")
    if optical:
        lines.append(f"optical axis: {optical['maps']} maps, {optical['stars_per_map']['mean']:.1f} stars per map; "
                     "boresight RMS / median [arcsec], failures, CRB RMS (known f)")
        for method in TRIPLE_METHODS + ALL_STAR_METHODS:
            bound = optical["crb_rms_arcsec"][("crb_scalar" if method.startswith("scalar") else "crb_vector")
                                              + ("_triple" if method in TRIPLE_METHODS else "")]
            median = optical["median_arcsec"][method]
            lines.append(f"  {method:<30} {optical['rms_arcsec'][method]:10.3f} {median if median is not None else float('nan'):8.3f}"
                         f"   failures {optical['failures'][method]:4d}   CRB {bound:7.3f}")
        for model in RANK_MODELS:
            paper = PAPER_BEATS.get(model, {})
            ranks = optical["rank_beats_percent"][model]
            lines.append(f"  rank {model:<17} best triple {ranks['best_triple']:5.1f} % ({paper.get('best_triple', '-')})"
                         f"   OLS {ranks['ols']:5.1f} % ({paper.get('ols', '-')})   [001 in brackets]")
    for name, s in summary.get("identification", {}).items():
        lines.append(f"identification {name}: {s['recognised_percent']:.1f} % recognised (001: 100 %), "
                     f"{s['false_matches']} false, solve ms median {s['solve_ms']['median']:.3f} p95 {s['solve_ms']['p95']:.3f}")
    return lines + ["", *summary["notes"]]


def figures(summary, arrays, params):
    """(figure, caption) pairs: 001 Fig. 2.3-3.5 and the §5.4 identification outcome."""
    import matplotlib.pyplot as plt

    del params
    out = []
    optical = summary.get("optical_axis")
    if optical:
        groups = (("scalar a, three stars (001 Fig. 2.3/2.4)", TRIPLE_METHODS[:3], "crb_scalar_triple"),
                  ("vector a, three stars (001 Fig. 3.1/3.3)", TRIPLE_METHODS[3:], "crb_vector_triple"),
                  ("scalar a, all stars (001 Fig. 2.5)", ALL_STAR_METHODS[:2], "crb_scalar"),
                  ("vector a, all stars (001 Fig. 3.4)", ALL_STAR_METHODS[2:], "crb_vector"))
        fig, axes = plt.subplots(2, 2, figsize=(10, 6.4))
        for ax, (title, methods, bound) in zip(axes.ravel(), groups):
            values = {m: arrays[f"optical_{m}"] / units.ARCSEC for m in methods}
            finite = np.concatenate([v[np.isfinite(v)] for v in values.values()])
            bins = np.linspace(0.0, np.percentile(finite, 99), 40)
            for m, v in values.items():
                ax.hist(v[np.isfinite(v)], bins=bins, histtype="step", lw=1.2, label=f"{m} (median {np.nanmedian(v):.2f}\")")
            ax.axvline(optical["crb_rms_arcsec"][bound], color="k", ls=":", label="Cramér-Rao RMS (known f)")
            ax.set_title(title, fontsize=9)
            ax.set_xlabel("boresight error [arcsec]")
            ax.legend(fontsize=6)
        fig.tight_layout()
        out.append((fig, f"Boresight error of the optical-axis solves over {optical['maps']} random maps (the largest 1 % "
                         "of each is off the scale)."))
        fig, axes = plt.subplots(1, 3, figsize=(10, 3.0), sharey=True)
        for ax, model in zip(axes, RANK_MODELS):
            for method in RANK_METHODS:
                ax.hist(arrays[f"optical_rank_{model}_{method}"], bins=np.linspace(0, 100, 41), histtype="step", lw=1.2,
                        label=f"{method} (mean {optical['rank_beats_percent'][model][method]:.1f} %)")
            ax.set_title(model, fontsize=9)
            ax.set_xlabel("share of triples beaten [%]")
            ax.legend(fontsize=6, loc="upper left")
        axes[0].set_ylabel("maps")
        fig.tight_layout()
        out.append((fig, "001 Fig. 2.6/3.5: rank of the best triple and of OLS among all triples of each map."))
    identification = summary.get("identification", {})
    if identification:
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.4))
        first = next(iter(identification))
        ok = arrays[f"id_{first}_ok"].astype(bool)
        ratio = (arrays[f"id_{first}_error"][ok, :2] / arrays[f"id_{first}_crb"][ok, :2]).ravel()
        axes[0].hist(ratio, bins=50, density=True, label="cross-boresight error / CRB σ")
        x = np.linspace(-4, 4, 200)
        axes[0].plot(x, np.exp(-x * x / 2) / np.sqrt(2 * np.pi), "k--", label="N(0, 1)")
        axes[0].set_xlabel("normalised attitude error")
        axes[0].legend(fontsize=7)
        for name in identification:
            axes[1].hist(arrays[f"id_{name}_ms"], bins=60, histtype="step", label=name)
        axes[1].set_xlabel("solve time [ms]")
        axes[1].set_yscale("log")
        axes[1].legend(fontsize=7)
        fig.tight_layout()
        out.append((fig, "001 §5.4: attitude error of the recognised maps normalised by the Cramér-Rao σ, and the solve "
                         "time of the full-sky identification."))
    return out


def key_results(summary, params):
    """(quantity, value, unit) rows for the report's key-result table."""
    del params
    rows = []
    optical = summary.get("optical_axis")
    if optical:
        r, crb = optical["rms_arcsec"], optical["crb_rms_arcsec"]
        rows += [("maps (optical axis)", f"{optical['maps']}", ""),
                 ("vector all-star OLS RMS", f"{r['vector_all_ols']:.3f}", "arcsec"),
                 ("vector Procrustes RMS", f"{r['vector_all_procrustes']:.3f}", "arcsec"),
                 ("Cramér-Rao RMS (vector, all stars)", f"{crb['crb_vector']:.3f}", "arcsec"),
                 ("casadi/Ipopt fit, median", "n/a" if optical["casadi_ms_median"] is None
                  else f"{optical['casadi_ms_median']:.1f}", "ms")]
    for name, s in summary.get("identification", {}).items():
        rows += [(f"recognised, δ = {s['gate_px']:.2f} px", f"{s['recognised_percent']:.1f}", "%"),
                 (f"false matches, δ = {s['gate_px']:.2f} px", f"{s['false_matches']}", "maps"),
                 (f"median solve, δ = {s['gate_px']:.2f} px", f"{s['solve_ms']['median']:.3f}", "ms")]
    return rows
