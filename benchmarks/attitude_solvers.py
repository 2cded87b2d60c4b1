"""Speed and accuracy of the attitude solvers beside scipy's Rotation.align_vectors; casadi fit time.

For N = 3, 10, 30 stars in a 16 deg field with 1" per-axis noise: median microseconds per solve of
every startrack solver (the full public call: validation, quaternion, covariance, residuals) and of
``Rotation.align_vectors(ref_I, obs_S, weights)`` + ``as_quat()``; RMS attitude error of each over the
same noisy frames (equal accuracy check).  Then the median milliseconds of the casadi/Ipopt constrained
boresight fit with unknown focal length (001 3.3.2 (二)), N = 10 and 30.  Measures, never asserts.

Run:  python benchmarks/attitude_solvers.py [--calls 2000] [--seed 0]
Writes benchmarks/results/attitude_solvers.json.
"""

import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np
import scipy
from scipy.spatial.transform import Rotation

from startrack.attitude import boresight as bs
from startrack.attitude.solvers import SOLVERS
from startrack.base.units import ARCSEC

FOCAL = 256.0 / np.tan(np.radians(8.0))
SIGMA = 1.0 * ARCSEC


def frames(rng, n, count):
    """(ref_I (n, 3), noisy obs_S (count, n, 3), q_true) for one attitude and star set."""
    q_true = Rotation.random(random_state=rng).as_quat()
    xy = rng.uniform(-255.5, 255.5, size=(n, 2))
    obs = bs.sensor_directions(xy, FOCAL)
    ref = obs @ Rotation.from_quat(q_true).as_matrix().T
    noise = rng.normal(scale=SIGMA, size=(count, n, 3))
    noise -= np.sum(noise * obs, axis=-1, keepdims=True) * obs
    noisy = obs + noise
    return ref, noisy / np.linalg.norm(noisy, axis=-1, keepdims=True), q_true


def median_us(call, frames_obs):
    times = np.empty(len(frames_obs))
    for k, obs in enumerate(frames_obs):
        start = time.perf_counter_ns()
        call(obs)
        times[k] = time.perf_counter_ns() - start
    return float(np.median(times) / 1e3)


def rms_error_arcsec(quaternions, q_true):
    err = (Rotation.from_quat(np.array(quaternions)).inv() * Rotation.from_quat(q_true)).magnitude()
    return float(np.sqrt(np.mean(err ** 2)) / ARCSEC)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--calls", type=int, default=2000, help="timed calls per solver and N")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=Path, default=Path("benchmarks/results/attitude_solvers.json"))
    args = parser.parse_args()
    streams = iter(np.random.default_rng(s) for s in np.random.SeedSequence(args.seed).spawn(8))
    weights_of = lambda n: np.full(n, SIGMA ** -2)  # noqa: E731
    result = {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
              "calls": args.calls, "sigma_arcsec": 1.0, "fov_deg": 16.0, "solvers": {}}
    print(f"median us per solve (RMS error [arcsec] over the same {args.calls} frames)")
    header = f"{'N':>3} " + " ".join(f"{name:>17}" for name in list(SOLVERS) + ["scipy_align"])
    print(header)
    for n in (3, 10, 30):
        ref, noisy, q_true = frames(next(streams), n, args.calls)
        row = {}
        for name, solver in SOLVERS.items():
            for obs in noisy[:50]:                                  # warm-up
                solver.solve(ref, obs, SIGMA)
            us = median_us(lambda obs: solver.solve(ref, obs, SIGMA), noisy)
            accuracy = rms_error_arcsec([solver.solve(ref, obs, SIGMA).q_IS for obs in noisy], q_true)
            row[name] = {"median_us": us, "rms_error_arcsec": accuracy}
        weights = weights_of(n)
        us = median_us(lambda obs: Rotation.align_vectors(ref, obs, weights)[0].as_quat(), noisy)
        accuracy = rms_error_arcsec([Rotation.align_vectors(ref, obs, weights)[0].as_quat() for obs in noisy], q_true)
        row["scipy_align_vectors"] = {"median_us": us, "rms_error_arcsec": accuracy}
        result["solvers"][str(n)] = row
        print(f"{n:>3} " + " ".join(f"{v['median_us']:7.1f} ({v['rms_error_arcsec']:6.3f})" for v in row.values()))

    rng = next(streams)
    casadi = {}
    for n in (10, 30):
        times, errors = [], []
        for _ in range(20):
            R_IS = Rotation.random(random_state=rng).as_matrix()
            xy = rng.uniform(-255.5, 255.5, size=(n, 2))
            ref = bs.sensor_directions(xy, FOCAL) @ R_IS.T
            xy_noisy = xy + rng.normal(scale=0.05, size=xy.shape)
            bs.solve_vector_constrained(ref, xy_noisy)              # first call per N builds the NLP
            start = time.perf_counter()
            fit = bs.solve_vector_constrained(ref, xy_noisy)
            times.append(1e3 * (time.perf_counter() - start))
            errors.append(np.arccos(np.clip(fit.boresight_I @ R_IS[:, 2], -1, 1)))
        casadi[str(n)] = {"median_ms": float(np.median(times)), "rms_boresight_error_arcsec":
                          float(np.sqrt(np.mean(np.square(errors))) / ARCSEC)}
        print(f"casadi/Ipopt constrained boresight fit, unknown f, N = {n}: median {casadi[str(n)]['median_ms']:.1f} ms")
    result["casadi_constrained_fit"] = casadi
    args.out.parent.mkdir(parents=True, exist_ok=True)
    with open(args.out, "w") as handle:
        json.dump(result, handle, indent=1)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
