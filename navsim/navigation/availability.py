"""Star availability along a navigation scenario's trajectory, without the filter (``navsim sky``).

Along the nominal trajectory the covariance analysis samples (:func:`navsim.navigation.covariance.nominal`),
per frame: the Sun's and the Moon's geometry and the exclusions (:mod:`navsim.navigation.exclusion`), with a
light budget the sky's brightness and the limiting magnitude at the boresight
(:mod:`navsim.navigation.sky_background`) with the sky's sources there (airglow, zodiacal light, starlight and
diffuse Galactic light, the air's scattering of them, the Moon, the Sun), and the stars the sensor reports (its vector-fidelity equivalent,
:func:`navsim.build.star_sensor.vector_equivalent`, noise-free) with their median σ. The same frames and stars
a run and the covariance analysis take: the sky is decided before any filter runs.
"""

from dataclasses import dataclass

import numpy as np

from navsim.build.star_sensor import vector_equivalent
from navsim.navigation import build, exclusion, sky_background
from navsim.navigation.covariance import nominal
from navsim.sensors.star_vector import AttitudeFixSensor
from startrack import InputError, load_star_catalog, units

#: The summary's format tag.
FORMAT = "navsim.sky-availability/1"


@dataclass(frozen=True)
class Availability:
    """The per-frame ``series`` and the ``summary`` of :func:`star_availability`."""

    series: dict
    summary: dict

    def lines(self):
        """What ``navsim sky`` prints (:func:`availability_lines`)."""
        return availability_lines(self.summary)


def star_availability(scenario, star_catalog=None):
    """The :class:`Availability` of a validated navigation scenario's star sensor (module docstring)."""
    if "star_sensor" not in scenario.data:
        raise InputError(f"{scenario.source}: no [star_sensor]: there is no star availability to show")
    nom = nominal(scenario)
    epoch = build.catalog_epoch(scenario)
    table = scenario["star_sensor"]
    interval = 1.0 / table["rate_hz"]
    sensor, note = vector_equivalent(scenario, star_catalog or load_star_catalog(epoch=epoch), interval, epoch)
    t = nom.frame_k * nom.dt
    geometry = exclusion.geometry(scenario, nom.trajectory, nom.orientation, nom.frame_k, sensor.q_BS_true)
    sensor = sky_background.seeing(exclusion.excluding(sensor, geometry, t), scenario, geometry, nom.trajectory, nom.frame_k)
    available = sensor.faults.available(t)
    series = {"t": t, **exclusion.series(geometry), "moon_elevation": geometry.moon_elevation,
              "moon_illuminated": geometry.moon_illuminated}
    if isinstance(sensor, AttitudeFixSensor):
        counts, sigma = available.astype(np.int64), np.where(available, sensor.sigma_cross, np.nan)
    else:
        stars = sensor.observe_frames(nom.sky.q_IB, np.random.default_rng(0), nom.sky.v_I, noise=False)
        counts = np.where(available, stars.counts, 0)
        sigma = np.array([np.median(stars.sigma[a:b]) if b > a else np.nan
                          for a, b in zip(stars.offsets[:-1], stars.offsets[1:])])
        sigma = np.where(counts > 0, sigma, np.nan)
    series |= {"stars": counts, "star_sigma_arcsec": units.rad_to_arcsec(sigma)}
    if getattr(sensor, "sky", None) is not None:
        series |= sensor.sky.series()
        sources, _ = sky_background.sky_sources(scenario, geometry, nom.trajectory, nom.frame_k, sensor.photometry.band)
        series |= source_series(sources)
    return Availability(series=series, summary=_summary(scenario, series, geometry, interval, note))


#: The sky's sources at the boresight: (series key, name printed, SkyBrightness field or fields).
SOURCES = (("sky_airglow_mag", "airglow", "airglow"), ("sky_zodiacal_mag", "zodiacal", "zodiacal"),
           ("sky_starlight_mag", "starlight/DGL", "starlight"), ("sky_scattered_mag", "scattered", "scattered"),
           ("sky_moon_mag", "moon", "moon"), ("sky_sun_mag", "twilight/day", "sun"))


def source_series(sky):
    """The series of the sky's sources at the boresight [mag arcsec⁻², inf: none] of a
    :class:`~navsim.earth.sky_brightness.SkyBrightness` (the Sun's: the brighter of twilight and daylight)."""
    sun = np.maximum(sky.day, sky.twilight)  # the lesser light of the two (Schaefer 1998 line 2380)
    return {key: np.asarray(sun if name == "sun" else getattr(sky, name), dtype=float) for key, _, name in SOURCES}


