"""Read and write star-sensor frames: PNG/TIFF (pillow) and NumPy .npy.

Frames are 2-D greyscale arrays [DN].  Integer images come back as
uint16 (8-bit files are widened), floating images as float64; colour,
multi-channel or non-2-D data are refused with one clear message.
"""

from pathlib import Path

import numpy as np
from PIL import Image, UnidentifiedImageError

from startrack.errors import InputError

IMAGE_SUFFIXES = (".png", ".tif", ".tiff", ".npy")


def read_image(path):
    """2-D frame from a PNG, TIFF or .npy file (uint16 for integer data, float64 otherwise)."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"image file {path} does not exist")
    suffix = path.suffix.lower()
    if suffix not in IMAGE_SUFFIXES:
        raise InputError(f"image file {path} has suffix {path.suffix!r}; expected one of {', '.join(IMAGE_SUFFIXES)}")
    if suffix == ".npy":
        try:
            array = np.load(path, allow_pickle=False)
        except (ValueError, OSError) as error:
            raise InputError(f"image file {path} is not a readable .npy array ({error})") from None
    else:
        try:
            with Image.open(path) as image:
                if image.mode not in ("L", "I;16", "I;16B", "I;16L", "I", "F", "1"):
                    raise InputError(
                        f"image file {path} has mode {image.mode} ({len(image.getbands())} channels); "
                        "a star-sensor frame must be single-channel greyscale"
                    )
                array = np.array(image)
        except (UnidentifiedImageError, OSError, SyntaxError) as error:
            raise InputError(f"image file {path} could not be read as an image ({error})") from None
    if array.ndim != 2:
        raise InputError(f"image file {path} holds an array of shape {array.shape}; expected a 2-D greyscale frame")
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


def write_image(path, image):
    """Write a frame: 16-bit greyscale PNG (.png, values rounded and clipped to 0..65535) or .npy (as is)."""
    path = Path(path)
    array = np.asarray(image)
    if array.ndim != 2 or array.size == 0:
        raise InputError(f"a frame to write must be a non-empty 2-D array, got shape {array.shape}")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        np.save(path, array, allow_pickle=False)
    elif suffix == ".png":
        if not np.all(np.isfinite(array)):
            raise InputError(f"cannot write {path}: the frame contains NaN or infinite values")
        data = np.clip(np.rint(array), 0, 65535).astype(np.uint16)
        Image.fromarray(data).save(path)
    else:
        raise InputError(f"output file {path} must end in .png (16-bit) or .npy")
    return path
