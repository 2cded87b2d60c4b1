"""``navsim`` command line (contract in docs/design.md).

    navsim run SCENARIO.toml --out DIR [--seed N] [--set key=value ...] [--report [FILE.pdf]]
    navsim report DIR -o FILE.pdf
    navsim montecarlo SCENARIO.toml --runs N --out DIR [--workers K | --scheduler tcp://HOST:PORT]
    navsim tune SCENARIO.toml [--runs N] [--set key=value ...]
    navsim budget SCENARIO.toml --out DIR [--method covariance [--compare MC_BUDGET_DIR] | --method montecarlo [--runs N] [--workers W]]
    navsim covariance SCENARIO.toml --out DIR [--set key=value ...] [--budget] [--compare CAMPAIGN_DIR] [--report [FILE.pdf]]
    navsim sweep SCENARIO.toml --vary KEY=V1,V2,... [--vary ...] --metric NAME[@TIME] --out DIR [--requirement VALUE]
                 [--method covariance | --method montecarlo --runs N] [--workers K | --scheduler tcp://HOST:PORT]
    navsim sky SCENARIO.toml [--set key=value ...] [--report FILE.pdf]
    navsim imu fit LOG [--columns t,gx,gy,gz,ax,ay,az] [--units gyro=U,accel=U,time=U] [--rate-hz F] [--variable NAME]
                   [--out DIR] [--plot FILE.pdf|.png]
    navsim replay REPLAY.toml --out DIR [--set key=value ...] [--report [FILE.pdf]]

Bad input ends with one line ``navsim: error: ...`` and exit status 2, never a traceback.
"""

import json
import sys
from pathlib import Path

from navsim.places import check_output, publish
from startrack import ArgumentParser, InputError, run_command

# Each command imports what it needs when it runs, so ``navsim --help`` starts at once.


def _print_summary(kind, summary, out):
    nees, updates = summary["nees"], summary["updates"]
    lines = kind.run_lines(summary) + [
        f"NEES                mean {nees['mean']:.2f} (dof {nees['dof']}), "
        f"{100 * nees['fraction_in_band']:.1f} % inside the 95 % band",
        f"updates             {updates['accepted']} accepted, {updates['rejected']} rejected",
        f"wall time           {summary['timing']['wall_seconds']:.2f} s",
        f"written to          {out}",
    ]
    print("\n".join(lines))


def _run(args):
    from navsim.kinds import STUDY, resolve_scenario
    from startrack import check_file

    _check_seed(args.seed)
    scenario = resolve_scenario(args.scenario, args.set or ())
    output = "study" if scenario.kind == STUDY else "run"
    check_output(args.out, output)
    if args.report:
        check_file(args.report, "--report", (".pdf",))
    out = _run_study(scenario, args) if scenario.kind == STUDY else _run_simulation(scenario, args)
    if args.report is not None:
        from navsim.report import write_report

        pdf = write_report(out, args.report or Path(out) / "report.pdf")
        print(f"report              {pdf}")
    return 0


def _run_study(scenario, args):
    from navsim import studies
    from navsim.output import write_study
    from navsim.simulation import run_study

    result = run_study(scenario, seed=args.seed, progress=True)
    out = publish(args.out, "study", lambda directory: write_study(directory, result))
    print(f"study               {scenario.name} ({scenario['study']['kind']}, seed {result.summary['seed']}, "
          f"{result.summary['wall_seconds']:.1f} s)")
    print("\n".join(studies.STUDIES[scenario["study"]["kind"]].text(result.summary, studies.parameters(scenario))))
    print(f"written to          {out}")
    return out


def _run_simulation(scenario, args):
    from navsim.kinds import run_kind
    from navsim.output import write_run
    from navsim.simulation import run

    result = run(scenario, seed=args.seed)
    out = publish(args.out, "run", lambda directory: write_run(directory, result))
    _print_summary(run_kind(scenario, "a simulation run"), result.summary, out)
    return out


def _report(args):
    from navsim.report import write_report
    from startrack import check_file

    check_file(args.output, "-o", (".pdf",))
    print(write_report(args.directory, args.output))
    return 0


def _check_seed(seed):
    if seed is not None and not 0 <= seed < 2**63:
        raise InputError(f"--seed {seed}: must be an integer from 0 to 2**63 - 1")


