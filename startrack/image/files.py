"""Read and write star-sensor frames: PNG/TIFF/JPEG (pillow), FITS (:mod:`startrack.image.fits`) and NumPy .npy.
Pictures are written as 16-bit PNG, or as 8-bit PNG or JPEG of levels stretched from the counts
(:func:`stretch_to_8_bit`).

Frames are 2-D arrays [DN].  Integer greyscale images come back as uint16 (8-bit files are widened),
floating ones as float64.  Colour images (RGB, RGBA, palette, CMYK, YCbCr: colour JPEGs from ordinary
cameras) are converted to their luminance Y = 0.299 R + 0.587 G + 0.114 B (ITU-R BT.601, the weights
of pillow's own "L" conversion) in float64, without rounding to 8 bits.  A .npy file must hold a 2-D
array.

:func:`read_frame` also gives the full scale of the data, from the file's bit depth: 255 for 8-bit
files (colour included); for 16-bit files the smallest of 2^8, 2^10, 2^12, 2^14, 2^16 above the
largest value, less the step of the data -- 12-bit data scaled by 16 (every value but a clipped
65535 a multiple of 16) saturates at 65520, not at each of its values; none for floating data.
A pixel at or above the full scale is saturated (:func:`startrack.image.detection.detect`).  A FITS frame may
also bring a mask of pixels without data and the epoch of its observation.
"""

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from PIL import Image, UnidentifiedImageError

from startrack.base.errors import InputError
from startrack.image.fits import FITS_SUFFIXES, is_fits

IMAGE_SUFFIXES = (".png", ".tif", ".tiff", ".jpg", ".jpeg", ".npy") + FITS_SUFFIXES
#: Greyscale pillow modes read as they are.
_GREY_MODES = ("L", "I;16", "I;16B", "I;16L", "I", "F", "1")
#: The picture files written (PNG, JPEG) and the JPEG quality (pillow's scale, 1-95).
_PICTURES = (".png", ".jpg", ".jpeg")
JPEG_QUALITY = 90
#: ITU-R BT.601 luma weights of R, G, B.
_LUMA_WEIGHTS = np.array([0.299, 0.587, 0.114])


@dataclass(frozen=True)
class Frame:
    """A frame read from a file: ``image`` (H, W) [DN] and its ``full_scale`` [DN] (None: unknown); ``mask``
    (H, W) True where the file has no data (None: none), ``epoch`` of the observation [Julian year] or None,
    ``hdu`` the index of a FITS file's HDU read (None: not FITS)."""

    image: np.ndarray
    full_scale: float | None
    mask: np.ndarray | None = None
    epoch: float | None = None
    hdu: int | None = None


def read_image(path):
    """2-D frame from a PNG, TIFF, JPEG, FITS or .npy file (uint16 for integer data, float64 otherwise)."""
    return read_frame(path).image


def read_frame(path, hdu=None) -> Frame:
    """The :class:`Frame` of a PNG, TIFF, JPEG, FITS (its first image HDU, or ``hdu``) or .npy file (module
    text)."""
    path = Path(path)
    if path.is_dir():
        raise InputError(f"image file {path} is a directory")
    if not path.is_file():
        raise InputError(f"image file {path} does not exist")
    suffix = path.suffix.lower()
    if suffix not in IMAGE_SUFFIXES and not is_fits(path):
        raise InputError(f"image file {path} has suffix {path.suffix!r}; expected one of {', '.join(IMAGE_SUFFIXES)}")
    if hdu is not None and not is_fits(path):
        raise InputError(f"--hdu {hdu} selects an HDU of a FITS file; {path} is not one")
    if is_fits(path):
        from startrack.image.fits import read_fits

        array, mask, saturate, epoch, index = read_fits(path, hdu)
        image = _checked(path, array)
        return Frame(image, saturate if saturate is not None else full_scale(image), mask, epoch, index)
    if suffix == ".npy":
        try:
            array = np.load(path, allow_pickle=False)
        except (ValueError, OSError) as error:
            raise InputError(f"image file {path} is not a readable .npy array ({error})") from None
        colour = False
    else:
        array, colour = _read_picture(path)
    image = _checked(path, array)
    if colour:
        return Frame(image, 255.0)
    return Frame(image, full_scale(image))


