"""``navsim`` command line (contract in DESIGN.md).

    navsim run SCENARIO.toml --out DIR [--seed N] [--set key=value ...]

Bad input ends with one line ``navsim: error: ...`` and exit status 2, never a traceback.
"""

import argparse
import sys

from navsim.output import write_run
from navsim.simulation import run
from startrack.errors import run_command


def _print_summary(summary, out):
    err = summary["attitude_error_rms_arcsec"]
    nees = summary["nees"]
    updates = summary["updates"]
    lines = [
        f"scenario            {summary['scenario']}  (seed {summary['seed']}, {summary['duration_s']:g} s, "
        f"{summary['fidelity']}/{summary['measurement']})",
        f"attitude RMS        x {err['x']:.2f}\"  y {err['y']:.2f}\"  z {err['z']:.2f}\"   "
        f"cross-boresight {summary['cross_boresight_rms_arcsec']:.2f}\"  roll {summary['roll_rms_arcsec']:.2f}\"",
        "final bias error    " + "  ".join(f"{v:+.4f}" for v in summary["bias_error_final_deg_per_h"]) + " deg/h",
        f"NEES                mean {nees['mean']:.2f} (dof {nees['dof']}), "
        f"{100 * nees['fraction_in_band']:.1f} % inside the 95 % band",
        f"updates             {updates['accepted']} accepted, {updates['rejected']} rejected",
        f"wall time           {summary['wall_seconds']:.2f} s",
        f"written to          {out}",
    ]
    print("\n".join(lines))


def _run(args):
    result = run(args.scenario, seed=args.seed, overrides=args.set or ())
    out = write_run(args.out, result)
    _print_summary(result.summary, out)
    return 0


def build_parser():
    parser = argparse.ArgumentParser(prog="navsim", description="INS / star-sensor navigation simulator.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    p = sub.add_parser("run", help="simulate one scenario and write summary.json and timeseries.npz")
    p.add_argument("scenario", help="scenario TOML file")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--seed", type=int, default=None, help="random seed (default: the scenario's)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a scenario value, e.g. --set gyro.rate_hz=200 (repeatable)")
    p.set_defaults(func=_run)
    return parser


def main(argv=None) -> int:
    return run_command("navsim", build_parser(), argv)


if __name__ == "__main__":
    sys.exit(main())
