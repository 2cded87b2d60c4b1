"""Numba set-up for startrack and navsim: compiled kernels are cached under the user cache directory, in a
folder keyed by the sources they are compiled from.

Import ``njit`` from here (not from numba).  numba keys a cached kernel by its own source file only, so a
kernel that calls a kernel of another module would load stale machine code after that module changed.
The cache folder is therefore ``<cache>/numba/<key>``, the key a hash of every ``.py`` file of the
``startrack`` and ``navsim`` packages and of numba's and Python's versions: any edit of either package
starts a new folder (a kernel that cannot have changed is compiled again once).  ``$NUMBA_CACHE_DIR`` set
by the user replaces ``<cache>/numba``.  Folders of other keys unused for :data:`_PRUNE_DAYS` are removed.
"""

import functools
import hashlib
import os
import shutil
import sys
import time
from pathlib import Path

import numba

from startrack.base.cache_dir import cache_dir

#: Cache folders of other keys not used for this many days are removed.
_PRUNE_DAYS = 14
#: The packages whose sources key the cache (siblings of startrack in the installation).
_PACKAGES = ("startrack", "navsim")


def source_key(roots) -> str:
    """16 hex digits of the SHA-256 of the ``.py`` files under ``roots`` (relative paths and contents, sorted)
    with numba's and Python's versions."""
    digest = hashlib.sha256(f"numba {numba.__version__} python {sys.version}".encode())
    for root in roots:
        root = Path(root)
        for path in sorted(root.rglob("*.py")):
            digest.update(str(path.relative_to(root.parent)).encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:16]


def kernel_cache_dir() -> Path:
    """The cache folder of this installation's kernels (created, marked as used; stale siblings pruned).
    Its root goes to ``$NUMBA_CACHE_DIR`` for child processes, which so share the folder."""
    base = Path(os.environ.setdefault("NUMBA_CACHE_DIR", str(cache_dir() / "numba")))
    here = Path(__file__).resolve().parents[2]
    folder = base / source_key([here / name for name in _PACKAGES if (here / name).is_dir()])
    folder.mkdir(parents=True, exist_ok=True)
    os.utime(folder)
    _prune(base, folder)
    return folder


def _prune(base, keep):
    old = time.time() - _PRUNE_DAYS * 86400.0
    for folder in base.iterdir():
        if folder != keep and folder.is_dir() and len(folder.name) == 16 and folder.stat().st_mtime < old:
            shutil.rmtree(folder, ignore_errors=True)


_FOLDER = kernel_cache_dir()
# numba reads its NUMBA_* variables again at every compilation when they changed since it last read them,
# and would then put $NUMBA_CACHE_DIR, just set for the children, in place of the keyed folder: read now.
numba.config.reload_config()
numba.config.CACHE_DIR = str(_FOLDER)

#: ``@njit`` with on-disk caching; kernels are pure functions of arrays and scalars.
njit = functools.partial(numba.njit, cache=True, nogil=True)
