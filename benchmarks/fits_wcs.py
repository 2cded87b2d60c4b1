"""startrack's FITS WCS (TAN-SIP, startrack.camera.wcs) read by astrometry.net's own tools, against the camera model.

For cameras from a pinhole to a 40 deg barrel lens and four attitudes (two at the celestial poles), the
solution's header is written as a ``.wcs`` file; astrometry.net's ``wcs-xy2rd`` maps 500 random pixels
to RA/Dec, compared with startrack's camera model (:meth:`startrack.camera.model.Camera.unproject`), and
``wcs-rd2xy`` maps those directions back to pixels.  astrometry.net comes from the Debian package
``astrometry.net`` (``apt-get install astrometry.net``); without it the script says so and writes nothing.
Measures, never asserts.

Run:  python benchmarks/fits_wcs.py        Writes benchmarks/results/fits_wcs.json.
"""

from __future__ import annotations

import datetime
import json
import math
import shutil
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np
from astropy.io import fits

from startrack.base.units import DEG
from startrack.camera.model import Camera
from startrack.camera.wcs import frame_wcs
from startrack.geometry.rotation import from_rotation_vector, to_matrix
from startrack.geometry.sphere import vector_to_radec

HERE = Path(__file__).resolve().parent
CAMERAS = {"pinhole 12 deg": (12.0, 0.0, 0.0), "pincushion 20 deg": (20.0, 0.05, 0.0),
           "barrel 20 deg": (20.0, -0.1, 0.01), "barrel 40 deg": (40.0, -0.2, 0.02)}
ATTITUDES = {"mid": [0.3, -1.1, 0.7], "north pole": [0.0, 0.0, 0.0], "south pole": [math.pi, 0.0, 0.0],
             "ra0": [1.5, 2.0, -0.2]}
POINTS = 500


def _table(path, names, columns):
    fits.BinTableHDU.from_columns([fits.Column(n, "D", array=c) for n, c in zip(names, columns)]).writeto(path)


def compare(work, fov_deg, k1, k2, rotation):
    """(SIP order, largest wcs-xy2rd miss of the camera model ["], largest wcs-rd2xy miss of the pixel [px])."""
    camera = Camera.from_fov(fov_deg * DEG, 1600, 1200, cx=810.3, cy=590.7, k1=k1, k2=k2)
    q = from_rotation_vector(np.array(rotation))
    solution = frame_wcs(camera, q)
    wcs = work / "frame.wcs"
    fits.PrimaryHDU(header=fits.Header(solution.cards())).writeto(wcs, overwrite=True)
    rng = np.random.default_rng(0)
    uv = np.stack([rng.uniform(-0.5, 1599.5, POINTS), rng.uniform(-0.5, 1199.5, POINTS)], axis=1)
    ra, dec = (np.degrees(a) for a in vector_to_radec(camera.unproject(uv) @ to_matrix(q).T))
    for name in ("xy.fits", "rd.fits", "rd_in.fits", "xy_out.fits"):
        (work / name).unlink(missing_ok=True)
    _table(work / "xy.fits", ("X", "Y"), (uv[:, 0] + 1.0, uv[:, 1] + 1.0))
    _table(work / "rd_in.fits", ("RA", "DEC"), (ra, dec))
    subprocess.run(["wcs-xy2rd", "-w", wcs, "-i", work / "xy.fits", "-o", work / "rd.fits"], check=True, capture_output=True)
    subprocess.run(["wcs-rd2xy", "-w", wcs, "-i", work / "rd_in.fits", "-o", work / "xy_out.fits"], check=True,
                   capture_output=True)
    rd, xy = fits.getdata(work / "rd.fits", 1), fits.getdata(work / "xy_out.fits", 1)
    miss = np.hypot(((rd["RA"] - ra + 180.0) % 360.0 - 180.0) * np.cos(np.radians(dec)), rd["DEC"] - dec) * 3600.0
    back = np.hypot(xy["X"] - (uv[:, 0] + 1.0), xy["Y"] - (uv[:, 1] + 1.0))
    return solution.order, float(miss.max()), float(back.max())


def main():
    if shutil.which("wcs-xy2rd") is None:
        print("astrometry.net's wcs-xy2rd is not installed (apt-get install astrometry.net): nothing measured")
        return 0
    warnings.simplefilter("ignore")  # astropy: a .wcs header has no image axes
    rows = []
    print(f"{'camera':<20} {'attitude':<11} {'SIP order':>9} {'xy2rd vs model [as]':>20} {'rd2xy back [px]':>16}")
    with tempfile.TemporaryDirectory() as folder:
        for name, (fov, k1, k2) in CAMERAS.items():
            for attitude, rotation in ATTITUDES.items():
                order, miss, back = compare(Path(folder), fov, k1, k2, rotation)
                rows.append({"camera": name, "k1": k1, "k2": k2, "attitude": attitude, "sip_order": order,
                             "xy2rd_max_arcsec": miss, "rd2xy_max_px": back})
                print(f"{name:<20} {attitude:<11} {order:>9} {miss:>20.5f} {back:>16.2e}")
    version = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "astrometry.net"], capture_output=True, text=True)
    out = {"benchmark": "startrack's TAN-SIP WCS read by astrometry.net's wcs-xy2rd / wcs-rd2xy (issue 32)",
           "utc": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
           "astrometry_net": version.stdout.strip() or None, "points": POINTS, "rows": rows}
    path = HERE / "results" / "fits_wcs.json"
    path.write_text(json.dumps(out, indent=1) + "\n")
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