def _read_picture(path):
    """(array, is colour) of an image file read by pillow; colour as luminance (module text)."""
    try:
        with Image.open(path) as image:
            if image.mode in _GREY_MODES:
                return np.array(image), False
            if image.mode == "LA":
                return np.array(image.getchannel("L")), False
            rgb = np.asarray(image.convert("RGB"), dtype=float)
            return rgb @ _LUMA_WEIGHTS, True
    except (UnidentifiedImageError, OSError, SyntaxError, ValueError) as error:
        raise InputError(f"image file {path} could not be read as an image ({error})") from None


def _checked(path, array):
    if array.ndim != 2:
        raise InputError(f"image file {path} holds an array of shape {array.shape}; expected a 2-D frame")
    if array.size == 0:
        raise InputError(f"image file {path} holds an empty frame (shape {array.shape})")
    if array.dtype == bool:
        array = array.astype(np.uint16)
    if np.issubdtype(array.dtype, np.integer):
        if array.min() < 0 or array.max() > 65535:
            return array.astype(np.float64)
        return array.astype(np.uint16)
    if np.issubdtype(array.dtype, np.floating):
        array = array.astype(np.float64)
        if not np.all(np.isfinite(array)):
            raise InputError(f"image file {path} contains NaN or infinite pixel values")
        return array
    raise InputError(f"image file {path} holds {array.dtype} data; expected integer or floating grey levels")


def full_scale(image):
    """Full scale [DN] of integer data (module text), None for floating data."""
    if image.dtype != np.uint16:
        return None
    top = int(image.max())
    below = image[image < 65535]
    step = 1
    if below.size and np.any(below):
        common = int(np.bitwise_or.reduce(below.ravel()))
        step = common & -common  # lowest set bit over all values: the data's step
    bits = next(b for b in (8, 10, 12, 14, 16) if top < 1 << b or b == 16)
    return float((1 << bits) - step)


def stretch_to_8_bit(image, black_dn, white_dn):
    """8-bit levels (uint8) of a frame [DN], linear: round(255 (DN - black) / (white - black)), clipped to 0..255
    (``black_dn`` < ``white_dn``)."""
    if not (np.isfinite(black_dn) and np.isfinite(white_dn) and black_dn < white_dn):
        raise InputError(f"the 8-bit stretch needs black < white, got black {black_dn!r} DN and white {white_dn!r} DN")
    levels = 255.0 * (np.asarray(image, dtype=float) - black_dn) / (white_dn - black_dn)
    return np.clip(np.rint(levels), 0, 255).astype(np.uint8)


def write_image(path, image):
    """Write a frame: a greyscale PNG (.png: 8-bit for uint8 data, else 16-bit, values rounded and clipped to
    0..65535), a greyscale JPEG (.jpg/.jpeg, quality :data:`JPEG_QUALITY`: uint8 data only, e.g. of
    :func:`stretch_to_8_bit`), FITS or .npy (as is)."""
    path = Path(path)
    array = np.asarray(image)
    if array.ndim != 2 or array.size == 0:
        raise InputError(f"a frame to write must be a non-empty 2-D array, got shape {array.shape}")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        np.save(path, array, allow_pickle=False)
    elif suffix in FITS_SUFFIXES:
        from astropy.io import fits

        from startrack.image.fits import write_hdus

        write_hdus(path, fits.HDUList([fits.PrimaryHDU(array)]), "image file")
    elif suffix in _PICTURES:
        if not np.all(np.isfinite(array)):
            raise InputError(f"cannot write {path}: the frame contains NaN or infinite values")
        if array.dtype == np.uint8:
            Image.fromarray(array).save(path, **({"quality": JPEG_QUALITY} if suffix != ".png" else {}))
        elif suffix != ".png":
            raise InputError(f"cannot write {path}: a JPEG holds 8-bit levels, got {array.dtype} (stretch the frame first)")
        else:
            Image.fromarray(np.clip(np.rint(array), 0, 65535).astype(np.uint16)).save(path)
    else:
        raise InputError(f"output file {path} must end in .png (8- or 16-bit), .jpg/.jpeg (8-bit), "
                         f"{', '.join(FITS_SUFFIXES)} or .npy")
    return path
