"""Alexander et al. 1999's day/night balloon star camera reproduced with the project's own sky and detection models
(issue 53 item 3): the limiting R magnitude at 35 km by day for exposures of 0.05-1 s, the one parameter the paper
does not give.

Alexander, Swift, Ghosh & Ramsey, "Design of a day/night star camera system" (NASA NTRS 19990103105, 1999; the
abstract, docs/references.md): a 64.3 mm f/2.8 lens (focal length 180.0 mm), a 1340 x 1037 CCD of 6.8 µm pixels
(7.79" each), 45 000 e⁻ wells, QE 0.525 at 700 nm, an R filter of 590-810 nm, a balloon at 35-42 km whose
worst-case daytime sky by MODTRAN is 2e-5 W cm⁻² sr⁻¹ µm⁻¹ in R, at the Sun's zenith angle of 30° (its Fig. 4);
predicted limiting magnitudes R 8.25-9.00 (1-2 stars per square degree). Not given there, and taken here:

- **exposure**: bracketed, 0.05, 0.1, 0.2, 0.5, 1 s;
- **the passband** as a rectangle of 590-810 nm (centre 0.70 µm, width 0.22 µm) whose Vega zero point f_λ,0 at
  0.70 µm is interpolated log-linearly in λ between the project's R_C and I_C ones (1.70e-2 W m⁻³): a star's and
  the sky's R magnitudes taken as Vega-coloured across the band (the project's own 138 nm R_C band is the
  second column, for comparison);
- **optics transmission** 0.8 and a PSF of σ = 0.671 px (the project's defaults; at f/2.8 the Airy disk is
  4.8 µm across, smaller than a pixel); read noise 3 e⁻ and dark current 10 e⁻ s⁻¹ px⁻¹ (the project's
  ``silicon_cmos`` preset: by day the sky's charge dwarfs both); detection at a = 5 σ of a pixel (004's rule,
  :class:`startrack.image.sensor_photometry.SensorPhotometry`, the runs' model), no trail (a stabilised
  gondola);
- **the sky**: :func:`navsim.earth.sky_brightness.sky_brightness` in R at 35 km (and at his ceiling of 42 km)
  with the Sun at zenith angle 30°, the boresight at the anti-solar azimuth 40-60° high (60-80° from the Sun: the Sun at 60° elevation
  leaves no line of sight above 30° elevation 90° from it), and Alexander's own 2e-5 converted to mag arcsec⁻²
  by :func:`navsim.earth.sky_brightness.surface_brightness` (his worst case).

Prints, per exposure, the limiting magnitude for each sky, the exposure range whose limits meet the published
8.25-9.00, the sensitivities d m_lim / d log10 t and d m_lim / d μ_sky, and the exposure at which the sky fills
the 45 000 e⁻ well. Run: PYTHONPATH=. .venv/bin/python reports/alexander1999.py
"""

import numpy as np

from navsim.earth.sky_brightness import Sightline, sky_brightness, surface_brightness
from startrack.image.sensor_photometry import SensorPhotometry
from startrack.photometry.bands import BANDS, Band
from startrack.photometry.detectors import Detector

#: Alexander et al. 1999 (the abstract): aperture [m], focal ratio, pixel pitch [m], QE, full well [e⁻], filter
#: [m], height [m], the Sun's zenith angle [deg] (Fig. 4), the worst-case sky [W cm⁻² sr⁻¹ µm⁻¹], the limits.
APERTURE = 64.3e-3
FOCAL_RATIO = 2.8
PIXEL_PITCH = 6.8e-6
QE = 0.525
FULL_WELL = 45000.0
FILTER = (590e-9, 810e-9)
HEIGHT = 35000.0
CEILING = 42000.0
SUN_ZENITH_DEG = 30.0
WORST_SKY_RADIANCE = 2e-5
PUBLISHED_LIMITS = (8.25, 9.00)
#: The bracket of exposures [s] and the boresight elevations [deg] at the anti-solar azimuth.
EXPOSURES = (0.05, 0.1, 0.2, 0.5, 1.0)
ELEVATIONS_DEG = (40.0, 50.0, 60.0)
#: Not in the paper (module docstring): transmission, PSF σ [px], read noise [e⁻], dark [e⁻ s⁻¹ px⁻¹], a.
TRANSMISSION = 0.8
PSF_SIGMA_PX = 0.671
READ_NOISE = 3.0
DARK = 10.0
DETECTION_SIGMAS = 5.0


def alexander_band():
    """His 590-810 nm filter as a rectangle, f_λ,0 at its centre interpolated log-linearly between R_C and I_C."""
    r, i = BANDS["R"], BANDS["I"]
    centre = 0.5 * (FILTER[0] + FILTER[1])
    slope = np.log(i.flux_zero / r.flux_zero) / (i.centre - r.centre)
    return Band("R", centre, FILTER[1] - FILTER[0], float(r.flux_zero * np.exp(slope * (centre - r.centre))))


def photometry(exposure_s, band=None):
    """The camera's :class:`SensorPhotometry` at ``exposure_s`` in ``band`` (default: his filter)."""
    band = alexander_band() if band is None else band
    ccd = Detector("alexander_1999_ccd", (FILTER[0], FILTER[1]), (QE, QE), READ_NOISE, DARK, FULL_WELL, PIXEL_PITCH)
    return SensorPhotometry(band=band, detector=ccd, aperture_area=np.pi * (0.5 * APERTURE) ** 2,
                            transmission=TRANSMISSION, exposure_s=exposure_s, psf_sigma_px=PSF_SIGMA_PX,
                            pixel_scale=PIXEL_PITCH / (APERTURE * FOCAL_RATIO), detection_sigmas=DETECTION_SIGMAS)


