"""Named star sensors of a navigation scenario (``star_sensor.preset``): the optics, detector, band and exposure of
a representative design as a bundle of the star sensor's keys, each of which the scenario may still set itself.

- ``swir_day_3deg`` — a narrow-field short-wave infrared sensor for daytime flight (issue 30): H band, an InGaAs
  array of 640 x 512 pixels of 15 µm (``startrack.photometry.detectors``' ``ingaas_swir``), 100 mm aperture and a 3° field
  (focal length 183 mm, f/1.8), 10 ms exposures, its catalog to H = 7. At 12 km with the Sun 34-50° up and 80° away
  it reaches H 4.4 against an H sky of 9.1-9.2 mag/arcsec² (``scenarios/sins_cns_aircraft_day.toml``).
- ``swir_day_1deg`` — the same array behind a 150 mm aperture at a 1° field (focal length 550 mm, f/3.7), the
  field of the aircraft astro-inertial trackers (the B-2's NAS-26: 40'), 10 ms: 2.2 times the aperture on a sky
  9 times fainter per pixel, at the price of fewer stars per field.
- ``nir_day_2deg`` — the silicon near-infrared design of Liu, Zhao & Xu (2019, Table 2; docs/references.md): 41 mm
  aperture, 2° field, f = 161.1 mm, 512 x 512 pixels of 11 µm, 800-1100 nm (our I_C band), QE 0.40, full well
  120 000 e⁻, 10 ms; read noise and dark current are not stated there (the silicon preset's).

A preset fills only the keys the scenario leaves unset (:func:`with_preset`), so ``--set`` and the file's own
keys win; the checked scenario keeps the preset's name beside the values it gave.
"""

from startrack import InputError

#: The presets (module docstring): the star sensor's keys they set, tables as dictionaries.
PRESETS = {
    "swir_day_3deg": {
        "fov_deg": 3.0, "band": "H", "mag_limit": 7.0,
        "image": {"width_px": 640, "height_px": 512, "exposure_s": 0.01},
        "photometry": {"aperture_mm": 100.0, "detector": "ingaas_swir"},
    },
    "swir_day_1deg": {
        "fov_deg": 1.0, "band": "H", "mag_limit": 8.0,
        "image": {"width_px": 640, "height_px": 512, "exposure_s": 0.01},
        "photometry": {"aperture_mm": 150.0, "detector": "ingaas_swir"},
    },
    "nir_day_2deg": {
        "fov_deg": 2.0, "band": "I", "mag_limit": 7.0,
        "image": {"width_px": 512, "height_px": 512, "exposure_s": 0.01},
        "photometry": {"aperture_mm": 41.0, "detector": "silicon_cmos", "qe": 0.40, "full_well_e": 120000.0},
    },
}


def with_preset(sensor, source):
    """The star-sensor table ``sensor`` (a dictionary, unchecked) with its ``preset``'s keys filled in where it sets
    none of its own (a table merged key by key); unchanged without a preset. InputError for an unknown name."""
    name = sensor.get("preset") if isinstance(sensor, dict) else None
    if name is None:
        return sensor
    if name not in PRESETS:
        raise InputError(f"{source}: star_sensor.preset: unknown preset {name!r}; choose from {', '.join(PRESETS)}")
    merged = dict(sensor)
    for key, value in PRESETS[name].items():
        own = merged.get(key)
        if isinstance(value, dict) and isinstance(own, dict):
            merged[key] = {**value, **own}
        elif own is None:
            merged[key] = dict(value) if isinstance(value, dict) else value
    return merged
