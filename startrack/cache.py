"""Where built tables are cached: never inside the installed package.

``$STARTRACK_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/startrack``, else
``~/.cache/startrack``.
"""

import os
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
