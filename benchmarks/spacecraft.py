"""The spacecraft beside Basilisk: one LEO inertial hold through both, orbit, gyro, star-tracker fixes and filters.

The case (issue 51 item 7): a 550 km, 97.6 deg orbit from the same state in both (two-body + J2: ours
``navsim.orbit.numerical``, Basilisk's hub with its spherical-harmonics gravity set to J2), a 300/350/250 kg m²
spacecraft held inertially and at rest in both (ours: the rigid body with frictionless wheels and its controller on
a fixed target, no gravity gradient; Basilisk: the torque-free hub), the dynamics at 100 Hz in both, star-tracker
attitude fixes at 1 Hz (5" about the cross axes, 40" about its boresight = body z) and each one's attitude filter:
our MEKF (``navsim.estimation.attitude_filter``: attitude and gyro bias from a 10 Hz gyro, ARW 0.002 deg/√h, RRW
0.0002 deg/h/√h, turn-on bias σ 0.01 deg/h) and Basilisk's ``inertialUKF`` (MRP and body rate), which takes the
fixes only (its gyro buffer serves its output between fixes; see benchmarks/peers/basilisk_runner.py) and gets its
process noise from the same gyro figures. Measured per seed (--runs), each filter against its own truth after
--settle:

- orbit: the largest distance between our propagation and Basilisk's of the same state [m] (Basilisk is handed the
  state in axes whose z is our pole, so both have J2 about the same axis);
- attitude: error RMS about each body axis ["] with its standard error over the runs, the per-axis normalised error
  RMS (1 for a consistent filter) and each filter's NEES over its own attitude states (ours: attitude and bias,
  6 dof; Basilisk's: attitude, 3 dof, its MRP covariance mapped to small angles by B(σ), eq. 3.155 of Schaub &
  Junkins) against the 95 % band;
- wall time per simulated second: ours the seed-free prepare (truth dynamics, orbit) and the seeded run (gyro,
  fixes, filter) once the kernels are compiled or loaded; Basilisk's ExecuteSimulation (its set-up apart).

    python benchmarks/spacecraft.py [--runs 20] [--duration 3000]

Needs Basilisk's venv (``make bench`` or ``sh benchmarks/peers/setup_venvs.sh``); prints a table and writes
benchmarks/results/spacecraft.json. Asserts nothing.
"""

import argparse
import json
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

from navsim import simulation
from navsim.earth.wgs84 import GM
from navsim.earth.wgs84 import A as R_EARTH
from navsim.estimation.consistency import nees_statistics
from navsim.kinds import resolve_scenario
from navsim.orbit.elements import J2
from navsim.spacecraft import build
from startrack.base.units import ARCSEC, DEG, HOUR
from startrack.geometry import rotation as rot

BASILISK = {"python": HERE / ".venv-basilisk" / "bin" / "python", "runner": HERE / "peers" / "basilisk_runner.py"}
ARW_DEG_PER_SQRT_H, RRW_DEG_PER_H_PER_SQRT_H, BIAS_DEG_PER_H = 0.002, 0.0002, 0.01
CROSS_ARCSEC, ROLL_ARCSEC, GYRO_HZ, FIX_HZ, TRUTH_HZ = 5.0, 40.0, 10.0, 1.0, 100.0
INITIAL_ATTITUDE_SIGMA_RAD, INITIAL_RATE_SIGMA_RAD_S = 1e-3, 1e-4
INERTIA = [[300.0, 0.0, 0.0], [0.0, 350.0, 0.0], [0.0, 0.0, 250.0]]


