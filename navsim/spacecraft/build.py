"""The spacecraft kind's tables in SI units: the orbit (SGP4 or the numerical propagator), the attitude law, the rigid
body with its wheels and controller, the heads (each the star sensor of :mod:`navsim.build.star_sensor` with its own
mounting, faults and the Earth's disc), and the MEKF with a mounting per head."""

import numpy as np

from navsim.attitude import build as attitude_build
from navsim.build.star_sensor import star_sensor
from navsim.earth.bodies import geocentric
from navsim.earth.frames import c_ei
from navsim.orbit.earth_disc import EarthDisc
from navsim.orbit.elements import J2, Elements, sun_synchronous_inclination
from navsim.orbit.numerical import Forces, NumericalOrbit
from navsim.orbit.radiation import ParticleFlux
from navsim.orbit.sgp4_orbit import SGP4Orbit
from navsim.scenario.star_sensor_fields import mounting
from navsim.sensors.radiation_hits import RadiationHits
from navsim.sensors.stray_light import Baffle, StrayLight
from navsim.truth.pointing import Nadir, SunPointing, Targets
from navsim.truth.spacecraft import Controller, Spacecraft, Wheels
from startrack import InputError, band, quaternion_from_radec_roll, units
from startrack import rotation as rot

#: The pyramid's wheel elevation above the body's x-y plane [rad]: atan(1/√2), the four axes equally spread.
PYRAMID_ELEVATION = np.arctan(1.0 / np.sqrt(2.0))
#: How far past the run the numerical orbit is propagated [s]: the controller's last interval may end after it.
ORBIT_MARGIN_S = 60.0
#: The wheels' momentum bias when the scenario gives none [N m s]: away from zero speed (its Coulomb flip).
DEFAULT_WHEEL_MOMENTUM = 0.5


def pole(scenario):
    """The Earth's figure axis (ITRS z) in GCRS at the epoch (3,)."""
    return c_ei(scenario["epoch_utc"], 0.0)[2]


def orbit(scenario):
    """The orbit strategy (``states(t)``) of ``scenario['orbit']``."""
    table = scenario["orbit"]
    if table["propagator"] == "sgp4":
        return SGP4Orbit(*table["tle"], scenario["epoch_utc"])
    if table.get("tle") is not None:
        r0, v0 = SGP4Orbit(*table["tle"], scenario["epoch_utc"]).states(np.array([0.0]))
        r0, v0 = r0[0], v0[0]
    elif table.get("state") is not None:
        r0, v0 = 1e3 * np.asarray(table["state"]["position_km"]), 1e3 * np.asarray(table["state"]["velocity_km_per_s"])
    else:
        r0, v0 = elements(scenario).state()
    forces = Forces(pole=tuple(pole(scenario)), j2=J2 if table["j2"] else 0.0, ballistic=table["ballistic_m2_per_kg"])
    return NumericalOrbit(tuple(map(float, r0)), tuple(map(float, v0)), scenario["duration_s"] + ORBIT_MARGIN_S, forces)


def elements(scenario):
    """The :class:`~navsim.orbit.elements.Elements` of ``scenario['orbit']['elements']``: a sun-synchronous
    inclination when asked for, the node from the local time of the ascending node (the Sun's right ascension at the
    epoch plus 15 deg per hour after noon) when given."""
    e = scenario["orbit"]["elements"]
    a = 1e3 * e["semi_major_axis_km"]
    inclination = sun_synchronous_inclination(a, e["eccentricity"]) if e["sun_synchronous"] else np.radians(e["inclination_deg"])
    if e["ltan_h"] is not None:
        sun, _ = geocentric(scenario["epoch_utc"], np.array([0.0]))
        raan = np.arctan2(sun[0, 1], sun[0, 0]) + np.radians(15.0 * (e["ltan_h"] - 12.0))
    else:
        raan = np.radians(e["raan_deg"])
    return Elements(a=a, e=e["eccentricity"], i=float(inclination), raan=float(raan % (2.0 * np.pi)),
                    argp=float(np.radians(e["argp_deg"])), nu=float(np.radians(e["true_anomaly_deg"])))


