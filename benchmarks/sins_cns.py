"""SINS/CNS speed: one hour of the star-aided aircraft at vector fidelity, the image-fidelity real-time factor, a 1000-run campaign.

Data: scenarios/sins_cns_aircraft_vector.toml (11 km, 250 m/s, turns; navigation IMU at 200 Hz, 5 m
baro and star vectors at 1 Hz, the filter's full state with the star-sensor mounting, a random
gravity field along the track) and its image-fidelity twin scenarios/sins_cns_aircraft.toml, each
run through the code path of ``navsim run`` (the navigation kind's run: prepare once, simulate a seed).
Measured:

- vector fidelity: the first hour (duration_s = 3600), wall seconds of one run (simulate, best of
  --repeats after a warm-up run: numba compilation or cache load; the seed-free prepare apart), and
  the split of one run: truth, IMU synthesis, star sensor (sky truth and every frame's stars drawn),
  filter (the closed loop, frame by frame) and the rest (series, summary). Two configurations: the
  issue's 18 states (the INS's 15 and the mounting; no gravity field, so the truth trajectory is
  built once by prepare) and the shipped scenario's 21 (a random gravity field along the track, three
  consider states; the field is drawn per run, so every run adds its term to the seed-free
  increments prepare built);
- image fidelity: the first --image-minutes (default 10) of flight, every frame rendered, detected
  and identified with the INS's prediction: the real-time factor (simulated s / wall s) and the
  wall milliseconds per frame of one run after a warm-up run of one minute;
- campaign: --campaign-runs (default 1000) runs of the 18-state vector hour through the real campaign
  runner (navsim.campaign.montecarlo.run_campaign: truth, IMU and stars, filter, series, summary and
  files of every run, two worker processes with single-threaded BLAS), wall minutes (and per 1000
  runs when fewer are asked for), with the campaign's NEES mean and its 95 % band.

    python benchmarks/sins_cns.py [--repeats 3] [--image-minutes 10] [--campaign-runs 1000]

Prints a table and writes benchmarks/results/sins_cns.json. Asserts nothing.
"""

import argparse
import json
import os
import platform
import sys
import time
from contextlib import contextmanager
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

from strapdown import best, campaign_minutes  # noqa: E402  (the same measures as the strapdown benchmark)

from navsim.kinds import load_scenario  # noqa: E402
from navsim.navigation import run as simulation  # noqa: E402
from navsim.truth import trajectory  # noqa: E402

HOUR = 3600.0
GOALS = {"vector_1h_s": 2.0, "campaign_1000x1h_min_on_2_cores": 10.0}
VECTOR = ROOT / "scenarios" / "sins_cns_aircraft_vector.toml"
IMAGE = ROOT / "scenarios" / "sins_cns_aircraft.toml"
#: The vector runs: the scenario's first hour, with its random gravity field (21 states) and without
#: (the issue's 18 states).
FIRST_HOUR = {"duration_s": HOUR}
FIRST_HOUR_18_STATES = {"duration_s": HOUR, "gravity": None}
#: The split of a run: simulate's steps, by the name simulate calls them through.
STEPS = {"truth": (trajectory, "with_gravity"), "star_sensor": (simulation, "_star_run"),
         "filter": (simulation, "run_loop")}


@contextmanager
def timed_steps(prepared):
    """Wall seconds of simulate's steps (module docstring) while inside: timers wrapped around the
    functions it calls (IMU synthesis: the gyro's and accelerometer's ``measure``; the star sensor:
    the sky truth too), yielding the dict they fill."""
    seconds = {}
    targets = [(module, name, step) for step, (module, name) in STEPS.items()]
    targets += [(type(prepared.gyro), "measure", "imu"), (type(prepared.accel), "measure", "imu"),
                (simulation.SkyTruth, "of", "star_sensor")]
    saved = [(owner, name, owner.__dict__[name]) for owner, name, _ in targets]

    def wrap(function, step):
        def timed(*args, **kwargs):
            start = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                seconds[step] = seconds.get(step, 0.0) + time.perf_counter() - start
        return timed

    try:
        for owner, name, step in targets:
            attribute = owner.__dict__[name]
            wrapped = wrap(getattr(owner, name), step)
            setattr(owner, name, classmethod(lambda cls, *a, _w=wrapped, **k: _w(*a, **k))
                    if isinstance(attribute, classmethod) else wrapped)
        yield seconds
    finally:
        for owner, name, attribute in reversed(saved):
            setattr(owner, name, attribute)


