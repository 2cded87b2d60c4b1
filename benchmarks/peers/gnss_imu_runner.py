"""Run the peer rtklibexplorer/GNSS_IMU (BSD-3-Clause, Tim Everett 2025; a loosely coupled GNSS/IMU filter after
Groves) on its own car drive with navsim's outages, in its own venv (numpy, scipy, matplotlib):

    python3 -m venv /tmp/peer && /tmp/peer/bin/pip install numpy scipy matplotlib
    /tmp/peer/bin/python benchmarks/peers/gnss_imu_runner.py PEER_SRC_DIR DATA_DIR WINDOWS_JSON OUT.pos [--zupt on|off]

Its scripts are run as they are, with only what a user edits changed: the data paths, plots off, velocity matching
off (it rewrites the coast after its end: not causal), ZUPT on (the peer's default) or off, and the coast flags set
to the given windows ([[start, end], ...] in GPST seconds since 1970) instead of its fixed 15 s pattern. Its IMU input
file is made first by its own ``convert_imu_file.py`` (which low-passes the log at 10 Hz, 5 Hz vertical, zero-phase).
Writes its solution (RTKLIB format, at the IMU's rate) to OUT.pos.
"""

import json
import os
import runpy
import shutil
import sys
from pathlib import Path


def _patched(source, replacements):
    for old, new in replacements:
        if old not in source:
            raise SystemExit(f"peer source changed: {old!r} not found")
        source = source.replace(old, new, 1)
    return source


def main(src, data, windows_file, out, zupt="on"):
    src, data = Path(src).resolve(), Path(data).resolve()
    work = Path(out).resolve().parent / "peer_work"
    shutil.rmtree(work, ignore_errors=True)
    shutil.copytree(src, work / "src")
    shutil.copytree(data, work / "data")
    os.environ["MPLBACKEND"] = "Agg"
    sys.path.insert(0, str(work / "src"))
    os.chdir(work / "src")
    imu = str(work / "data" / "imu_1934.csv")
    convert = _patched((work / "src" / "convert_imu_file.py").read_text(),
                       [("filepath = r'..\\data\\drive_0708\\imu_1934.csv'", f"filepath = {imu!r}")])
    (work / "src" / "convert_navsim.py").write_text(convert)
    runpy.run_path(str(work / "src" / "convert_navsim.py"), run_name="__main__")
    windows = json.loads(Path(windows_file).read_text())
    main_source = _patched((work / "src" / "GNSS_IMU.py").read_text(), [
        ("import drive_config as cfg\n", "import drive_config as cfg\ncfg.plot_results = cfg.plot_bias_data = False\n"
                                          f"cfg.vel_match = False\ncfg.zupt_enable = {zupt == 'on'}\n"),
        ("dataDir = r'..\\data\\drive_0708'", f"dataDir = {str(work / 'data')!r}"),
        ("# loop through forward and backward passes",
         "outp[:, 10, :] = 0\n"
         f"for _a, _b in {windows!r}:\n"
         "    outp[(in_imu[:num_epochs, 0] + cfg.imu_t_off >= _a) & (in_imu[:num_epochs, 0] + cfg.imu_t_off < _b), 10, :] = 1\n"
         "# loop through forward and backward passes"),
    ])
    script = work / "src" / "GNSS_IMU_navsim.py"
    script.write_text(main_source)
    with open(os.devnull, "w") as quiet:
        stdout, sys.stdout = sys.stdout, quiet
        try:
            runpy.run_path(str(script), run_name="__main__")
        finally:
            sys.stdout = stdout
    shutil.copy(work / "data" / "gnss_imu_1934_sf.pos", out)


if __name__ == "__main__":
    args = sys.argv[1:]
    zupt = "on"
    if "--zupt" in args:
        zupt = args[args.index("--zupt") + 1]
        args = args[:args.index("--zupt")]
    main(*args, zupt=zupt)