def model_skies(elevations_deg=ELEVATIONS_DEG, height=HEIGHT):
    """The model's R sky [mag arcsec⁻²] at ``height`` [m] (35 km), the Sun 30° from the zenith, boresights at the
    anti-solar azimuth ``elevations_deg`` high."""
    e = np.asarray(elevations_deg, dtype=float)
    sun_elevation = 90.0 - SUN_ZENITH_DEG
    far = np.full_like(e, np.pi)
    sight = Sightline(zenith=np.radians(90.0 - e), sun_zenith=np.full_like(e, np.radians(SUN_ZENITH_DEG)),
                      sun_angle=np.radians(180.0 - sun_elevation - e), moon_zenith=far, moon_angle=far,
                      moon_phase_angle=far, height=np.full_like(e, height), year=np.full_like(e, 1999.0))
    return sky_brightness("R", sight).total


def limiting_magnitudes(skies_mag, exposures=EXPOSURES, band=None):
    """Limiting magnitude [exposure, sky] (−inf: the sky fills the well) for skies of ``skies_mag``."""
    rows = []
    for t in exposures:
        p = photometry(t, band)
        rows.append(p.limiting_magnitude(p.sky_e_per_px_s(np.asarray(skies_mag, dtype=float))))
    return np.array(rows)


def well_filling_exposure(sky_mag, band=None):
    """The exposure [s] at which the sky and dark charge alone fill the 45 000 e⁻ well."""
    p = photometry(1.0, band)
    return FULL_WELL / (float(p.sky_e_per_px_s(sky_mag)) + DARK)


def published_exposure_range(sky_mag, band=None):
    """(shortest, longest) exposure [s] of the bracket whose limit on a sky of ``sky_mag`` lies in 8.25-9.00 (None:
    none), on 200 exposures spaced evenly in log t over 0.05-1 s."""
    t = np.geomspace(min(EXPOSURES), max(EXPOSURES), 200)
    m = limiting_magnitudes([sky_mag], t, band)[:, 0]
    inside = (m >= PUBLISHED_LIMITS[0]) & (m <= PUBLISHED_LIMITS[1])
    return (float(t[inside][0]), float(t[inside][-1])) if inside.any() else None


def bracket_span(sky_mag, band=None):
    """(faintest, deepest) limiting magnitude over the bracket's exposures on a sky of ``sky_mag`` before its charge
    fills the well (200 exposures evenly in log t over 0.05-1 s)."""
    t = np.geomspace(min(EXPOSURES), max(EXPOSURES), 200)
    m = limiting_magnitudes([sky_mag], t, band)[:, 0]
    m = m[np.isfinite(m)]
    return (float(m.min()), float(m.max())) if m.size else None


def main():
    skies = model_skies()
    worst = float(surface_brightness("R", WORST_SKY_RADIANCE))
    ceiling = float(model_skies([50.0], CEILING)[0])
    all_skies = np.append(skies, [worst, ceiling])
    own = limiting_magnitudes(all_skies)
    rc = limiting_magnitudes(all_skies, band=BANDS["R"])
    names = [f"model el {e:.0f}° (ρ {120.0 - e:.0f}°)" for e in ELEVATIONS_DEG] + ["Alexander 2e-5", "model 42 km el 50°"]
    print("Alexander et al. 1999 at 35 km, Sun at zenith angle 30°: limiting R [mag] (his 590-810 nm / our R_C)")
    print("sky [mag/arcsec²]     " + "  ".join(f"{n:>22}" for n in names))
    print("                      " + "  ".join(f"{s:>22.2f}" for s in all_skies))
    for k, t in enumerate(EXPOSURES):
        cells = [f"{own[k, j]:>10.2f} / {rc[k, j]:<9.2f}" for j in range(len(all_skies))]
        print(f"t = {t:<5} s            " + "  ".join(f"{c:>22}" for c in cells))
    for j, name in enumerate(names):
        span, reach = published_exposure_range(all_skies[j]), bracket_span(all_skies[j])
        fill = well_filling_exposure(all_skies[j])
        text = "none in the bracket" if span is None else f"{span[0]:.2f}-{span[1]:.2f} s"
        print(f"{name}: limits {reach[0]:.2f}-{reach[1]:.2f} over the bracket; R 8.25-9.00 at {text}; "
              f"the sky fills the well at {fill:.2f} s")
    finite = np.isfinite(own[:, 1])
    t = np.log10(np.asarray(EXPOSURES)[finite])
    slope_t = np.polyfit(t, own[finite, 1], 1)[0]
    d_sky = (limiting_magnitudes([skies[1] + 0.1], (0.1,))[0, 0] - limiting_magnitudes([skies[1]], (0.1,))[0, 0]) / 0.1
    print(f"sensitivity (model sky at el 50°): d m_lim / d log10 t = {slope_t:.2f}, d m_lim / d μ_sky = {d_sky:.2f} at 0.1 s")


if __name__ == "__main__":
    main()