def attitude_law(scenario):
    """The attitude law (:mod:`navsim.truth.pointing`) of ``scenario['pointing']``; an InputError naming the target (or
    offset) whose slew from the one before cannot end before the next starts."""
    law = _law(scenario)
    targets = law.offsets if isinstance(law, Nadir) else law if isinstance(law, Targets) else None
    late = None if targets is None else targets.late()
    if late is not None:
        key = "targets" if isinstance(law, Targets) else "offsets"
        k = late if key == "targets" or scenario["pointing"]["offsets"][0]["start_s"] == 0.0 else late - 1
        slew = targets.slews()[late - 1]
        raise InputError(f"{scenario.source}: pointing.{key}[{k}].start_s: "
                         f"the slew that starts there takes {slew[4]:.0f} s under the rate and acceleration limits, past "
                         f"the next {key[:-1]}'s start")
    return law


def _law(scenario):
    p = scenario["pointing"]
    limits = {"max_rate": float(np.radians(p["max_rate_deg_per_s"])),
              "max_acceleration": float(np.radians(p["max_acceleration_deg_per_s2"]))}
    if p["law"] == "nadir":
        offsets = [(o["start_s"], tuple(rot.multiply(rot.from_rotation_vector(np.radians([o["roll_deg"], 0.0, 0.0])),
                                                      rot.from_rotation_vector(np.radians([0.0, o["pitch_deg"], 0.0])))))
                   for o in p["offsets"]]
        if offsets and offsets[0][0] > 0.0:
            offsets.insert(0, (0.0, (0.0, 0.0, 0.0, 1.0)))
        return Nadir(yaw=float(np.radians(p["yaw_deg"])), offsets=Targets(tuple(offsets), **limits) if offsets else None)
    if p["law"] == "sun":
        return SunPointing(axis=tuple(p["sun_axis"]), secondary=tuple(p["secondary_axis"]), yaw_steering=p["yaw_steering"])
    targets = tuple((t["start_s"], tuple(quaternion_from_radec_roll(*units.deg_to_rad([t["ra_deg"], t["dec_deg"], t["roll_deg"]]))))
                    for t in p["targets"])
    return Targets(targets=targets, **limits)


def wheel_axes(layout):
    """The spin axes (n, 3) of a wheel layout: the pyramid's four about +z, or the triad's three body axes."""
    if layout == "triad":
        return np.eye(3)
    azimuth = np.radians([45.0, 135.0, 225.0, 315.0])
    c = np.cos(PYRAMID_ELEVATION)
    return np.stack([c * np.cos(azimuth), c * np.sin(azimuth), np.full(4, np.sin(PYRAMID_ELEVATION))], axis=1)


def spacecraft(scenario):
    """(the :class:`~navsim.truth.spacecraft.Spacecraft`, the wheels' initial momenta (n,) [N m s])."""
    table = scenario["spacecraft"]
    w, c = table["wheels"], table["controller"]
    axes = wheel_axes(w["layout"])
    wheels = Wheels(axes=tuple(map(tuple, axes)), inertia=w["inertia_kg_m2"], max_torque=w["max_torque_N_m"],
                    max_momentum=w["max_momentum_N_m_s"], viscous=w["viscous_N_m_s_per_rad"], coulomb=w["coulomb_N_m"]).check()
    body = Spacecraft(inertia=tuple(map(tuple, table["inertia_kg_m2"])), wheels=wheels,
                      controller=Controller(bandwidth=c["bandwidth_rad_per_s"], damping=c["damping"], rate_hz=c["rate_hz"]),
                      gravity_gradient=table["gravity_gradient"])
    initial = w["initial_momentum_N_m_s"]
    return body, np.full(len(axes), DEFAULT_WHEEL_MOMENTUM) if initial is None else np.asarray(initial, dtype=float)


