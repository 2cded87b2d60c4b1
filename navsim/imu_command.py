"""``navsim imu fit``: the Allan fit of a recorded static IMU log into a scenario's ``[imu]`` block
(:mod:`navsim.inertial_log`)."""

import json
import time
from pathlib import Path

# The fit's modules (numpy, scipy, numba) are imported when the command runs, so ``navsim --help`` starts at once.

#: A fit whose chi-square is this improbable is flagged.
MISFIT = 1e-3

DESCRIPTION = """The Allan fit of a static IMU log (IEEE Std 952 / 1554): the overlapping Allan deviation of each
axis with its 95 % chi-square interval, the noise terms Q, N, B, K, R fitted by generalised least squares with
their 1-sigma, and the [imu] block a scenario takes (the worst axis of each sensor).

The log: CSV/TXT (comma, semicolon, tab or blank separated; header lines skipped), .npy, .npz or .mat (one 2-D
array, one row a sample; --variable names it in an .npz/.mat holding several). --columns names each column in
order: t (time), gx gy gz (gyro), ax ay az (accelerometer), skip (not used); any subset of the axes. --units gives
each sensor's unit: gyro rad/s | deg/s | deg/h | rad | deg (the last two: angle increments per sample),
accel m/s^2 | g | mg | m/s (velocity increments per sample), time s | ms | us | ns.

It prints each axis's terms (SI) and the block; --out DIR writes DIR/imu.toml (the block: arw_deg_per_sqrt_h,
rrw_deg_per_h_per_sqrt_h, bias_instability_deg_per_h + bias_correlation_s, quantization_arcsec and the
accelerometer's vrw_m_per_s_per_sqrt_h, bias_rw_micro_g_per_sqrt_h, bias_instability_micro_g, quantization_m_per_s;
a term the log does not resolve is 0 with its upper bound in a comment, the rate ramp only in a comment) and
DIR/fit.json (the curves, bands, EDF, terms with their sigma; docs/design.md).

Example: navsim imu fit static.csv --columns t,gx,gy,gz,ax,ay,az --units gyro=deg/s,accel=g --out fit/ --plot allan.pdf
"""


def add_parser(sub):
    """The ``imu`` command (with its ``fit``) of ``sub`` (the navsim parser's subcommands)."""
    imu = sub.add_parser("imu", help="inertial sensors from recorded logs: `navsim imu fit LOG` (the Allan fit)")
    commands = imu.add_subparsers(dest="imu_command", metavar="ACTION", required=True)
    p = commands.add_parser("fit", help="the Allan fit of a static IMU log into a scenario [imu] block",
                            description=DESCRIPTION, formatter_class=_raw_formatter())
    p.add_argument("log", help="the log file (.csv, .txt, .dat, .npy, .npz, .mat)")
    p.add_argument("--columns", default="t,gx,gy,gz,ax,ay,az",
                   help="the meaning of each column in order (default t,gx,gy,gz,ax,ay,az)")
    p.add_argument("--units", default="", metavar="gyro=U,accel=U,time=U",
                   help="the columns' units (default gyro=rad/s,accel=m/s^2,time=s)")
    p.add_argument("--rate-hz", type=float, default=None, help="the sample rate (without a time column; with one, "
                                                                "a check of it)")
    p.add_argument("--variable", default=None, help="the array of an .npz or .mat file")
    p.add_argument("--out", default=None, metavar="DIR", help="write DIR/imu.toml (the block) and DIR/fit.json")
    p.add_argument("--plot", default=None, metavar="FILE", help="draw the curves, bands, fits and asymptotes "
                                                                 "(.pdf or .png)")
    p.set_defaults(func=run)


def _raw_formatter():
    import argparse

    return argparse.RawDescriptionHelpFormatter


def run(args):
    from navsim.inertial_log import axis_fit, plot, preset, reading
    from navsim.places import check_output, publish
    from startrack import check_file

    started = time.perf_counter()
    columns, unit_names = reading.parse_columns(args.columns), reading.parse_units(args.units)
    if args.plot:
        check_file(args.plot, "--plot", (".pdf", ".png"))
    if args.out:
        check_output(args.out, "imu-fit")
    log = reading.read_log(args.log, columns, unit_names, args.rate_hz, args.variable)
    fits = axis_fit.fit_axes(log)
    figures = preset.sensor_figures(fits)
    block = preset.imu_block(figures, log.rate_hz, Path(args.log).name)
    summary = preset.summary(log, fits, figures, args.log, block)
    if args.plot:
        plot.write_plot(args.plot, fits, f"{Path(args.log).name}: {log.samples} samples at {log.rate_hz:.6g} Hz")
    summary["timing"] = {"wall_seconds": time.perf_counter() - started}
    print("\n".join(_lines(log, fits)))
    print(block, end="")
    if args.out:
        publish(args.out, "imu-fit", lambda directory: _write(directory, block, summary))
        print(f"written to          {args.out}")
    if args.plot:
        print(f"plot                {args.plot}")
    return 0


def _write(directory, block, summary):
    (directory / "imu.toml").write_text(block, encoding="utf-8")
    (directory / "fit.json").write_text(json.dumps(summary, indent=1) + "\n", encoding="utf-8")


def _lines(log, fits):
    from scipy import stats

    duration = log.samples / log.rate_hz
    lines = [f"log                 {log.samples} samples at {log.rate_hz:.6g} Hz ({duration:.6g} s), {len(fits)} axes"]
    for name, axis in fits.items():
        terms = ", ".join(f"{term} {t.value:.4g} ± {t.sigma:.2g}" if t.resolved else f"{term} < {t.upper_bound:.3g}"
                          for term, t in axis.fit.terms.items())
        lines.append(f"{name:<4}(SI)           {terms}; chi-square {axis.fit.chi_square:.1f} for {axis.fit.fit_dof}")
        if stats.chi2.sf(axis.fit.chi_square, max(axis.fit.fit_dof, 1)) < MISFIT:
            lines.append(f"{name:<4}               the model does not fit this curve (chi-square probability below "
                         f"{MISFIT:g}): a noise outside IEEE 952's terms, e.g. a Gauss-Markov bias whose deviation "
                         "falls after its peak; read the plot before using its figures")
    return lines
