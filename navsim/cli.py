"""``navsim`` command line (contract in docs/design.md).

    navsim run SCENARIO.toml --out DIR [--seed N] [--set key=value ...] [--report [FILE.pdf]]
    navsim report DIR -o FILE.pdf
    navsim montecarlo SCENARIO.toml --runs N --out DIR [--workers K | --scheduler tcp://HOST:PORT]
    navsim tune SCENARIO.toml [--runs N] [--set key=value ...]
    navsim budget SCENARIO.toml --out DIR [--runs N] [--workers W]

Bad input ends with one line ``navsim: error: ...`` and exit status 2, never a traceback.
"""

import json
import sys
from pathlib import Path

from startrack.errors import ArgumentParser, InputError, run_command

# Each command imports what it needs when it runs, so ``navsim --help`` starts at once.


def _print_summary(summary, out):
    nees, updates = summary["nees"], summary["updates"]
    lines = _navigation_lines(summary) if summary.kind == "navigation" else _attitude_lines(summary)
    lines += [
        f"NEES                mean {nees['mean']:.2f} (dof {nees['dof']}), "
        f"{100 * nees['fraction_in_band']:.1f} % inside the 95 % band",
        f"updates             {updates['accepted']} accepted, {updates['rejected']} rejected",
        f"wall time           {summary['timing']['wall_seconds']:.2f} s",
        f"written to          {out}",
    ]
    print("\n".join(lines))


def _attitude_lines(summary):
    err = summary["attitude_error_rms_arcsec"]
    return [
        f"scenario            {summary['scenario']}  (seed {summary['seed']}, {summary['duration_s']:g} s, "
        f"{summary['fidelity']}/{summary['measurement']})",
        f"attitude RMS        x {err['x']:.2f}\"  y {err['y']:.2f}\"  z {err['z']:.2f}\"   "
        f"cross-boresight {summary['cross_boresight_rms_arcsec']:.2f}\"  roll {summary['roll_rms_arcsec']:.2f}\"",
        "final bias error    " + "  ".join(f"{v:+.4f}" for v in summary["bias_error_final_deg_per_h"]) + " deg/h",
    ]


def _navigation_lines(summary):
    nav, position = summary["navigation"], summary["position_error_m"]
    horizontal, vertical, nmi = position["horizontal"], position["vertical"], summary["position_error_nmi"]["horizontal"]
    velocity = summary["velocity_error_m_per_s"]
    return [
        f"scenario            {summary['scenario']}  (seed {summary['seed']}, {summary['duration_s']:g} s, INS at "
        f"{nav['imu_rate_hz']:g} Hz, aiding: {', '.join(nav['aiding']) or 'none (free INS)'})",
        f"horizontal error    final {horizontal['final']:.2f} m ({nmi['final']:.3f} nmi, {nmi['final_per_hour']:.3f} nmi/h)  "
        f"RMS {horizontal['rms']:.2f} m  max {horizontal['max']:.2f} m",
        f"vertical error      final {vertical['final']:.2f} m  RMS {vertical['rms']:.2f} m  max {vertical['max']:.2f} m",
        f"velocity error RMS  horizontal {velocity['horizontal']['rms']:.3f} m/s  vertical {velocity['vertical']['rms']:.3f} m/s",
        f"attitude error RMS  tilt {summary['tilt_error_arcsec']['rms']:.1f}\"  heading {summary['heading_error_arcsec']['rms']:.1f}\"",
        "final bias error    gyro " + "  ".join(f"{v:+.4f}" for v in summary["bias_error_final_deg_per_h"]) + " deg/h, "
        "accelerometer " + "  ".join(f"{v:+.1f}" for v in summary["accel_bias_error_final_micro_g"]) + " µg",
    ]


def _run(args):
    from navsim.output import write_run, write_study
    from navsim.places import check_output, publish
    from navsim.scenario import resolve_scenario
    from navsim.simulation import run, run_study
    from navsim.studies import STUDIES
    from startrack.paths import check_file

    _check_seed(args.seed)
    scenario = resolve_scenario(args.scenario, args.set or ())
    kind = "study" if scenario.is_study else "run"
    check_output(args.out, kind)
    if args.report:
        check_file(args.report, "--report", (".pdf",))
    if scenario.is_study:
        result = run_study(scenario, seed=args.seed, progress=True)
        out = publish(args.out, kind, lambda directory: write_study(directory, result))
        print(f"study               {scenario.name} ({scenario['study']['kind']}, seed {result.summary['seed']}, "
              f"{result.summary['wall_seconds']:.1f} s)")
        print("\n".join(STUDIES[scenario["study"]["kind"]].text(result.summary, scenario.study_parameters)))
        print(f"written to          {out}")
    else:
        result = run(scenario, seed=args.seed)
        out = publish(args.out, kind, lambda directory: write_run(directory, result))
        _print_summary(result.summary, out)
    if args.report is not None:
        from navsim.report import write_report

        pdf = write_report(out, args.report or Path(out) / "report.pdf")
        print(f"report              {pdf}")
    return 0


