"""Tune the attitude filter from Python: a grid over the process-noise scale, then navsim.campaign.tuning.

The filter below assumes a gyro twice as good as the one flown (ARW 0.05 instead of 0.1 deg/√h),
so it is over-confident: its NEES per degree of freedom is well above 1. The grid shows how the
consistency statistics and the error move with the process-noise scale; `tune` then fits both
scale factors. Every batch uses the same seeds (common random numbers).

    .venv/bin/python examples/tune_filter.py
"""

from navsim.campaign.tuning import batch_statistics, tune
from navsim.simulation import run_batch

SCENARIO = {
    "name": "tuning-example",
    "duration_s": 120.0,
    "truth": {"profile": "constant_rate", "rate_hz": 40.0, "constant_rate": {"rate_deg_per_s": [0.5, -0.3, 0.8]}},
    "gyro": {"rate_hz": 10.0, "arw_deg_per_sqrt_h": 0.1, "rrw_deg_per_h_per_sqrt_h": 0.5, "bias_turn_on_deg_per_h": 5.0},
    "star_sensor": {"measurement": "attitude", "rate_hz": 1.0, "fov_deg": 16.0,
                    "attitude_sigma_cross_arcsec": 10.0, "attitude_sigma_roll_arcsec": 30.0},
    "filter": {"arw_deg_per_sqrt_h": 0.05},
}
SEEDS = range(20)

print(f"{'Q scale':>8} {'NEES/dof':>9} {'NIS/dof':>8} {'cross RMS':>10}")
for q_scale in (0.5, 1.0, 2.0, 4.0, 8.0):
    results = run_batch(SCENARIO, SEEDS, overrides={"filter.process_noise_scale": q_scale})
    batch = batch_statistics(results, settle_s=12.0)
    print(f"{q_scale:8.2f} {batch.nees_per_dof:9.3f} {batch.nis_per_dof:8.3f} {batch.errors['cross-boresight RMS'][0]:9.2f}\"")

fitted = tune(SCENARIO, runs=len(SEEDS))
first, last = fitted.steps[0], fitted.steps[-1]
print(f"tune: Q scale {last.process_noise_scale:.3f} (expected near 4: ARW² ratio), R scale "
      f"{last.measurement_noise_scale:.3f}; NEES/dof {first.nees_per_dof:.2f} -> {last.nees_per_dof:.2f}, "
      f"NIS/dof {first.nis_per_dof:.2f} -> {last.nis_per_dof:.2f}")
