"""Size a SINS/CNS from Python: which gyro and which star sensor keep the horizontal error under 500 m after 4 h
of the aircraft scenario, by linear covariance analysis (seconds a point instead of a Monte Carlo campaign).

1. One analysis of the scenario as shipped, with its error budget: which source leaves how much.
2. A sweep over the gyro's bias and the star sensor's noise (their requirement chart in sweep.pdf).
3. The sweep the budget points to: the accelerometer's bias against the star sensor's noise.

    .venv/bin/python examples/size_sins_cns.py [OUT_DIR]   (default reports/out/size_sins_cns)
"""

import sys
from pathlib import Path

import navsim
from navsim import analysis
from navsim.report import write_report

SCENARIO = Path(__file__).resolve().parents[1] / "scenarios" / "sins_cns_aircraft_vector.toml"
REQUIREMENT_M = 500.0
OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[1] / "reports" / "out" / "size_sins_cns"
STAR_SIGMA = ("star_sensor.star_sigma_arcsec", [1.0, 2.0, 5.0, 10.0, 20.0, 40.0])
SWEEPS = {"gyro_x_star_sensor": [("imu.gyro.bias_turn_on_deg_per_h", [0.001, 0.0035, 0.01, 0.03, 0.1, 0.3]), STAR_SIGMA],
          "accelerometer_x_star_sensor": [("imu.accelerometer.bias_turn_on_micro_g", [5.0, 10.0, 25.0, 50.0, 100.0, 200.0]),
                                          STAR_SIGMA]}


def main():
    scenario = navsim.resolve_scenario(SCENARIO)
    budget = analysis.budget(scenario, navsim.covariance(scenario, split=True), navsim.KINDS[scenario.kind].COVARIANCE_SOURCES)
    print("\n".join(analysis.budget_text(budget)))
    for name, vary in SWEEPS.items():
        result = navsim.run_sweep(SCENARIO, vary, "horizontal_position@4h", OUT / name, requirement=REQUIREMENT_M)
        meets = [point["values"] for point in result["points"] if point["value"] <= REQUIREMENT_M]
        print(f"\n{name}: {len(meets)} of {len(result['points'])} points meet {REQUIREMENT_M:g} m after 4 h "
              f"({', '.join(key for key, _ in vary)}); chart in {write_report(OUT / name, OUT / name / 'sweep.pdf')}")
        for point in result["points"]:
            print("  " + ", ".join(f"{v:g}" for v in point["values"]) + f": {point['value']:.0f} m")


if __name__ == "__main__":  # the sweep's workers are spawned processes: they import this file
    main()