def _montecarlo(args):
    from navsim.campaign.montecarlo import run_campaign
    from navsim.kinds import resolve_scenario, run_kind

    if args.workers is not None and args.scheduler is not None:
        raise InputError("give either --workers or --scheduler, not both")
    if args.workers is not None and args.workers < 1:
        raise InputError(f"--workers must be at least 1, got {args.workers}")
    _check_seed(args.seed)
    scenario = resolve_scenario(args.scenario, args.set or ())
    kind = run_kind(scenario, "a Monte Carlo campaign")
    summary = run_campaign(scenario, args.runs, args.out, base_seed=args.seed, workers=args.workers,
                           scheduler=args.scheduler, retry_failed=args.retry_failed)
    nees = summary.get("nees", {})
    print(f"campaign            {summary['scenario']}: {summary['runs_finished']} of {summary['runs_requested']} runs "
          f"finished, {summary['runs_failed']} failed")
    if summary["failures"]:
        first = summary["failures"][0]
        again = ("the same command runs them again" if first["cause"] == "environment"
                 else "add --retry-failed to run them again")
        print(f"first failure       run {first['run']}: {first['error']} (all in {args.out}/runs/*/error.json; "
              f"once the cause is fixed, {again})")
    for line in kind.campaign_lines(summary):
        print(line)
    if nees:
        from navsim.estimation.intervals import interval_text

        print(f"NEES (run average)  {nees['mean']:.2f} for {nees['dof']} dof, 95 % interval of the mean "
              f"{interval_text(nees['mean_interval_95'])} over {nees['runs']} runs; {100 * nees['fraction_in_band']:.1f} % "
              f"of frames inside the 95 % band [{nees['band_95'][0]:.2f}, {nees['band_95'][1]:.2f}]")
    if summary.get("divergent_runs"):
        print(f"divergent runs      {summary['divergent_runs']}")
    print(f"written to          {args.out}")
    return 0 if summary["runs_failed"] == 0 else 1


def _tune(args):
    from tqdm import tqdm

    from navsim.campaign.tuning import tune

    _check_seed(args.seed)
    if args.evaluations < 1:
        raise InputError(f"--evaluations must be at least 1, got {args.evaluations}")
    with tqdm(total=args.runs, desc="evaluation 0", unit="run", leave=False, disable=True if args.quiet else None) as bar:
        def on_step(k, step):
            bar.clear()
            if not args.json:
                print("\n".join(_tune_rows(k, step)), flush=True)
            bar.reset()
            bar.set_description(f"evaluation {k + 1}")

        result = tune(args.scenario, runs=args.runs, seed=args.seed, overrides=args.set or (),
                      evaluations=args.evaluations, on_step=on_step, on_run=bar.update)
    if args.json:
        print(json.dumps(result.as_dict(), indent=2))
        return 0
    first, last = result.steps[0], result.steps[-1]
    if not result.change_proposed:
        print(f"{_consistency(first)}: {first.runs} runs cannot tell these from 1; no change proposed")
        return 0
    print(f"before: {_consistency(first)} ({first.runs} runs)")
    still = "" if last.consistent else "; 1 still outside: more --evaluations or --runs"
    print(f"after (step {result.steps.index(last)}): {_consistency(last)}{still}")
    print(f"use: --set filter.process_noise_scale={last.process_noise_scale:.4g} "
          f"--set filter.measurement_noise_scale={last.measurement_noise_scale:.4g}")
    return 0


def _tune_rows(k, step):
    """The lines of `navsim tune`'s table for evaluation ``k``: the header first."""
    header = ([f"{'step':>4} {'Q scale':>9} {'R scale':>9} {'NEES/dof':>9} {'NIS/dof':>8} "
               + " ".join(f"{label:>20}" for label in step.errors)] if k == 0 else [])
    errors = " ".join(f"{f'{value:.2f} {unit}':>20}" for value, unit in step.errors.values())
    return header + [f"{k:>4} {step.process_noise_scale:9.3f} {step.measurement_noise_scale:9.3f} "
                     f"{step.nees_per_dof:9.3f} {step.nis_per_dof:8.3f} {errors}"]


def _consistency(step):
    """"NEES/dof 0.94, 95 % interval [0.82, 1.05]; NIS/dof ..." of a tuning step."""
    from navsim.estimation.intervals import interval_text

    return (f"NEES/dof {step.nees_per_dof:.2f}, 95 % interval {interval_text(step.nees_interval)}; "
            f"NIS/dof {step.nis_per_dof:.2f}, 95 % interval {interval_text(step.nis_interval)}")


def _budget(args):
    from navsim.analysis import budget_text
    from navsim.campaign.budget import run_budget
    from navsim.kinds import resolve_scenario, run_kind
    from navsim.report import write_report

    _check_seed(args.seed)
    scenario = resolve_scenario(args.scenario, args.set or ())
    budget = run_budget(scenario, args.out, runs=args.runs, workers=args.workers, base_seed=args.seed, method=args.method,
                        compare=args.compare)
    write_report(args.out, Path(args.out) / "budget.pdf")
    text = budget_text if args.method == "covariance" else run_kind(scenario, "an error budget").budget_text
    print("\n".join(text(budget)))
    for part in budget.get("comparison", {}).values():
        print(f"Monte Carlo         {part['label']}: {part['runs']} runs, {part['inside']} of {part['checks']} RMS values "
              f"inside their 95 % band, {part['inside_family']} inside the family-wise band")
    print(f"written to          {Path(args.out) / 'budget.json'}, {Path(args.out) / 'budget.pdf'}")
    if args.method == "covariance":
        return 0
    return 1 if any(row["status"] == "failed" for row in [*budget["parts"], budget["total"]]) else 0