def gyro(scenario):
    """The gyro of ``scenario['gyro']`` at its rate (the attitude kind's)."""
    return attitude_build.gyro(scenario)


def head_sensor(head, star_catalog, frame_interval, epoch, lanes=()):
    """One head's sensor (:func:`navsim.build.star_sensor.star_sensor` of its table and its faults; ``lanes`` the
    run's compile-ahead lanes at image fidelity)."""
    return star_sensor({"star_sensor": head, "faults": head["faults"]}, star_catalog, frame_interval, epoch, lanes)


def stray_light(head, sky, frames):
    """The head's :class:`~navsim.sensors.stray_light.StrayLight` at the frames: its baffle against the sunlit Earth
    (``head['stray_light']``), the limb's angle from its boresight (``sky``, its :class:`HeadSky`)."""
    table = head["stray_light"]
    baffle = Baffle(pst_ref=table["pst"], angle_ref=float(np.radians(table["angle_deg"])), slope=table["slope"])
    ratio = EarthDisc(frames.r_I).albedo_irradiance(frames.sun, table["earth_albedo"])
    return StrayLight.of_earth(sky.limb_angle, ratio, band(head["band"]), baffle, table["pixel_um"], table["qe"])


def particle_flux(scenario):
    """The :class:`~navsim.orbit.radiation.ParticleFlux` of ``scenario['radiation']``, or None."""
    r = scenario.data.get("radiation")
    if r is None:
        return None
    return ParticleFlux(background=r["background_per_cm2_s"], saa_peak=r["saa_peak_per_cm2_s"], saa_lat_deg=r["saa_lat_deg"],
                        saa_lon_deg=r["saa_lon_deg"], saa_lat_width_deg=r["saa_lat_width_deg"],
                        saa_lon_width_deg=r["saa_lon_width_deg"], saa_height_m=1e3 * r["saa_height_km"],
                        saa_height_exponent=r["saa_height_exponent"], horn_peak=r["horn_peak_per_cm2_s"],
                        horn_lat_deg=r["horn_lat_deg"], horn_width_deg=r["horn_width_deg"])


def radiation_hits(scenario, head, frames):
    """The head's :class:`~navsim.sensors.radiation_hits.RadiationHits` in the orbit's flux at the frames (its detector
    of the image table's size, exposure and the stray-light table's pixel pitch), or None without radiation."""
    flux = particle_flux(scenario)
    if flux is None:
        return None
    r, image = scenario["radiation"], head["image"]
    return RadiationHits.of_flux(flux.flux(*frames.geodetic), image["width_px"], image["height_px"], image["exposure_s"],
                                 thickness_um=r["thickness_um"], pixel_um=head["stray_light"]["pixel_um"],
                                 electrons_per_um=r["electrons_per_um"], spread=r["spread"])


def mountings(scenario):
    """(nominal q_BS (H, 4), true q_BS (H, 4)) of the heads."""
    pairs = [mounting(head) for head in scenario["star_sensor"]]
    return np.array([p[0] for p in pairs]), np.array([p[1] for p in pairs])


def filter_config(scenario, gyro):
    """The MEKF of ``scenario['filter']`` (the attitude kind's) with one nominal mounting per head, each treated as its
    ``filter_mounting`` says (default ``filter.mounting``) with the initial σ of its drawn mounting error
    (``misalignment_sigma_arcsec``; without one ``filter.initial_mounting_sigma_arcsec``)."""
    heads = scenario["star_sensor"]
    treatments = [head["filter_mounting"] or scenario["filter"]["mounting"] for head in heads]
    sigmas = [head["misalignment_sigma_arcsec"] or scenario["filter"]["initial_mounting_sigma_arcsec"] for head in heads]
    return attitude_build.filter_config(scenario, gyro, mountings(scenario)[0], treatments, sigmas)
