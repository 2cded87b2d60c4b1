"""The spacecraft's sky at image fidelity (issue 51 items 3 and 5): the particle flux's map, the hits' statistics
against their closed forms, the Earth's stray light against the Lambert sphere, and a short run of two image heads in
a heavy particle flux: hits drawn and counted, no wrong identification, the filter consistent."""

from pathlib import Path

import numpy as np
import pytest

from navsim.kinds import scenario_from_dict
from navsim.orbit.earth_disc import EarthDisc
from navsim.orbit.radiation import ParticleFlux, geomagnetic_latitude
from navsim.scenario import read_scenario_file
from navsim.sensors.radiation_hits import RadiationHits
from navsim.sensors.stray_light import SUN_MAGNITUDE, Baffle, StrayLight
from navsim.simulation import prepare, simulate
from startrack.photometry.bands import band

DATA = Path(__file__).resolve().parent / "data"


def test_the_flux_peaks_in_the_anomaly_and_the_horns_over_the_background():
    flux = ParticleFlux()
    lat, lon = np.radians([-26.0, 0.0]), np.radians([-50.0, 100.0])
    values = flux.flux(lat, lon, np.full(2, 550e3))
    assert values[0] == pytest.approx(flux.background + flux.saa_peak, rel=1e-3)  # the horns are far from the anomaly
    assert values[1] == pytest.approx(flux.background, rel=1e-2)
    # the dipole's pole is at 90 deg of geomagnetic latitude; 25 deg from it along its meridian, the horn's peak at 65
    pole_lat, pole_lon = np.radians([80.65, -72.68])
    assert np.degrees(geomagnetic_latitude(pole_lat, pole_lon)) == pytest.approx(90.0, abs=1e-6)
    point = (pole_lat - np.radians(25.0), pole_lon)
    assert np.degrees(geomagnetic_latitude(*point)) == pytest.approx(65.0, abs=1e-9)
    assert flux.terms(*point, 550e3)[1] == pytest.approx(flux.horn_peak, rel=1e-9)


def test_the_hits_are_poisson_with_the_cosine_law_and_their_charge():
    """40000 frames of 2.5 expected hits: the mean count within 4σ of Poisson's; the incidence recovered from each
    track's length (L p / t = tan θ) follows the cosine law of an isotropic flux through a plane (cos² θ uniform:
    Kolmogorov-Smirnov at 1e-3); the charge over the path's q t / cos θ is the log-normal spread (log: mean −σ²/2,
    σ, each within 4 of its standard errors); the rendered pieces carry the whole charge, none longer than 4 px."""
    from scipy.stats import kstest

    q, t, p, sigma = 300.0, 10.0, 5.0, 0.5
    hits = RadiationHits(expected=np.full(40000, 2.5), thickness_um=t, pixel_um=p, electrons_per_um=q, spread=sigma)
    rng = np.random.default_rng(3)
    draws = [hits.draw(f, rng, 1e9, 1e9) for f in range(40000)]
    counts = np.array([len(d[0]) for d in draws])
    assert counts.mean() == pytest.approx(2.5, abs=4 * np.sqrt(2.5 / counts.size))
    length = np.concatenate([np.hypot(d[2], d[3]) for d in draws])
    charge = np.concatenate([d[4] for d in draws])
    cos_theta = 1.0 / np.sqrt(1.0 + (length * p / t) ** 2)
    assert kstest(cos_theta**2, "uniform").pvalue > 1e-3
    spread = np.log(charge * cos_theta / (q * t))
    n = spread.size
    assert spread.mean() == pytest.approx(-0.5 * sigma**2, abs=4 * sigma / np.sqrt(n))
    assert spread.std() == pytest.approx(sigma, abs=4 * sigma / np.sqrt(2 * n))
    pieces = RadiationHits.sources(draws[0])
    assert sum(float(piece.electrons[0]) for piece in pieces) == pytest.approx(float(draws[0][4].sum()))
    assert all(np.hypot(*(piece.tracks[0, -1] - piece.tracks[0, 0])) <= 4.0 + 1e-6 for piece in pieces)


def test_the_hits_scale_with_the_flux_area_and_exposure():
    hits = RadiationHits.of_flux(np.array([1000.0, 3.0]), 1024, 1024, 0.1, pixel_um=5.5)
    area_cm2 = (1024 * 5.5e-4) ** 2
    assert hits.expected == pytest.approx([1000.0 * area_cm2 * 0.1, 3.0 * area_cm2 * 0.1])


def test_the_earth_stray_light_follows_the_lambert_sphere_and_the_baffle():
    r = np.array([[7.0e6, 0.0, 0.0]] * 3)
    sun = np.array([[1.5e11, 0.0, 0.0], [0.0, 1.5e11, 0.0], [-1.5e11, 0.0, 0.0]])  # phase 0, 90, 180 deg
    ratio = EarthDisc(r).albedo_irradiance(sun, 0.3)
    full = 2.0 * 0.3 / 3.0 * (6378137.0 / 7.0e6) ** 2
    assert ratio == pytest.approx([full, full / np.pi, 0.0], abs=1e-15)
    baffle = Baffle(pst_ref=1e-7, angle_ref=np.radians(20.0), slope=3.0)
    assert baffle.pst(np.radians(40.0)) == pytest.approx(1e-7 / 8.0)
    light = StrayLight.of_earth(np.radians([20.0, 40.0]), np.full(2, full), band("V"), baffle, 5.5, 0.6)
    sun_photons = band("V").photons_zero * 10.0 ** (0.4 * 26.76)
    assert light.sky_e_per_px_s[0] == pytest.approx(1e-7 * full * sun_photons * (5.5e-6) ** 2 * 0.6)
    assert light.sky_e_per_px_s[1] == pytest.approx(light.sky_e_per_px_s[0] / 8.0)
    assert SUN_MAGNITUDE["V"] == -26.76


def test_two_image_heads_in_a_heavy_flux_identify_no_wrong_star():
    """60 s of two image heads with 300 hits cm⁻² s⁻¹ everywhere (~10 hits a frame): the hits are drawn and counted,
    no identified star is where the truth says it is not, and the filter stays consistent."""
    data = read_scenario_file(DATA / "base_spacecraft.toml")
    data["duration_s"] = 60.0
    data["pointing"].pop("offsets")
    data["star_sensor"] = [{**h, "fidelity": "image", "sun_exclusion_deg": 0.0, "image": {"render_mag_limit": 6.5}}
                           for h in data["star_sensor"]]
    data["radiation"] = {"background_per_cm2_s": 300.0}
    run = simulate(prepare(scenario_from_dict(data)), 1)
    heads = run.summary["heads"]
    assert all(h["image"]["hits"] > 200 for h in heads)
    assert sum(h["image"]["wrong_identifications"] for h in heads) == 0
    assert all(h["availability"] > 0.9 for h in heads)
    assert run.summary["nees"]["mean"] < 3.0 * 6