def _covariance(args):
    from navsim.analysis import lines
    from navsim.campaign.montecarlo import finished_series
    from navsim.kinds import resolve_scenario, run_kind
    from navsim.output import write_covariance
    from navsim.simulation import covariance
    from startrack import check_file

    scenario = resolve_scenario(args.scenario, args.set or ())
    run_kind(scenario, "a covariance analysis")  # a static study has none: one clear line now
    runs = finished_series(args.compare, scenario) if args.compare else None
    if args.report:
        check_file(args.report, "--report", (".pdf",))
    check_output(args.out, "covariance")
    analysis = covariance(scenario, split=args.budget)
    comparison = analysis.compare(runs) if runs else None
    out = publish(args.out, "covariance", lambda directory: write_covariance(directory, scenario, analysis, comparison))
    print("\n".join(lines(analysis.summary(scenario))))
    if comparison is not None:
        print(f"Monte Carlo         {comparison['runs']} runs: {comparison['inside']} of {comparison['checks']} RMS values inside "
              f"their 95 % band, {comparison['inside_family']} inside the family-wise band")
    print(f"wall time           {analysis.wall_seconds:.2f} s")
    print(f"written to          {out}")
    if args.report is not None:
        from navsim.report import write_report

        print(f"report              {write_report(out, args.report or Path(out) / 'report.pdf')}")
    return 0


def _sky(args):
    from navsim.kinds import resolve_scenario, run_kind
    from startrack import check_file

    scenario = resolve_scenario(args.scenario, args.set or ())
    if args.report:
        check_file(args.report, "--report", (".pdf",))
    availability = run_kind(scenario, "a star availability").star_availability(scenario)
    print("\n".join(availability.lines()))
    if args.report:
        from navsim.report.sky import sky_report

        Path(args.report).write_bytes(sky_report(availability))
        print(f"report              {args.report}")
    return 0


def _replay(args):
    from navsim.replay import output, summary

    from startrack import check_file

    check_output(args.out, "replay")
    if args.report:
        check_file(args.report, "--report", (".pdf",))
    data, result, series = output.replay(args.replay, args.set or ())
    out = publish(args.out, "replay", lambda directory: output.write(directory, data, result, series))
    print("\n".join(summary.lines(result) + [f"written to          {out}"]))
    if args.report is not None:
        from navsim.report import write_report

        print(f"report              {write_report(out, args.report or Path(out) / 'report.pdf')}")
    return 0


