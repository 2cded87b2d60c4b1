"""FITS frames in and out (astropy.io.fits): the astronomers' images and the solution's WCS header.

Reading: the first HDU holding an image (or the HDU ``hdu``), its data scaled by BZERO/BSCALE as astropy
does (16-bit data with BZERO 32768 comes back as uint16), length-1 axes dropped; a cube is refused.  NaN
pixels are the frame's ``mask`` (no data: filled with the median of the others for the detection, and no
star is taken within :data:`MASK_MARGIN_PX` of them).  The full scale is SATURATE when the header gives it,
else the data's (:func:`startrack.image.files.full_scale`).  The observation's epoch is the middle of the
exposure: DATE-OBS (ISO 8601, UTC; else MJD-OBS) plus EXPTIME / 2, as a Julian year
2000 + (JD - 2451545.0) / 365.25 (UTC for TT: 69 s, nothing to a star's proper motion).

Writing never leaves half a file: the HDUs go to a temporary file beside the target, renamed over it.
"""

from __future__ import annotations

import datetime
import math
import re
import warnings
from pathlib import Path

import numpy as np

from startrack.base.errors import InputError
from startrack.base.output_paths import write_whole

FITS_SUFFIXES = (".fits", ".fit", ".fts")
#: File names read as FITS: those suffixes, gzipped, or tile-compressed (.fz, fpack).
_FITS_NAMES = FITS_SUFFIXES + tuple(s + ".gz" for s in FITS_SUFFIXES) + (".fz",)
#: Detections closer than this to a pixel without data are dropped [px] (a cut edge looks like a star).
MASK_MARGIN_PX = 3
#: J2000.0 as a Julian date, and the days of a Julian year.
JD_J2000, JULIAN_YEAR_DAYS = 2451545.0, 365.25
#: Header keywords of a celestial WCS (primary description), removed before a new one is written.
WCS_KEYWORDS = re.compile(r"^(WCSAXES|CTYPE\d|CUNIT\d|CRPIX\d|CRVAL\d|CDELT\d|CROTA\d|CD\d_\d|PC\d_\d|PV\d_\d+|"
                          r"PS\d_\d+|LONPOLE|LATPOLE|RADESYS|RADECSYS|EQUINOX|IMAGEW|IMAGEH|"
                          r"(A|B|AP|BP)_(ORDER|DMAX|\d+_\d+))$")


def is_fits(path):
    """True for a file name astropy reads as FITS (:data:`_FITS_NAMES`)."""
    return Path(path).name.lower().endswith(_FITS_NAMES)


def fits_stem(path):
    """The file name without its FITS suffixes ("m42.fits.gz", "m42.fits.fz" -> "m42")."""
    name = Path(path).name
    while is_fits(name):
        name = name[:-len(next(s for s in _FITS_NAMES if name.lower().endswith(s)))]
    return name


def read_fits(path, hdu=None):
    """(image (H, W), mask (H, W) bool or None, full scale or None, epoch [Julian year] or None, the HDU's
    index) of a FITS file (module text); one InputError naming the file and the problem otherwise."""
    from astropy.io import fits

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            with fits.open(path, memmap=False) as hdus:
                index = _image_hdu(path, hdus, hdu)
                header, data = hdus[index].header, np.asarray(hdus[index].data)
                epoch = _epoch(path, header)
                saturate = header.get("SATURATE")
    except InputError:
        raise
    except Exception as error:  # astropy raises OSError, ValueError, VerifyError, TypeError... for a bad file
        raise InputError(f"image file {path} is not a readable FITS file ({type(error).__name__}: {error})") from None
    if data.ndim > 2:
        data = data.reshape([n for n in data.shape if n != 1] or [1])
    if data.ndim != 2:
        raise InputError(f"image file {path}: HDU {index} holds a {data.ndim}-D array of shape {data.shape}; "
                         "expected a 2-D image")
    image, mask = _masked(path, data)
    scale = float(saturate) if isinstance(saturate, (int, float)) and saturate > 0 else None
    return image, mask, scale, epoch, index


def _image_hdu(path, hdus, hdu):
    """Index of the image HDU: ``hdu`` checked, else the first with image data."""
    if hdu is not None:
        if not 0 <= hdu < len(hdus):
            raise InputError(f"image file {path} has HDUs 0..{len(hdus) - 1}; --hdu {hdu} is not one")
        if not getattr(hdus[hdu], "is_image", False) or hdus[hdu].data is None:
            raise InputError(f"image file {path}: HDU {hdu} holds no image")
        return hdu
    for index, unit in enumerate(hdus):
        if getattr(unit, "is_image", False) and unit.data is not None and unit.data.ndim >= 2:
            return index
    raise InputError(f"image file {path} holds no image HDU (no HDU with 2-D image data)")


def _masked(path, data):
    """(image, mask or None): NaN/inf pixels masked and filled with the median of the finite ones."""
    if not np.issubdtype(data.dtype, np.floating):
        return data, None
    bad = ~np.isfinite(data)
    if not bad.any():
        return data, None
    if bad.all():
        raise InputError(f"image file {path} has no finite pixel (all NaN or infinite)")
    image = np.array(data, dtype=np.float64)
    image[bad] = np.median(image[~bad])
    return image, bad


def _epoch(path, header):
    """Julian year of the middle of the exposure, or None when the header gives no time (module text)."""
    start = None
    if "DATE-OBS" in header:
        text = str(header["DATE-OBS"]).strip()
        try:
            when = datetime.datetime.fromisoformat(text.rstrip("Z"))
        except ValueError:
            raise InputError(f"image file {path}: DATE-OBS = {text!r} is not an ISO 8601 date "
                             "(YYYY-MM-DD[Thh:mm:ss]); give --epoch") from None
        if when.tzinfo is not None:
            when = when.astimezone(datetime.timezone.utc).replace(tzinfo=None)
        days = (when - datetime.datetime(2000, 1, 1, 12)) / datetime.timedelta(days=1)
        start = JD_J2000 + days
    elif "MJD-OBS" in header:
        start = float(header["MJD-OBS"]) + 2400000.5
    if start is None:
        return None
    exposure = header.get("EXPTIME", header.get("EXPOSURE", 0.0))
    if not isinstance(exposure, (int, float)) or not math.isfinite(exposure) or exposure < 0:
        raise InputError(f"image file {path}: EXPTIME = {exposure!r} is not an exposure time in seconds")
    return 2000.0 + (start + 0.5 * exposure / 86400.0 - JD_J2000) / JULIAN_YEAR_DAYS


def write_hdus(path, hdus, what):
    """Write the astropy HDUList ``hdus`` to ``path`` whole or not at all
    (:func:`startrack.base.output_paths.write_whole`); ``what`` names the option in the message of a file that
    cannot be written."""
    write_whole(path, lambda temporary: hdus.writeto(temporary, overwrite=True, output_verify="silentfix"), what)
