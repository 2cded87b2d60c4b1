"""``startrack solve --annotate FILE``: a PNG of a solved frame with what was matched (matplotlib, Agg).

Drawn over the frame (grey, linear from b - 2 sigma_n to b + 40 sigma_n of its detection), in the frame's own
pixels (0-based (u, v), v down: the picture as stored, top row first; a FITS frame therefore upside down
beside a FITS viewer, which puts row 1 at the bottom):

* every detection: a small orange square;
* every matched catalog star: a green circle at its catalog direction projected through the solved camera
  (:meth:`startrack.camera.model.Camera.project` of the answer's ``ref_I``; a star's detection lies within
  its residual of it), named by its HIP number (Gaia DR3 source_id for a Gaia star Hipparcos-2 lacks), its
  constellation (IAU boundaries, astropy's ``get_constellation``) and V magnitude -- the shipped catalogs
  (Hipparcos-2's hip2.dat, the Gaia DR3 table) hold no Bayer or proper names;
* the RA/Dec grid: lines of constant RA and Dec projected through the camera, spaced to about a quarter of
  the field's height (RA in minutes or hours of time), labelled where they enter the image;
* a compass (north, east at the image centre's corner) and a legend with the centre, field, scale and
  orientation of :class:`startrack.camera.sky_field.SkyField`.

The figure's data coordinates are the image's pixels, the axes the whole figure, so a point drawn at (u, v)
lands on the PNG's pixel (u, v) (scaled down when the image is wider than :data:`_MAX_SIDE_PX`).  Each kind
of artist carries a ``gid`` ("detections", "matched", "names", "grid") so that a test reads back what was drawn.
"""

from __future__ import annotations

import math

import numpy as np

from startrack.base.output_paths import write_whole
from startrack.catalog.hipparcos import HIP_MAX
from startrack.geometry.rotation import to_matrix
from startrack.geometry.sphere import local_frame, radec_to_vector, vector_to_radec

#: Largest side of the PNG [px]: a larger frame is drawn scaled down.
_MAX_SIDE_PX = 4096
#: Grid spacings [deg]: Dec (arcminutes to 30 deg) and RA (1 min of time to 2 h).
_DEC_STEPS = (1 / 60, 2 / 60, 5 / 60, 10 / 60, 15 / 60, 0.5, 1.0, 2.0, 5.0, 10.0, 15.0, 30.0)
_RA_STEPS = (0.25, 0.5, 1.25, 2.5, 5.0, 7.5, 15.0, 30.0)
#: Samples along each grid line.
_SAMPLES = 400


def write_annotation(path, frame, result, epoch):
    """Write the PNG of ``frame`` (a SolveFrame with its image) and its identified ``result`` to ``path``."""
    import matplotlib.pyplot as plt

    figure, dpi = annotation_figure(frame, result, epoch)
    try:
        write_whole(path, lambda temporary: figure.savefig(temporary, dpi=dpi, format="png"), "--annotate")
    finally:
        plt.close(figure)


