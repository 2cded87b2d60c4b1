"""astrometry.net (the Debian package ``astrometry.net`` 0.93 with ``astrometry-data-tycho2-10-19``) on a
benchmark frame's centroids; runs in the project's venv (astropy reads the answer).

Each frame's centroids (brightest first) are written as an x-y list (a FITS table X, Y in FITS pixels,
u + 1 and v + 1, and FLUX) and solved by ``solve-field`` with the image size, the field width's range
(``--scale-units degwidth``), a CPU limit, and nothing else (its defaults: SIP order 2 tweak, its own
verification).  The answer's ``.wcs`` gives R_IC (the image-centre frame: +z the direction of the centre
pixel, +x along the image columns' tangent there) and the field of view (the angle between the left and
right edges' midpoints).  ``solve_ms`` is the wall time of the ``solve-field`` process (it includes the
process start and reading the index files: astrometry.net has no in-process solve to time alone).

Set-up: ``apt-get install astrometry.net astrometry-data-tycho2-10-19`` (index scales 10-19: quads of
1-33 deg, fields of ~2-100 deg).
"""

from __future__ import annotations

import math
import shutil
import subprocess
import time
import warnings
from pathlib import Path

import numpy as np

INDEX_DIR = Path("/usr/share/astrometry")


def unavailable():
    """None when solve-field and the Tycho-2 index files are installed, else why not."""
    if shutil.which("solve-field") is None:
        return "no solve-field: apt-get install astrometry.net"
    if not list(INDEX_DIR.glob("index-tycho2-1*.fits")):
        return f"no Tycho-2 index files in {INDEX_DIR}: apt-get install astrometry-data-tycho2-10-19"
    return None


def _write_xylist(path, centroids):
    from astropy.io import fits

    columns = [fits.Column(name="X", format="D", array=centroids[:, 0] + 1.0),
               fits.Column(name="Y", format="D", array=centroids[:, 1] + 1.0),
               fits.Column(name="FLUX", format="D", array=centroids[:, 2])]
    fits.BinTableHDU.from_columns(columns).writeto(path, overwrite=True)


def _direction(wcs, x, y):
    ra, dec = np.radians(wcs.all_pix2world([[x, y]], 1)[0])
    return np.array([math.cos(dec) * math.cos(ra), math.cos(dec) * math.sin(ra), math.sin(dec)])


def centre_frame(wcs, width, height):
    """(R_IC (3, 3), field of view across the width [deg]) of a FITS WCS."""
    xc, yc = (width + 1) / 2.0, (height + 1) / 2.0
    z = _direction(wcs, xc, yc)
    x = _direction(wcs, xc + 1.0, yc) - z
    x -= z * (x @ z)
    x /= np.linalg.norm(x)
    R = np.column_stack([x, np.cross(z, x), z])
    left, right = _direction(wcs, 0.5, yc), _direction(wcs, width + 0.5, yc)
    return R, math.degrees(math.acos(np.clip(left @ right, -1.0, 1.0)))


def solve(frame, work, fov_range_deg, cpulimit_s):
    """One result record (benchmarks/peers/runner_io.py's fields R_IC, fov_deg) of a frame's centroids."""
    from astropy.io import fits
    from astropy.wcs import WCS

    folder = Path(work) / frame["id"]
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    centroids = np.array(frame["centroids"], dtype=float).reshape(-1, 4)
    if len(centroids) == 0:
        return {"id": frame["id"], "status": "too_few", "solve_ms": 0.0}
    _write_xylist(folder / "xy.fits", centroids)
    command = ["solve-field", str(folder / "xy.fits"), "--width", str(frame["width"]), "--height", str(frame["height"]),
               "--x-column", "X", "--y-column", "Y", "--sort-column", "FLUX", "--scale-units", "degwidth",
               "--scale-low", str(fov_range_deg[0]), "--scale-high", str(fov_range_deg[1]), "--cpulimit",
               str(cpulimit_s), "--no-plots", "--overwrite", "--dir", str(folder), "--out", "solution",
               "--new-fits", "none", "--corr", "none", "--rdls", "none", "--match", "none", "--index-xyls", "none"]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True)
    ms = 1e3 * (time.perf_counter() - start)
    wcs_file = folder / "solution.wcs"
    if done.returncode != 0:
        return {"id": frame["id"], "status": "error", "solve_ms": ms, "reason": done.stderr.strip()[-200:]}
    if not wcs_file.is_file():
        return {"id": frame["id"], "status": "no_match", "solve_ms": ms}
    with fits.open(wcs_file) as hdus, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a header without data: "more axes than the image"
        R, fov = centre_frame(WCS(hdus[0].header), frame["width"], frame["height"])
    shutil.rmtree(folder, ignore_errors=True)
    return {"id": frame["id"], "status": "ok", "solve_ms": ms, "R_IC": R.tolist(), "fov_deg": fov}