def case(duration):
    """Our scenario of the case (the spacecraft kind)."""
    return {
        "name": "basilisk_leo", "epoch_utc": "2000-01-01T12:00:00", "duration_s": duration, "seed": 0,
        "orbit": {"elements": {"height_km": 550.0, "inclination_deg": 97.6, "raan_deg": 30.0}},
        "pointing": {"law": "targets", "targets": [{"start_s": 0.0, "ra_deg": 120.0, "dec_deg": 30.0}]},
        "spacecraft": {"inertia_kg_m2": INERTIA, "gravity_gradient": False, "truth_rate_hz": TRUTH_HZ,
                       "wheels": {"viscous_N_m_s_per_rad": 0.0, "coulomb_N_m": 0.0}},
        "gyro": {"rate_hz": GYRO_HZ, "arw_deg_per_sqrt_h": ARW_DEG_PER_SQRT_H,
                 "rrw_deg_per_h_per_sqrt_h": RRW_DEG_PER_H_PER_SQRT_H, "bias_turn_on_deg_per_h": BIAS_DEG_PER_H},
        "star_sensor": [{"rate_hz": FIX_HZ, "fov_deg": 20.0, "measurement": "attitude",
                         "attitude_sigma_cross_arcsec": CROSS_ARCSEC, "attitude_sigma_roll_arcsec": ROLL_ARCSEC,
                         "mounting_rotvec_deg": [0.0, 0.0, 0.0], "sun_exclusion_deg": 0.0, "moon_exclusion_deg": 0.0,
                         "earth_exclusion_deg": -90.0}],
        "filter": {"initial_attitude_sigma_deg": INITIAL_ATTITUDE_SIGMA_RAD / DEG},
    }


def pole_axes(pole):
    """R (3, 3): GCRS components to axes whose z is ``pole`` (x in the GCRS x-z plane)."""
    z = np.asarray(pole) / np.linalg.norm(pole)
    x = np.array([1.0, 0.0, 0.0]) - z[0] * z
    x /= np.linalg.norm(x)
    return np.array([x, np.cross(z, x), z])


def mrp_from_quaternion(q):
    """σ (..., 3) of a scalar-last q_IB: Basilisk's σ_BN, the MRP of [BN] = R_IBᵀ (Schaub & Junkins eq. 3.131), the
    short set (|σ| <= 1)."""
    q = rot.normalize(q)
    q = np.where(q[..., 3:] < 0.0, -q, q)
    return q[..., :3] / (1.0 + q[..., 3:])


def quaternion_from_mrp(s):
    """q_IB (..., 4) of Basilisk's σ_BN (the inverse of :func:`mrp_from_quaternion`)."""
    s = np.asarray(s, dtype=float)
    s2 = np.sum(s * s, axis=-1, keepdims=True)
    return np.concatenate([2.0 * s, 1.0 - s2], axis=-1) / (1.0 + s2)


def mrp_b_matrix(s):
    """B(σ) (3, 3) of σ̇ = ¼ B(σ) ω (Schaub & Junkins eq. 3.155): a small rotation δθ in B moves σ by ¼ B δθ."""
    s = np.asarray(s, dtype=float)
    return (1.0 - s @ s) * np.eye(3) + 2.0 * rot.skew(s) + 2.0 * np.outer(s, s)


def ours(scenario, seed):
    """One run of ours: (result, prepare [s], simulate [s])."""
    start = time.perf_counter()
    prepared = simulation.prepare(scenario)
    middle = time.perf_counter()
    result = simulation.simulate(prepared, seed)
    return result, middle - start, time.perf_counter() - middle


def basilisk_input(scenario, seed, series, axes):
    """The runner's input (benchmarks/peers/basilisk_runner.py) for the case and our run's ``series`` (its truth's
    initial attitude), the orbit in ``axes``."""
    r0, v0 = build.orbit(scenario).states(np.array([0.0]))
    return {
        "duration_s": scenario["duration_s"], "dynamics_step_s": 1.0 / TRUTH_HZ, "orbit_sample_s": 10.0, "seed": int(seed),
        "orbit": {"r_m": (axes @ r0[0]).tolist(), "v_m_s": (axes @ v0[0]).tolist(), "mu_m3_s2": GM, "j2": J2,
                  "radius_m": R_EARTH},
        "inertia_kg_m2": INERTIA, "sigma_BN0": mrp_from_quaternion(series["q_true"][0]).tolist(), "omega_BN0_rad_s": [0.0, 0.0, 0.0],
        "gyro": {"rate_hz": GYRO_HZ, "arw_rad_per_sqrt_s": ARW_DEG_PER_SQRT_H * DEG / np.sqrt(HOUR),
                 "rrw_rad_per_s_sqrt_s": RRW_DEG_PER_H_PER_SQRT_H * DEG / HOUR / np.sqrt(HOUR)},
        "star_tracker": {"rate_hz": FIX_HZ, "sigma_rad": [CROSS_ARCSEC * ARCSEC, CROSS_ARCSEC * ARCSEC, ROLL_ARCSEC * ARCSEC]},
        "filter": {"initial_attitude_sigma_rad": INITIAL_ATTITUDE_SIGMA_RAD, "initial_rate_sigma_rad_s": INITIAL_RATE_SIGMA_RAD_S},
    }