def _report(args):
    from navsim.report import write_report
    from startrack.paths import check_file

    check_file(args.output, "-o", (".pdf",))
    print(write_report(args.directory, args.output))
    return 0


def _check_seed(seed):
    if seed is not None and not 0 <= seed < 2**63:
        raise InputError(f"--seed {seed}: must be an integer from 0 to 2**63 - 1")


def _montecarlo(args):
    from navsim.campaign.montecarlo import run_campaign

    if args.workers is not None and args.scheduler is not None:
        raise InputError("give either --workers or --scheduler, not both")
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers must be at least 1, got {args.workers}")
    _check_seed(args.seed)
    summary = run_campaign(args.scenario, args.runs, args.out, base_seed=args.seed, overrides=args.set or (),
                           workers=args.workers, scheduler=args.scheduler, retry_failed=args.retry_failed)
    cross, roll, nees = summary.get("cross_boresight_rms_arcsec", {}), summary.get("roll_rms_arcsec", {}), summary.get("nees", {})
    print(f"campaign            {summary['scenario']}: {summary['runs_finished']} of {summary['runs_requested']} runs "
          f"finished, {summary['runs_failed']} failed")
    if summary["failures"]:
        first = summary["failures"][0]
        again = ("the same command runs them again" if first["cause"] == "environment"
                 else "add --retry-failed to run them again")
        print(f"first failure       run {first['run']}: {first['error']} (all in {args.out}/runs/*/error.json; "
              f"once the cause is fixed, {again})")
    if cross:
        print(f"cross-boresight RMS mean {cross['mean']:.2f}\"  p95 {cross['p95']:.2f}\"   roll RMS mean {roll['mean']:.2f}\"  p95 {roll['p95']:.2f}\"")
    if summary.get("position_error_m"):
        horizontal, nmi = summary["position_error_m"]["horizontal"], summary["position_error_nmi"]["horizontal"]
        print(f"final horizontal    CEP50 {horizontal['cep50']:.2f} m ({nmi['cep50']:.3f} nmi)  CEP95 {horizontal['cep95']:.2f} m "
              f"({nmi['cep95']:.3f} nmi)   vertical p95 {summary['position_error_m']['vertical']['p95']:.2f} m")
    accel = (summary.get("imu_calibration") or {}).get("accel_bias_micro_g")
    if accel:
        print(f"accelerometer bias  {100 * accel['within_3_sigma']:.1f} % of the final errors within 3σ "
              f"(normalised RMS {', '.join(f'{v:.2f}' for v in accel['normalised_error_rms'])})")
    if nees:
        print(f"NEES (run average)  {nees['mean']:.2f} for {nees['dof']} dof; {100 * nees['fraction_in_band']:.1f} % of frames "
              f"inside the 95 % band [{nees['band_95'][0]:.2f}, {nees['band_95'][1]:.2f}]")
    if summary.get("divergent_runs"):
        print(f"divergent runs      {summary['divergent_runs']}")
    print(f"written to          {args.out}")
    return 0 if summary["runs_failed"] == 0 else 1