def _sources_summary(series):
    """{name: median [mag arcsec⁻²] of the frames where that light is (None: never)} and the fraction of those
    frames, for each source at the boresight and the total."""
    out = {}
    for key, name, _ in SOURCES + (("sky_background_mag", "total", None),):
        values = np.asarray(series[key], dtype=float)
        lit = np.isfinite(values)
        out[name] = {"median_mag": float(np.median(values[lit])) if lit.any() else None, "fraction": float(lit.mean())}
    return out


def _summary(scenario, series, geometry, interval, note):
    """The availability's totals and its hour-by-hour table."""
    stars, hours = series["stars"], series["t"] / units.HOUR
    seen = stars > 0
    hourly = []
    for start in np.arange(0.0, hours[-1] + 1e-9, 1.0) if hours.size else ():
        rows = (hours > start) & (hours <= start + 1.0)
        if not rows.any():
            continue
        hourly.append({"hour": float(start), "sun_elevation_deg": _mean_deg(series["sun_elevation"][rows]),
                       "moon_elevation_deg": _mean_deg(series["moon_elevation"][rows]),
                       "boresight_elevation_deg": _mean_deg(series["boresight_elevation"][rows]),
                       "sky_mag": _median(series.get("sky_background_mag"), rows),
                       "limiting_mag": _median(series.get("limiting_mag"), rows),
                       "stars_mean": float(stars[rows].mean()), "fraction_with_stars": float(seen[rows].mean())})
    return {"format": FORMAT, "scenario": scenario.name, "band": scenario["star_sensor"]["band"],
            "light_budget": "limiting_mag" in series, "frames": int(stars.size), "frame_interval_s": interval,
            "hours": float(stars.size * interval / units.HOUR), "hours_with_stars": float(seen.sum() * interval / units.HOUR),
            "fraction_with_stars": float(seen.mean()) if stars.size else 0.0,
            "stars_per_frame": {"mean": float(stars.mean()), "median": float(np.median(stars)), "max": int(stars.max(initial=0))},
            "frames_excluded": geometry.counts(), "hourly": hourly, "notes": [note] if note else [],
            "sky_sources": _sources_summary(series) if "sky_airglow_mag" in series else None}


def _source_text(name, entry):
    """'name 21.95' (fainter than 30: '>30'; 'none' if never there), with the share of frames when not all."""
    mu = entry["median_mag"]
    text = "none" if mu is None else (">30" if mu > 30.0 else f"{mu:.2f}")
    share = "" if mu is None or entry["fraction"] == 1.0 else f" ({100 * entry['fraction']:.0f} % of frames)"
    return f"{name} {text}{share}"


def _mean_deg(angles):
    return float(np.degrees(np.mean(angles)))


def _median(values, rows):
    """The median of the finite ``values[rows]`` (None: no such series, or none finite)."""
    if values is None:
        return None
    finite = values[rows][np.isfinite(values[rows])]
    return float(np.median(finite)) if finite.size else None


def availability_lines(summary):
    """What ``navsim sky`` prints: the totals, then one line per hour."""
    per_frame = summary["stars_per_frame"]
    lines = [f"sky                 {summary['scenario']}: stars in {summary['hours_with_stars']:.2f} of {summary['hours']:.2f} h "
             f"({100 * summary['fraction_with_stars']:.1f} % of {summary['frames']} frames), {per_frame['mean']:.2f} per frame "
             f"(median {per_frame['median']:g}, max {per_frame['max']}); band {summary['band']}"
             + ("" if summary["light_budget"] else " (no light budget: every catalog star in the field counts)")]
    excluded = ", ".join(f"{count} {reason}" for reason, count in summary["frames_excluded"].items() if count)
    if excluded:
        lines.append(f"excluded frames     {excluded}")
    if summary.get("sky_sources"):
        lines.append("sky sources         median at the boresight [mag/arcsec²]: " + ", ".join(
            _source_text(name, entry) for name, entry in summary["sky_sources"].items()))
    lines.append("hour  Sun el  Moon el  boresight el  sky mag/arcsec²  limiting mag  stars/frame  with stars")
    for row in summary["hourly"]:
        sky = "" if row["sky_mag"] is None else f"{row['sky_mag']:.2f}"
        limit = "none" if row["limiting_mag"] is None and summary["light_budget"] else (
            "" if row["limiting_mag"] is None else f"{row['limiting_mag']:.2f}")
        lines.append(f"{row['hour']:4.0f}  {row['sun_elevation_deg']:6.1f}  {row['moon_elevation_deg']:7.1f}  "
                     f"{row['boresight_elevation_deg']:12.1f}  {sky:>15}  {limit:>12}  {row['stars_mean']:11.2f}  "
                     f"{100 * row['fraction_with_stars']:9.0f} %")
    return lines + [f"note                {n}" for n in summary["notes"]]