def annotation_figure(frame, result, epoch):
    """(matplotlib Figure, its dpi) of the annotated frame (module text)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    height, width = frame.image.shape
    dpi = 100.0 * min(1.0, _MAX_SIDE_PX / max(width, height))
    points = 7.0 * max(width, height) / 1024.0  # text and markers scale with the image
    figure = plt.figure(figsize=(width / 100.0, height / 100.0), dpi=dpi)
    ax = figure.add_axes((0.0, 0.0, 1.0, 1.0))
    background, noise = frame.detection["background_dn"], max(frame.detection["sigma_n_dn"], 1e-9)
    ax.imshow(frame.image, cmap="gray", vmin=background - 2.0 * noise, vmax=background + 40.0 * noise,
              extent=(-0.5, width - 0.5, height - 0.5, -0.5), interpolation="nearest")
    _draw_grid(ax, result.camera, result.q_IS, points)
    ax.scatter(frame.uv[:, 0], frame.uv[:, 1], s=(1.6 * points) ** 2, marker="s", facecolors="none",
               edgecolors="orange", linewidths=points / 10.0, gid="detections")
    _draw_matched(ax, result, epoch, points)
    _draw_compass(ax, result.camera, result.q_IS, points)
    _legend(ax, frame, result, points)
    ax.set_xlim(-0.5, width - 0.5)
    ax.set_ylim(height - 0.5, -0.5)
    ax.axis("off")
    return figure, dpi


def star_names(ids, ra_deg, dec_deg, epoch):
    """Names of matched stars: "HIP n" (or "Gaia DR3 id"), constellation, "V m" (module text)."""
    from astropy.coordinates import SkyCoord, get_constellation

    from startrack.identify.pattern_catalog import magnitudes_of

    ids = np.asarray(ids, np.int64)
    magnitudes = magnitudes_of(ids, epoch)
    constellations = get_constellation(SkyCoord(ra_deg, dec_deg, unit="deg", frame="icrs"), short_name=True)
    return [f"{'HIP' if i <= HIP_MAX else 'Gaia DR3'} {i} {c} V {m:.1f}"
            for i, c, m in zip(ids, np.atleast_1d(constellations), magnitudes)]


def _draw_matched(ax, result, epoch, points):
    """The matched catalog stars: circles at their projected directions, and their names."""
    uv, _ = result.camera.project(result.q_IS, result.ref_I)
    ra, dec = np.degrees(vector_to_radec(result.ref_I))
    ax.scatter(uv[:, 0], uv[:, 1], s=(3.0 * points) ** 2, marker="o", facecolors="none", edgecolors="lime",
               linewidths=points / 7.0, gid="matched")
    for (u, v), name in zip(uv, star_names(result.matched_hip, ra, dec, epoch)):
        ax.annotate(name, (u, v), xytext=(2.2 * points, -1.5 * points), textcoords="offset points", color="lime",
                    fontsize=points, gid="names")


def _draw_grid(ax, camera, q_IS, points):
    """Lines of constant RA and Dec over the image, labelled where each enters it."""
    ra_range, dec_range, dec_centre = _sky_extent(camera, q_IS)
    dec_step = _step(_DEC_STEPS, (dec_range[1] - dec_range[0]) / 4.0)
    ra_step = _step(_RA_STEPS, dec_step / max(math.cos(math.radians(dec_centre)), 0.03))
    dec_samples = np.linspace(*dec_range, _SAMPLES)
    ra_samples = np.linspace(*ra_range, _SAMPLES)
    lines = [(_hours(ra), np.full(_SAMPLES, ra), dec_samples, 1) for ra in _multiples(ra_range, ra_step)]
    lines += [(_degrees(dec), ra_samples, np.full(_SAMPLES, dec), 0) for dec in _multiples(dec_range, dec_step)
              if abs(dec) < 90.0]
    for label, ra, dec, axis in lines:
        uv, inside = _projected(camera, q_IS, ra, dec)
        ax.plot(uv[:, 0], uv[:, 1], color="deepskyblue", linewidth=points / 10.0, alpha=0.7, gid="grid")
        if inside.any():  # an RA line labelled at its lower end in the image, a Dec line at its left end
            ends = uv[np.flatnonzero(inside)[[0, -1]]]
            u, v = ends[np.argmax(ends[:, 1])] if axis else ends[np.argmin(ends[:, 0])]
            ax.annotate(label, (u, v), xytext=(2, 2), textcoords="offset points", color="deepskyblue",
                        fontsize=0.9 * points, gid="grid")


def _projected(camera, q_IS, ra_deg, dec_deg):
    """(uv (N, 2) with NaN where the camera does not image the direction or far outside, inside the image (N,))."""
    vectors = radec_to_vector(np.radians(ra_deg), np.radians(dec_deg))
    uv, inside = camera.project(q_IS, vectors)
    near = np.zeros(len(vectors), bool)
    near[camera.stars_in_field(q_IS, vectors, margin_px=0.25 * max(camera.width, camera.height))] = True
    return np.where(near[:, None], uv, np.nan), inside


def _sky_extent(camera, q_IS):
    """((RA low, high), (Dec low, high), Dec of the centre) [deg] of the image: RA about the centre's, unwrapped;
    all RA and Dec to the pole when a pole is in the image."""
    u, v = np.meshgrid(np.linspace(-0.5, camera.width - 0.5, 33), np.linspace(-0.5, camera.height - 0.5, 33))
    directions = camera.unproject(np.stack([u.ravel(), v.ravel()], axis=1)) @ to_matrix(np.asarray(q_IS, dtype=float)).T
    ra, dec = np.degrees(vector_to_radec(directions))
    centre = directions[len(directions) // 2]
    ra_c, dec_c = np.degrees(vector_to_radec(centre))
    relative = (ra - ra_c + 180.0) % 360.0 - 180.0
    ra_range, dec_range = (ra_c + relative.min(), ra_c + relative.max()), (dec.min(), dec.max())
    for pole in (1.0, -1.0):
        _, inside = camera.project(q_IS, np.array([[0.0, 0.0, pole]]))
        if inside[0]:
            ra_range = (0.0, 360.0)
            dec_range = (dec_range[0], 90.0) if pole > 0 else (-90.0, dec_range[1])
    return ra_range, dec_range, float(dec_c)


def _step(steps, wanted):
    """The largest of ``steps`` at most ``wanted`` (the smallest if none)."""
    fitting = [s for s in steps if s <= wanted]
    return fitting[-1] if fitting else steps[0]


def _multiples(bounds, step):
    """The multiples of ``step`` within ``bounds``."""
    return step * np.arange(math.ceil(bounds[0] / step), math.floor(bounds[1] / step) + 1)


def _hours(ra_deg):
    """RA [deg] as "5h36m" (whole minutes of time)."""
    minutes = round((ra_deg % 360.0) * 4.0) % 1440
    return f"{minutes // 60}h{minutes % 60:02d}m"


def _degrees(dec_deg):
    """Dec [deg] as "+5°20'" (whole arcminutes)."""
    minutes = round(abs(dec_deg) * 60.0)
    return f"{'-' if dec_deg < 0 else '+'}{minutes // 60}°{minutes % 60:02d}'"


def _draw_compass(ax, camera, q_IS, points):
    """Arrows towards north and east from a point a tenth of the image in from its lower right corner."""
    corner = np.array([[0.9 * camera.width, 0.9 * camera.height]])
    direction = camera.unproject(corner)[0] @ to_matrix(np.asarray(q_IS, dtype=float)).T
    _, east, north = local_frame(*vector_to_radec(direction))
    length = 0.06 * min(camera.width, camera.height)
    for axis, name in ((north, "N"), (east, "E")):
        tip, _ = camera.project(q_IS, (direction + 1e-4 * axis)[None])
        delta = tip[0] - corner[0]
        delta *= length / np.linalg.norm(delta)
        ax.annotate("", corner[0] + delta, corner[0], arrowprops={"arrowstyle": "->", "color": "yellow",
                                                                   "linewidth": points / 7.0})
        ax.annotate(name, corner[0] + 1.25 * delta, color="yellow", fontsize=points, ha="center", va="center")


def _legend(ax, frame, result, points):
    """The field of the answer and what the marks are, at the top left."""
    field = result.sky_field
    ra, dec = field.sexagesimal
    text = (f"centre {ra} {dec} ({field.ra_deg:.4f}, {field.dec_deg:+.4f} deg)\n"
            f"field {field.width_deg:.3f} x {field.height_deg:.3f} deg, {field.scale_arcsec:.3f}\"/px, "
            f"+v (rows down; astrometry.net's up) is {field.orientation_deg:.2f} deg E of N, parity {field.parity}\n"
            f"green circles: {len(result.matches)} matched catalog stars; orange squares: {len(frame.uv)} detections; "
            f"blue: RA/Dec grid")
    ax.text(0.01, 0.99, text, transform=ax.transAxes, va="top", ha="left", color="white", fontsize=points,
            bbox={"facecolor": "black", "alpha": 0.6, "edgecolor": "none"})
