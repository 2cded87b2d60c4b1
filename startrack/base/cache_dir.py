"""Where built tables are cached: never inside the installed package.

``$STARTRACK_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/startrack``, else
``~/.cache/startrack``. Processes that fill the cache at once (the workers of a campaign, a parallel
test suite) each write their own temporary and rename it into place (:func:`publish_file`,
:func:`publish_folder`): a reader sees a whole table or none.
"""

import os
import shutil
import uuid
from pathlib import Path


def cache_dir() -> Path:
    """Return the cache directory, creating it if needed."""
    explicit = os.environ.get("STARTRACK_CACHE_DIR")
    if explicit:
        path = Path(explicit)
    else:
        base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
        path = Path(base) / "startrack"
    path.mkdir(parents=True, exist_ok=True)
    return path


#: How many times :func:`publish_folder` renames its folder into place while other writers do the same.
_PUBLISH_ATTEMPTS = 100


def _temporary(path: Path) -> Path:
    """A name beside ``path`` that no other writer uses (hidden, same suffix: ``np.savez`` keeps it)."""
    return path.with_name(f".{path.stem}.{os.getpid()}-{uuid.uuid4().hex[:8]}.tmp{path.suffix}")


def publish_file(path, write) -> Path:
    """Write the file ``path`` by ``write(temporary)`` and an atomic rename over it; returns ``path``."""
    path = Path(path)
    temporary = _temporary(path)
    try:
        write(temporary)
        os.replace(temporary, path)
    finally:
        temporary.unlink(missing_ok=True)
    return path


def publish_folder(folder, write) -> Path:
    """Write the folder ``folder`` by ``write(temporary)`` (an empty folder) and a rename in place of the old
    one (moved aside first, then deleted); when another writer's rename wins, theirs stays (the same table).
    Returns ``folder``."""
    folder = Path(folder)
    temporary = _temporary(folder)
    temporary.mkdir(parents=True)
    try:
        write(temporary)
        for _ in range(_PUBLISH_ATTEMPTS):
            _discard(folder)
            try:
                os.replace(temporary, folder)
                return folder
            except OSError:
                if folder.is_dir():
                    return folder
        raise OSError(f"{folder}: could not be replaced ({_PUBLISH_ATTEMPTS} attempts against other writers)")
    finally:
        shutil.rmtree(temporary, ignore_errors=True)


def _discard(folder):
    """Move ``folder`` aside (one atomic rename: a reader sees it whole or not at all) and delete it."""
    aside = _temporary(folder)
    try:
        os.replace(folder, aside)
    except FileNotFoundError:
        return
    shutil.rmtree(aside, ignore_errors=True)