def _sweep(args):
    from navsim.campaign.sweep import parse_vary, run_sweep
    from navsim.report import write_report

    if args.workers is not None and args.scheduler is not None:
        raise InputError("give either --workers or --scheduler, not both")
    result = run_sweep(args.scenario, [parse_vary(v) for v in args.vary], args.metric, args.out, method=args.method,
                       runs=args.runs, requirement=args.requirement, workers=args.workers, scheduler=args.scheduler,
                       overrides=args.set or ())
    pdf = write_report(args.out, Path(args.out) / "sweep.pdf")
    unit, requirement = result["unit"], result["requirement"]
    keys = [key for key, _ in result["vary"]]
    print(" ".join(f"{key:>24}" for key in keys) + f" {result['metric'] + ' [' + unit + ']':>28}")
    for point in result["points"]:
        meets = "" if requirement is None else ("  meets" if point["value"] <= requirement else "  fails")
        print(" ".join(f"{str(v):>24}" for v in point["values"]) + f" {point['value']:28.4g}{meets}")
    print(f"written to          {Path(args.out) / 'sweep.json'}, {Path(args.out) / 'sweep.csv'}, {pdf}")
    return 0


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

    p = sub.add_parser("tune", help="fit the filter's Q and R scale factors for NEES/NIS consistency (no change when "
                                    "the runs cannot tell the scenario's filter from a consistent one)")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--runs", type=int, default=20, help="seeded runs per evaluation, at least 2 (default 20)")
    p.add_argument("--evaluations", type=int, default=30, help="most batches evaluated (default 30)")
    p.add_argument("--seed", type=int, default=None, help="first seed (default: the scenario's)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario value (repeatable)")
    p.add_argument("--json", action="store_true", help="print the evaluations as JSON at the end (no table)")
    p.add_argument("--quiet", action="store_true", help="no progress line on stderr")
    p.set_defaults(func=_tune)

    p = sub.add_parser("budget", help="the error budget of a navigation scenario: what each error source leaves, by "
                                      "linear covariance analysis (default) or by runs with one source at a time")
    p.add_argument("scenario", help="scenario TOML file (a navigation scenario; --method montecarlo: with a [star_sensor])")
    p.add_argument("--out", required=True, help="budget directory (budget.json, budget.pdf; Monte Carlo: parts/, finished "
                                                "runs there are kept)")
    p.add_argument("--method", default="covariance", help="covariance (default: one pass, no draws) or montecarlo")
    p.add_argument("--runs", type=int, default=None, help="Monte Carlo runs per source (default 5)")
    p.add_argument("--workers", type=int, default=None, help="Monte Carlo local processes (default: all cores)")
    p.add_argument("--seed", type=int, default=None, help="Monte Carlo base seed (default: the scenario's)")
    p.add_argument("--compare", default=None, metavar="BUDGET_DIR", help="check the covariance budget part by part "
                   "against a Monte Carlo budget of the same scenario (navsim budget --method montecarlo --out)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario value (repeatable)")
    p.set_defaults(func=_budget)
    _add_sizing_commands(sub)

    p = sub.add_parser("sky", help="the stars the star sensor sees along a navigation scenario's trajectory (the Sun, "
                                   "the Moon, the sky's brightness, the limiting magnitude), without running the filter")
    p.add_argument("scenario", help="scenario TOML file (a navigation scenario with a [star_sensor])")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario value (repeatable)")
    p.add_argument("--report", default=None, metavar="FILE.pdf", help="also typeset the availability as a PDF")
    p.set_defaults(func=_sky)
    _add_imu_command(sub)

    p = sub.add_parser("replay", help="a recorded IMU through the strapdown INS and the navigation filter, aided by its "
                                      "GNSS fixes outside simulated outages; the error against the fixes held out")
    p.add_argument("replay", help="replay TOML file (a [replay] table)")
    p.add_argument("--out", required=True, help="output directory (summary.json, timeseries.npz)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a replay value (repeatable)")
    p.add_argument("--report", nargs="?", const="", default=None, metavar="FILE.pdf",
                   help="also write a PDF report (default file: DIR/report.pdf)")
    p.set_defaults(func=_replay)
    return parser


def _add_imu_command(sub):
    """``navsim imu fit`` (:mod:`navsim.imu_command`, imported when it runs)."""
    from navsim import imu_command

    imu_command.add_parser(sub)


def _add_sizing_commands(sub):
    """The ``covariance`` and ``sweep`` commands of ``sub`` (the parser's subcommands)."""
    p = sub.add_parser("covariance", help="linear covariance analysis: the true RMS of every error along the scenario's "
                                          "nominal trajectory in one pass, the filter's own sigma beside it")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--out", required=True, help="output directory (summary.json, timeseries.npz)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario value (repeatable)")
    p.add_argument("--budget", action="store_true", help="also split the errors by source (the error budget)")
    p.add_argument("--compare", metavar="CAMPAIGN_DIR", default=None,
                   help="check the analysis against a Monte Carlo campaign of the same scenario (comparison.json)")
    p.add_argument("--report", nargs="?", const="", default=None, metavar="FILE.pdf",
                   help="also write a PDF report (default file: DIR/report.pdf)")
    p.set_defaults(func=_covariance)

    p = sub.add_parser("sweep", help="a trade sweep: one metric over a grid of scenario keys, by covariance analysis "
                                     "(default) or Monte Carlo, with its requirement chart")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--vary", action="append", required=True, metavar="KEY=V1,V2,...",
                   help="a scenario key and its values (repeatable: the grid is every combination)")
    p.add_argument("--metric", required=True, metavar="NAME[@TIME]",
                   help="a summary quantity (e.g. horizontal_position), at a time (e.g. @4h, @1800 s; default: the end)")
    p.add_argument("--out", required=True, help="sweep directory (sweep.json, sweep.csv, sweep.pdf, points/; finished "
                                                "points there are kept)")
    p.add_argument("--requirement", type=float, default=None, help="the metric's requirement, drawn on the chart")
    p.add_argument("--method", default="covariance", help="covariance (default) or montecarlo")
    p.add_argument("--runs", type=int, default=None, help="Monte Carlo runs per point")
    p.add_argument("--workers", type=int, default=None, help="local processes (default: all cores)")
    p.add_argument("--scheduler", default=None, metavar="tcp://HOST:PORT", help="a Dask distributed scheduler")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a scenario value (repeatable)")
    p.set_defaults(func=_sweep)


def main(argv=None) -> int:
    return run_command("navsim", build_parser, argv)


if __name__ == "__main__":
    sys.exit(main())