def basilisk(inputs):
    """Basilisk's output for the runner's ``inputs`` (a dict), or None with the reason printed."""
    if not BASILISK["python"].exists():
        print(f"Basilisk missing: {BASILISK['python']} (sh benchmarks/peers/setup_venvs.sh)")
        return None
    with tempfile.TemporaryDirectory() as work:
        source, target = Path(work) / "input.json", Path(work) / "output.json"
        source.write_text(json.dumps(inputs))
        done = subprocess.run([str(BASILISK["python"]), str(BASILISK["runner"]), str(source), str(target)],
                              capture_output=True, text=True, check=False)
        if done.returncode != 0:
            print(f"Basilisk failed: {done.stderr.strip()[-500:]}")
            return None
        return json.loads(target.read_text())


def our_errors(series, settle):
    """(t, δθ (F, 3) [rad], σ (F, 3) [rad], NEES (F,), dof) of our run's steady frames."""
    steady = series["t"] >= settle
    return (series["t"][steady], series["attitude_error"][steady], np.sqrt(series["P_diag"][steady, :3]),
            series["nees"][steady], 6)


def basilisk_errors(out, settle):
    """The same of Basilisk's run: δθ in its estimate's body axes, its MRP covariance mapped by B(σ_est)."""
    t = np.asarray(out["t_s"])
    steady = t >= settle
    s_est = np.asarray(out["sigma_est"])[steady]
    error = rot.attitude_error(quaternion_from_mrp(s_est), quaternion_from_mrp(np.asarray(out["sigma_true"])[steady]))
    p_sigma = np.asarray(out["P_sigma"])[steady]
    inverse_b = np.linalg.inv(np.array([mrp_b_matrix(s) for s in s_est]))
    p_theta = 16.0 * inverse_b @ p_sigma @ np.swapaxes(inverse_b, 1, 2)
    nees = np.einsum("fi,fi->f", error, np.linalg.solve(p_theta, error[..., None])[..., 0])
    return t[steady], error, np.sqrt(np.einsum("fii->fi", p_theta)), nees, 3


def pooled(runs):
    """Per-axis error RMS ["], normalised RMS and the run-averaged NEES statistics of ``runs`` (each a tuple of
    :func:`our_errors`)."""
    frames = min(len(r[0]) for r in runs)
    error = np.concatenate([r[1][:frames] for r in runs])
    sigma = np.concatenate([r[2][:frames] for r in runs])
    nees = np.mean([r[3][:frames] for r in runs], axis=0)
    mean_square = np.array([np.mean(r[1][:frames] ** 2, axis=0) for r in runs])  # (runs, 3) [rad²]
    rms = np.sqrt(np.mean(mean_square, axis=0))
    spread = np.std(mean_square, axis=0, ddof=1) / np.sqrt(len(runs)) / (2.0 * rms) if len(runs) > 1 else np.zeros(3)
    return {"rms_arcsec": (rms / ARCSEC).tolist(), "rms_standard_error_arcsec": (spread / ARCSEC).tolist(),
            "normalised_rms": np.sqrt(np.mean((error / sigma) ** 2, axis=0)).tolist(),
            "nees": nees_statistics(nees, runs[0][4], len(runs))}


def orbit_difference(scenario, out, axes):
    """The largest distance [m] between our orbit and Basilisk's (rotated back to GCRS) at Basilisk's samples."""
    t = np.asarray(out["orbit_t_s"])
    r_ours, _ = build.orbit(scenario).states(t)
    return float(np.max(np.linalg.norm(r_ours - np.asarray(out["r_m"]) @ axes, axis=1)))