def vector_hour(repeats, overrides):
    """The vector-fidelity hour (``overrides`` of the scenario): prepare's wall seconds, simulate's best
    of ``repeats``, the split and the filter's state count."""
    scenario = load_scenario(VECTOR, overrides)
    start = time.perf_counter()
    prepared = simulation.prepare(scenario)
    prepare_s = time.perf_counter() - start
    best_s, times = best(lambda: simulation.simulate(prepared, 1), repeats)
    with timed_steps(prepared) as split:
        start = time.perf_counter()
        simulation.simulate(prepared, 1)
        total = time.perf_counter() - start
    split = {step: split.get(step, 0.0) for step in ("truth", "imu", "star_sensor", "filter")}
    split["rest"] = total - sum(split.values())
    return {"filter_states": simulation.simulate(prepared, 1).summary["navigation"]["filter_states"],
            "simulated_s": prepared.grid.n_frames * prepared.grid.ratio * prepared.grid.dt,
            "frames": prepared.grid.n_frames, "prepare_s": prepare_s, "run_s_best": best_s, "wall_s": times,
            "split_s": split, "split_run_s": total}


def image_run(minutes):
    """The image-fidelity aircraft over its first ``minutes``: real-time factor and ms per frame of one
    run after a warm-up run of one minute."""
    warm = simulation.prepare(load_scenario(IMAGE, {"duration_s": 60.0}))
    simulation.simulate(warm, 1)
    prepared = simulation.prepare(load_scenario(IMAGE, {"duration_s": 60.0 * minutes}))
    start = time.perf_counter()
    result = simulation.simulate(prepared, 1)
    wall = time.perf_counter() - start
    simulated = prepared.grid.n_frames * prepared.grid.ratio * prepared.grid.dt
    timing = result.summary.timing
    return {"simulated_s": simulated, "frames": prepared.grid.n_frames, "wall_s": wall,
            "real_time_factor": simulated / wall, "ms_per_frame": 1000.0 * wall / prepared.grid.n_frames,
            "frame_ms": timing.get("frame_ms"), "identification_ms": timing.get("identification_ms")}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--image-minutes", type=float, default=10.0)
    parser.add_argument("--campaign-runs", type=int, default=1000)
    args = parser.parse_args()
    results = {"vector_1h": vector_hour(args.repeats, FIRST_HOUR_18_STATES),
               "vector_1h_gravity_field": vector_hour(args.repeats, FIRST_HOUR), "image": image_run(args.image_minutes)}
    image = results["image"]
    print(f"{'SINS/CNS aircraft, IMU 200 Hz, stars 1 Hz':44s} {'wall':>10s} {'goal':>8s}")
    for key in ("vector_1h", "vector_1h_gravity_field"):
        vector = results[key]
        label = f"1 h at vector fidelity, {vector['filter_states']} states (best)"
        print(f"{label:44s} {vector['run_s_best']:8.2f} s {GOALS['vector_1h_s']:6.1f} s")
        split = ", ".join(f"{step.replace('_', ' ')} {seconds:.2f}" for step, seconds in vector["split_s"].items())
        print(f"  split of one run ({vector['split_run_s']:.2f} s): {split} s; prepare {vector['prepare_s']:.2f} s (once)")
    label = f"{image['simulated_s'] / 60:.0f} min at image fidelity"
    print(f"{label:44s} {image['wall_s']:8.1f} s   "
          f"real-time factor {image['real_time_factor']:.1f}, {image['ms_per_frame']:.1f} ms per frame")
    results["campaign"] = campaign_minutes(args.campaign_runs, VECTOR, FIRST_HOUR_18_STATES)
    campaign = results["campaign"]
    print(f"campaign of {campaign['runs']} x 1 h through navsim's campaign runner on 2 workers: "
          f"{campaign['wall_min_on_2_workers']:.1f} min, {campaign['per_1000_runs_min']:.1f} min per 1000 runs "
          f"(goal {GOALS['campaign_1000x1h_min_on_2_cores']:.0f}); NEES {campaign['nees_mean']:.2f} "
          f"(95 % band {campaign['nees_band_95'][0]:.2f}-{campaign['nees_band_95'][1]:.2f}, {campaign['nees_dof']} dof), "
          f"{campaign['divergent_runs']} divergent")
    out = HERE / "results" / "sins_cns.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    payload = {"machine": platform.platform(), "python": platform.python_version(), "cpu_count": os.cpu_count(),
               "imu_rate_hz": 200.0, "star_rate_hz": 1.0, "goals": GOALS, "results": results}
    out.write_text(json.dumps(payload, indent=2) + "\n")
    print(f"written {out}")


if __name__ == "__main__":
    main()
