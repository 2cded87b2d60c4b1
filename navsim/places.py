"""Output directories: checked before any work, marked with what they hold, replaced whole, locked.

A directory that navsim writes carries ``navsim-output.json`` naming its kind (run, study,
campaign, budget, covariance, sweep, imu-fit or replay). Before a command starts working it checks its ``--out`` (:func:`check_output`): not a
file, not under a file, created and writable, and empty or holding an output of the same kind —
never another kind, never somebody else's files. A run or study is written into a sibling directory and swapped in
when complete (:func:`publish`), so nothing is half-written and no file of an earlier run survives.
A campaign directory is written run by run (:mod:`navsim.campaign.montecarlo`) under a lock
(:func:`campaign_lock`) so that two campaigns never share it.
"""

import contextlib
import json
import os
import shutil
from pathlib import Path

from startrack import InputError, probe_directory

MARKER = "navsim-output.json"
KINDS = ("run", "study", "campaign", "budget", "covariance", "sweep", "imu-fit", "replay")
#: Files that identify the kind of an output written before the marker existed.
_LEGACY = (("campaign", ("campaign.json",)), ("run", ("summary.json", "timeseries.npz")),
           ("study", ("summary.json", "study.npz")))


def output_kind(directory):
    """The kind of output ``directory`` holds ('run', 'study', 'campaign'), None when it is empty, or
    'foreign' when it holds files navsim did not write."""
    directory = Path(directory)
    marker = directory / MARKER
    if marker.is_file():
        try:
            kind = json.loads(marker.read_text(encoding="utf-8")).get("kind")
        except (OSError, ValueError, AttributeError):
            kind = None
        return kind if kind in KINDS else "foreign"
    for kind, files in _LEGACY:
        if all((directory / name).is_file() for name in files):
            return kind
    return "foreign" if any(directory.iterdir()) else None


def check_output(path, kind, option="--out"):
    """Raise an InputError now when ``path`` cannot receive an output of ``kind``; returns the Path."""
    path = Path(path)
    if path.exists():
        if not path.is_dir():
            raise InputError(f"{option} {path}: is a file, not a directory")
        held = output_kind(path)
        if held not in (None, kind):
            what = "files navsim did not write" if held == "foreign" else f"a {held} output"
            raise InputError(f"{option} {path}: holds {what}; give a new or empty directory for this {kind}")
    probe_directory(path, option, path)
    probe_directory(path.resolve().parent, option, path)  # a run or study is put in place from its parent
    return path


def publish(directory, kind, write):
    """Write an output of ``kind`` with ``write(temporary_directory)`` next to ``directory``, then put
    it in place of ``directory`` (an earlier output of the same kind is replaced whole). Returns the Path."""
    directory = check_output(directory, kind)
    final = directory.resolve()
    final.parent.mkdir(parents=True, exist_ok=True)
    staging = final.with_name(f".{final.name}.partial-{os.getpid()}")
    shutil.rmtree(staging, ignore_errors=True)
    try:
        staging.mkdir()
        write(staging)
        mark(staging, kind)
        retired = final.with_name(f".{final.name}.old-{os.getpid()}")
        if final.exists():
            os.replace(final, retired)
        os.replace(staging, final)
        shutil.rmtree(retired, ignore_errors=True)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return directory


def mark(directory, kind):
    """Write the marker naming what ``directory`` holds."""
    (Path(directory) / MARKER).write_text(json.dumps({"kind": kind}) + "\n", encoding="utf-8")


@contextlib.contextmanager
def campaign_lock(directory):
    """Hold ``directory/campaign.lock`` (this process id) while a campaign runs in it; a lock left by a
    process that no longer runs is taken over."""
    lock = Path(directory) / "campaign.lock"
    for _ in range(2):
        try:
            descriptor = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
            break
        except FileExistsError:
            holder = _lock_holder(lock)
            if holder is not None and _running(holder):
                raise InputError(f"{directory}: another campaign (process {holder}) is running in this directory; "
                                 "wait for it or use another --out") from None
            lock.unlink(missing_ok=True)
    else:
        raise InputError(f"{directory}: cannot take the campaign lock {lock}")
    try:
        os.write(descriptor, str(os.getpid()).encode())
        os.close(descriptor)
        yield
    finally:
        lock.unlink(missing_ok=True)


def _lock_holder(lock):
    try:
        return int(lock.read_text().strip())
    except (OSError, ValueError):
        return None


def _running(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True