def measure(runs, duration, settle):
    """Every figure of the module docstring over ``runs`` seeds."""
    scenario = resolve_scenario(case(duration))
    axes = pole_axes(build.pole(scenario))
    ours(scenario, 0)  # warm-up: the kernels compiled or loaded
    mine, theirs, orbit, wall = [], [], [], {"ours": [], "basilisk": [], "basilisk_setup": []}
    for seed in range(1, runs + 1):
        result, prepare_s, simulate_s = ours(scenario, seed)
        wall["ours"].append(prepare_s + simulate_s)
        mine.append(our_errors(result.series, settle))
        out = basilisk(basilisk_input(scenario, seed, result.series, axes))
        if out is None:
            continue
        theirs.append(basilisk_errors(out, settle))
        orbit.append(orbit_difference(scenario, out, axes))
        wall["basilisk"].append(out["wall_s"])
        wall["basilisk_setup"].append(out["setup_s"])
        print(f"  seed {seed}: ours {wall['ours'][-1]:.2f} s, Basilisk {out['wall_s']:.1f} s (+{out['setup_s']:.1f} s set-up), "
              f"orbits {1e3 * orbit[-1]:.3f} mm apart", flush=True)
    per_second = {name: float(np.mean(values)) / duration for name, values in wall.items() if values}
    return {"ours": pooled(mine), "basilisk": pooled(theirs) if theirs else None,
            "orbit_max_difference_m": max(orbit) if orbit else None, "wall_s_per_simulated_s": per_second,
            "basilisk_gravity": out["gravity"] if theirs else None, "basilisk_note": out["note"] if theirs else None,
            "basilisk_version": out["bsk_version"] if theirs else None}


def table(figures):
    """The printed comparison."""
    lines = [f"{'':<28}{'ours (MEKF)':>22}{'Basilisk (inertialUKF)':>26}"]
    rows = (("attitude RMS x/y/z [\"]", lambda f: "/".join(f"{v:.2f}" for v in f["rms_arcsec"])),
            ("  its standard error [\"]", lambda f: "/".join(f"{v:.2f}" for v in f["rms_standard_error_arcsec"])),
            ("normalised RMS x/y/z", lambda f: "/".join(f"{v:.2f}" for v in f["normalised_rms"])),
            ("NEES mean (dof)", lambda f: f"{f['nees']['mean']:.2f} ({f['nees']['dof']})"),
            ("frames in 95 % band", lambda f: f"{100 * f['nees']['fraction_in_band']:.1f} %"))
    for label, cell in rows:
        theirs = cell(figures["basilisk"]) if figures["basilisk"] else "-"
        lines.append(f"{label:<28}{cell(figures['ours']):>22}{theirs:>26}")
    wall = figures["wall_s_per_simulated_s"]
    theirs = f"{1e3 * wall['basilisk']:.2f}" if "basilisk" in wall else "-"
    lines.append(f"{'wall ms per simulated s':<28}{1e3 * wall['ours']:>22.3f}{theirs:>26}")
    if figures["orbit_max_difference_m"] is not None:
        lines.append(f"orbit: largest distance between the two propagations {1e3 * figures['orbit_max_difference_m']:.3f} mm "
                     f"(Basilisk's gravity: {figures['basilisk_gravity']})")
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=20)
    parser.add_argument("--duration", type=float, default=3000.0, help="simulated seconds of each run")
    parser.add_argument("--settle", type=float, default=300.0, help="seconds left out of the statistics")
    args = parser.parse_args()
    figures = measure(args.runs, args.duration, args.settle)
    print(table(figures))
    figures.update({"runs": args.runs, "duration_s": args.duration, "settle_s": args.settle,
                    "machine": platform.processor() or platform.machine(), "python": platform.python_version()})
    out = HERE / "results" / "spacecraft.json"
    out.write_text(json.dumps(figures, indent=1))
    print(f"written to {out.relative_to(ROOT)}")


if __name__ == "__main__":
    main()
