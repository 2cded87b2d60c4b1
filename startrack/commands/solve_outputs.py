"""The files ``startrack solve`` writes per solved frame for the astronomers' tools (FITS, astropy.io.fits) and eyes.

* ``--wcs FILE``: the solution's WCS (:func:`startrack.camera.wcs.frame_wcs`: TAN with SIP of the order the camera
  model needs, ZPN for a fisheye) as the header of a FITS file without data, as astrometry.net's ``.wcs`` files;
* ``--new-fits FILE``: the input image with that header -- a FITS input keeps its HDUs and header, its
  earlier celestial WCS replaced; another image is written as the frame read (grey levels);
* ``--annotate FILE.png``: the image with its detections, the matched catalog stars and an RA/Dec grid
  (:mod:`startrack.commands.solve_annotate`);
* ``--corr FILE``: the matched stars as a FITS table: ``field_x``, ``field_y`` (FITS pixels, 1-based),
  ``field_ra``, ``field_dec`` (the WCS's direction of the star's centroid), ``index_ra``, ``index_dec``
  (the catalog's, at the epoch) [deg], ``index_id`` (HIP, else the Gaia DR3 source_id), ``field_id`` (the
  centroid's index), ``mag`` (V).

With several frames (INPUTs or ``--batch``) a FILE must hold ``{stem}``, replaced by each image's file name
without its suffix (a JSON Lines frame's id).  Every file is written whole or not at all
(:func:`startrack.image.fits.write_hdus`); a frame not identified writes none.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from startrack.base.errors import InputError
from startrack.base.output_paths import check_file
from startrack.image.fits import FITS_SUFFIXES, WCS_KEYWORDS, fits_stem, is_fits, write_hdus

#: The options, and the file suffixes each takes (astrometry.net's .wcs, .new and .corr are FITS files too).
_OUTPUTS = {"wcs": ("--wcs", FITS_SUFFIXES + (".wcs",)), "new_fits": ("--new-fits", FITS_SUFFIXES + (".new",)),
           "corr": ("--corr", FITS_SUFFIXES + (".corr",)), "annotate": ("--annotate", (".png",))}


def add_output_options(parser):
    """``--wcs``, ``--new-fits``, ``--corr``, ``--annotate`` (module text)."""
    group = parser.add_argument_group("outputs (per identified frame; {stem} names each of several frames)")
    group.add_argument("--wcs", metavar="FILE", help="write the solution's FITS WCS header (TAN-SIP) to FILE")
    group.add_argument("--new-fits", metavar="FILE", help="write the image with the solution's WCS header to FILE")
    group.add_argument("--corr", metavar="FILE", help="write the matched stars (pixel, catalog RA/Dec, HIP, V) to FILE")
    group.add_argument("--annotate", metavar="FILE.png",
                       help="draw the image with its detections, the matched catalog stars (HIP or Gaia DR3 id, "
                            "constellation, V) and an RA/Dec grid to FILE.png")


def check_output_options(args, frames):
    """Refuse, before any work, a FILE without ``{stem}`` for several frames (``frames``: the number of
    INPUTs, or None for a batch), with another suffix, or where it cannot be written
    (:func:`startrack.base.output_paths.check_file`)."""
    for name, (option, suffixes) in _OUTPUTS.items():
        template = getattr(args, name)
        if template is None:
            continue
        if (frames is None or frames > 1) and "{stem}" not in template:
            raise InputError(f"{option} {template}: several frames need {{stem}} in the file name (e.g. out/{{stem}}.fits)")
        check_file(template, option, suffixes)


def write_outputs(args, frame, result, epoch):
    """Write the files of the options for the identified ``frame`` (a SolveFrame) and its ``result``."""
    if not result.ok or not any(getattr(args, name) for name in _OUTPUTS):
        return
    stem = _stem(frame.frame_id)
    if args.annotate:
        if frame.image is None:
            raise InputError(f"--annotate needs an image; {frame.frame_id} is a list of centroids")
        from startrack.commands.solve_annotate import write_annotation

        write_annotation(args.annotate.replace("{stem}", stem), frame, result, epoch)
    if not (args.wcs or args.new_fits or args.corr):
        return
    from astropy.io import fits

    from startrack.camera.wcs import frame_wcs

    solution = frame_wcs(result.camera, result.q_IS)
    header = fits.Header(solution.cards())
    model = "ZPN, exact" if solution.projection == "ZPN" else\
        f"SIP order {solution.order} within {solution.max_error_px:.1e} px of the camera model"
    header.add_comment(f"startrack solve: {len(result.matches)} catalog stars at epoch J{epoch:.3f}, {model}")
    if args.wcs:
        write_hdus(args.wcs.replace("{stem}", stem), fits.HDUList([fits.PrimaryHDU(header=header)]), "--wcs")
    if args.new_fits:
        with _new_fits(frame, header) as hdus:
            write_hdus(args.new_fits.replace("{stem}", stem), hdus, "--new-fits")
    if args.corr:
        write_hdus(args.corr.replace("{stem}", stem), _corr(frame, result, header, epoch), "--corr")


def _stem(frame_id):
    text = str(frame_id)
    return fits_stem(text) if is_fits(text) else Path(text).stem if Path(text).suffix else text


def _new_fits(frame, header):
    """The HDUList of the input with the WCS: a FITS input's own HDUs (the image HDU's old WCS removed),
    else the frame read."""
    from astropy.io import fits

    path = Path(str(frame.frame_id))
    if is_fits(path):
        hdus = fits.open(path, memmap=False)
        image = hdus[frame.hdu]
        for keyword in [k for k in image.header if WCS_KEYWORDS.match(k)]:
            del image.header[keyword]
        image.header.extend(header, unique=True)
        return hdus
    if frame.image is None:
        raise InputError(f"--new-fits needs an image; {frame.frame_id} is a list of centroids")
    return fits.HDUList([fits.PrimaryHDU(frame.image, header=header)])


def _corr(frame, result, header, epoch):
    """The BINTABLE of the matched stars (module text)."""
    from astropy.io import fits
    from astropy.wcs import WCS

    from startrack.geometry.sphere import vector_to_radec
    from startrack.identify.pattern_catalog import magnitudes_of

    index = result.matches[:, 0]
    pixels = frame.uv[index] + 1.0
    ra, dec = np.degrees(vector_to_radec(result.ref_I))
    field_ra, field_dec = WCS(header).all_pix2world(pixels[:, 0], pixels[:, 1], 1)
    mag = magnitudes_of(result.matched_hip, epoch)
    columns = [fits.Column("field_x", "D", array=pixels[:, 0]), fits.Column("field_y", "D", array=pixels[:, 1]),
               fits.Column("field_ra", "D", "deg", array=field_ra), fits.Column("field_dec", "D", "deg", array=field_dec),
               fits.Column("index_ra", "D", "deg", array=ra % 360.0), fits.Column("index_dec", "D", "deg", array=dec),
               fits.Column("index_id", "K", array=result.matched_hip), fits.Column("field_id", "K", array=index),
               fits.Column("mag", "E", "mag", array=mag)]
    return fits.HDUList([fits.PrimaryHDU(), fits.BinTableHDU.from_columns(columns, name="CORR")])
