"""Output paths checked before any work is done: a file name that can be written, a directory that
can be created or written into. The check creates the directory and writes (and removes) a probe file
there, since permissions alone do not tell (a read-only or full file system, /proc, a superuser).
Each problem is one :class:`~startrack.base.errors.InputError` naming the option, the path and what is
wrong."""

import os
from pathlib import Path

from startrack.base.errors import InputError


def check_file(path, option, suffixes):
    """The file ``path`` (ending in one of ``suffixes``) can be written; its directory is created.
    Returns the Path."""
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise InputError(f"{option} {path}: the file name must end in {' or '.join(suffixes)}")
    if path.is_dir():
        raise InputError(f"{option} {path}: is a directory, not a file name")
    probe_directory(path.parent, option, path)
    return path


def check_directory(path, option):
    """The directory ``path`` exists or is created, and can be written into. Returns the Path."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(f"{option} {path}: is a file, not a directory")
    probe_directory(path, option, path)
    return path


def probe_directory(directory, option, named):
    """Create ``directory`` (and its parents) and write a file there; an InputError about ``named`` if not."""
    directory = Path(directory)
    blocking = next((p for p in (directory, *directory.parents) if p.exists() and not p.is_dir()), None)
    if blocking is not None:
        raise InputError(f"{option} {named}: {blocking} is a file, so nothing can be created under it")
    probe = directory / f".write-probe-{os.getpid()}"
    try:
        directory.mkdir(parents=True, exist_ok=True)
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as error:
        raise InputError(f"{option} {named}: cannot write in {directory} ({error.strerror or error})") from None


def write_whole(path, write, what):
    """Write ``path`` whole or not at all: ``write(temporary)`` writes a temporary file beside it, renamed over it;
    ``what`` names the option in the message of a file that cannot be written.  Returns the Path."""
    path = Path(path)
    temporary = path.with_name(f".{path.name}.{os.getpid()}.part")
    try:
        write(temporary)
        os.replace(temporary, path)
    except OSError as error:
        raise InputError(f"{what} {path} cannot be written ({error.strerror or error})") from None
    finally:
        if temporary.exists():
            temporary.unlink()
    return path
