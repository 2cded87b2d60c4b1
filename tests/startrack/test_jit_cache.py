"""Compiled kernels cannot load stale machine code: the cache folder is keyed by every source file of
startrack and navsim (``startrack.compiled.numba_setup``), so editing a module a kernel calls -- which numba's own per-file
cache key misses -- compiles that kernel again."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import startrack
from startrack.compiled.numba_setup import source_key

PACKAGE = Path(startrack.__file__).resolve().parent
CALLEE = "from startrack.compiled.numba_setup import njit\n\n\n@njit\ndef value():\n    return {}\n"
CALLER = "from startrack._probe_callee import value\nfrom startrack.compiled.numba_setup import njit\n\n\n@njit\ndef twice():\n    return 2.0 * value()\n"


def test_the_key_follows_every_source_file(tmp_path):
    root = tmp_path / "pkg"
    (root / "sub").mkdir(parents=True)
    (root / "a.py").write_text("x = 1\n")
    (root / "sub" / "b.py").write_text("y = 2\n")
    first = source_key([root])
    assert source_key([root]) == first  # the same sources, the same folder
    (root / "sub" / "b.py").write_text("y = 3\n")
    edited = source_key([root])
    (root / "sub" / "c.py").write_text("")
    assert len({first, edited, source_key([root])}) == 3


def test_editing_a_called_module_recompiles_its_caller(tmp_path):
    top = tmp_path / "site"
    shutil.copytree(PACKAGE, top / "startrack", ignore=shutil.ignore_patterns("__pycache__"))
    (top / "startrack" / "_probe_callee.py").write_text(CALLEE.format("1.0"))
    (top / "startrack" / "_probe_caller.py").write_text(CALLER)
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(PYTHONPATH=str(top), STARTRACK_CACHE_DIR=str(tmp_path / "cache"))

    def run():
        code = "from startrack._probe_caller import twice; print(twice())"
        done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, cwd=tmp_path)
        assert done.returncode == 0, done.stderr
        return float(done.stdout)

    assert run() == 2.0
    assert run() == 2.0  # loaded from the cache
    (top / "startrack" / "_probe_callee.py").write_text(CALLEE.format("5.0"))  # the caller's file is untouched
    assert run() == 10.0
    assert len(list((tmp_path / "cache" / "numba").iterdir())) == 2


def test_kernels_defined_after_a_compilation_still_go_to_the_keyed_folder(tmp_path):
    """numba re-reads its environment at a compilation; the folder must survive it (set with no
    ``$NUMBA_CACHE_DIR`` given, as on a newcomer's machine)."""
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(STARTRACK_CACHE_DIR=str(tmp_path / "cache"))
    script = tmp_path / "probe.py"
    script.write_text("import numba\nfrom startrack.compiled.numba_setup import njit, kernel_cache_dir\n\n\n@njit\ndef first():\n"
                      "    return 1.0\n\n\nfirst()\n\n\ndef second():\n    return 2.0\n\n\nsecond = njit(second)\n"
                      "second()\nprint(numba.config.CACHE_DIR == str(kernel_cache_dir()), len(list(kernel_cache_dir().rglob('*.nbi'))))\n")
    done = subprocess.run([sys.executable, str(script)], env=env, capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["True", "2"]  # both kernels' indexes in the keyed folder