def _tune(args):
    from navsim.campaign.tuning import tune

    _check_seed(args.seed)
    if args.runs < 1:
        raise InputError(f"--runs must be at least 1, got {args.runs}")
    if args.evaluations < 1:
        raise InputError(f"--evaluations must be at least 1, got {args.evaluations}")
    result = tune(args.scenario, runs=args.runs, seed=args.seed, overrides=args.set or (), evaluations=args.evaluations)
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
        return 0
    labels = list(result.steps[0].errors)
    print(f"{'step':>4} {'Q scale':>9} {'R scale':>9} {'NEES/dof':>9} {'NIS/dof':>8} " + " ".join(f"{label:>20}" for label in labels))
    for k, step in enumerate(result.steps):
        errors = " ".join(f"{f'{value:.2f} {unit}':>20}" for value, unit in step.errors.values())
        print(f"{k:>4} {step.process_noise_scale:9.3f} {step.measurement_noise_scale:9.3f} {step.nees_per_dof:9.3f} "
              f"{step.nis_per_dof:8.3f} {errors}")
    first, last = result.steps[0], result.steps[-1]
    print(f"before: NEES/dof {first.nees_per_dof:.2f}, NIS/dof {first.nis_per_dof:.2f}; "
          f"after: NEES/dof {last.nees_per_dof:.2f}, NIS/dof {last.nis_per_dof:.2f}")
    print(f"use: --set filter.process_noise_scale={last.process_noise_scale:.4g} "
          f"--set filter.measurement_noise_scale={last.measurement_noise_scale:.4g}")
    return 0


def _budget(args):
    from navsim.campaign.budget import run_budget, text
    from navsim.scenario import resolve_scenario

    _check_seed(args.seed)
    budget = run_budget(resolve_scenario(args.scenario, args.set or ()), args.out, runs=args.runs, workers=args.workers,
                        base_seed=args.seed)
    print("\n".join(text(budget)))
    print(f"written to          {Path(args.out) / 'budget.json'}, {Path(args.out) / 'budget.pdf'}")
    return 1 if any(row["status"] == "failed" for row in [*budget["parts"], budget["total"]]) else 0


def build_parser():
    parser = ArgumentParser(prog="navsim", description="INS / star-sensor navigation simulator.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    p = sub.add_parser("run", help="simulate one scenario (or run a static study) and write summary.json and "
                                   "timeseries.npz (study.npz)")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--seed", type=int, default=None, help="random seed (default: the scenario's)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a scenario value, e.g. --set gyro.rate_hz=200 (repeatable)")
    p.add_argument("--report", nargs="?", const="", default=None, metavar="FILE.pdf",
                   help="also write a PDF report (default file: DIR/report.pdf)")
    p.set_defaults(func=_run)
    p = sub.add_parser("report", help="typeset the PDF report of a run or Monte Carlo campaign directory")
    p.add_argument("directory", help="run directory (navsim run --out) or campaign directory (navsim montecarlo)")
    p.add_argument("-o", "--output", required=True, metavar="FILE.pdf", help="PDF file to write")
    p.set_defaults(func=_report)

    p = sub.add_parser("montecarlo", help="run (or resume) a seeded campaign of one scenario")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--runs", type=int, required=True, help="number of runs")
    p.add_argument("--out", required=True, help="campaign directory (finished runs there are kept)")
    p.add_argument("--seed", type=int, default=None, help="base seed (default: the scenario's)")
    p.add_argument("--workers", type=int, default=None, help="local processes (default: all cores)")
    p.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT", help="a Dask distributed scheduler")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario value (repeatable)")
    p.add_argument("--retry-failed", action="store_true",
                   help="run again the runs that failed for a cause in the scenario (runs that failed for a cause "
                        "outside it, such as a full disk, are always run again)")
    p.set_defaults(func=_montecarlo)

    p = sub.add_parser("tune", help="fit the filter's Q and R scale factors for NEES/NIS consistency")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--runs", type=int, default=20, help="seeded runs per iteration (default 20)")
    p.add_argument("--evaluations", type=int, default=30, help="most batches evaluated (default 30)")
    p.add_argument("--seed", type=int, default=None, help="first seed (default: the scenario's)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario value (repeatable)")
    p.add_argument("--json", action="store_true", help="print the iterations as JSON")
    p.set_defaults(func=_tune)

    p = sub.add_parser("budget", help="the error budget of a star-aided navigation scenario: the horizontal error each "
                                      "source leaves, from runs with one source at a time")
    p.add_argument("scenario", help="scenario TOML file (a navigation scenario with a [star_sensor])")
    p.add_argument("--out", required=True, help="budget directory (budget.json, budget.pdf, parts/; finished runs "
                                                "there are kept)")
    p.add_argument("--runs", type=int, default=5, help="runs per source (default 5)")
    p.add_argument("--workers", type=int, default=None, help="local processes (default: all cores)")
    p.add_argument("--seed", type=int, default=None, help="base seed (default: the scenario's)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario value (repeatable)")
    p.set_defaults(func=_budget)
    return parser


def main(argv=None) -> int:
    return run_command("navsim", build_parser, argv)


if __name__ == "__main__":
    sys.exit(main())
