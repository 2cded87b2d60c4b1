"""Run every benchmark script of benchmarks/ in turn (``make bench``); each writes benchmarks/results/<name>.json.

The scripts are the ``benchmarks/*.py`` files with a ``__main__`` block other than this one
(helper modules such as star_id_frames.py have none), found afresh on every run so a new
benchmark is picked up without editing this file.  Each runs in its own process from the
repository root with this interpreter; a script that fails is reported and the others still run.
The exit status is 1 when any script failed (a crash, not a slow result: benchmarks measure, they
never assert).  The star-identification peers need their virtualenvs first:
``sh benchmarks/peers/setup_venvs.sh`` (``make bench`` does it).

Run:  python benchmarks/run_all.py [--only star_id catalog_build ...]
"""

import argparse
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


def benchmark_scripts():
    """Names (without .py) of the runnable benchmark scripts in benchmarks/, alphabetical."""
    return sorted(
        path.stem for path in HERE.glob("*.py")
        if path.name != Path(__file__).name and 'if __name__ == "__main__":' in path.read_text()
    )


def main():
    scripts = benchmark_scripts()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="+", choices=scripts, help="run only these scripts")
    args = parser.parse_args()
    outcomes = []
    for name in args.only or scripts:
        print(f"=== benchmarks/{name}.py", flush=True)
        start = time.perf_counter()
        status = subprocess.run([sys.executable, str(HERE / f"{name}.py")], cwd=ROOT).returncode
        outcomes.append((name, status, time.perf_counter() - start))
    print("\n=== summary")
    for name, status, seconds in outcomes:
        print(f"  {name:<18} {'ok' if status == 0 else f'FAILED (exit {status})':<18} {seconds:8.1f} s")
    return 1 if any(status != 0 for _, status, _ in outcomes) else 0


if __name__ == "__main__":
    sys.exit(main())
