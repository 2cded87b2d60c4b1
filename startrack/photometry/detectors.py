"""Detector presets of star sensors: quantum efficiency against wavelength, read noise, dark current, full well.

Two families a star sensor is built on (representative values, to be replaced by a datasheet's: every
field of a preset can be overridden in a scenario):

- ``silicon_cmos`` — a front-illuminated global-shutter CMOS of 3-6 µm pixels such as the Sony IMX265 of
  the real night-sky frames of the tests (``tests/data/realsky``; EMVA 1288 data of such cameras: peak QE 0.6-0.75 near
  530 nm falling to ~0.2 at 900 nm and 0 beyond 1.1 µm; temporal dark noise 2-3 e⁻; saturation 10-11 ke⁻;
  dark current a few e⁻ s⁻¹ at room temperature); read noise 3 e⁻, dark 10 e⁻ s⁻¹, full well 10 500 e⁻.
- ``ingaas_swir`` — a thermoelectrically cooled InGaAs array of 15 µm pixels for 0.9-1.7 µm (QE 0.7-0.85
  over 1.0-1.6 µm, cut off at 1.7 µm by the lattice-matched In0.53Ga0.47As; dark current density
  ~5 nA cm⁻² at 20 °C, halving every ~7 K: ~5000 e⁻ s⁻¹ in a 15 µm pixel near −20 °C); read noise 50 e⁻
  (low-gain, large-well mode), full well 500 000 e⁻.
"""

from dataclasses import dataclass, replace

import numpy as np

from startrack.base.errors import InputError


@dataclass(frozen=True)
class Detector:
    """A detector: QE sampled at ``wavelengths`` [m] (linear between samples, 0 outside), read noise [e⁻],
    dark current [e⁻ s⁻¹ px⁻¹], full well [e⁻], pixel pitch [m]."""

    name: str
    wavelengths: tuple
    qe_samples: tuple
    read_noise_e: float
    dark_e_per_px_s: float
    full_well_e: float
    pixel_pitch: float

    def qe(self, wavelength):
        """Quantum efficiency at ``wavelength`` [m] (0 outside the sampled range)."""
        return float(np.interp(wavelength, self.wavelengths, self.qe_samples, left=0.0, right=0.0))

    def with_overrides(self, **values):
        """This detector with the given fields replaced (``qe`` a constant QE over its sampled range)."""
        qe = values.pop("qe", None)
        unknown = sorted(set(values) - {"read_noise_e", "dark_e_per_px_s", "full_well_e", "pixel_pitch"})
        if unknown:
            raise InputError(f"detector {self.name}: unknown value(s) {', '.join(unknown)}")
        detector = replace(self, **{key: float(value) for key, value in values.items()})
        if qe is not None:
            detector = replace(detector, qe_samples=tuple(float(qe) for _ in self.wavelengths))
        return detector


_UM = 1e-6

#: The detector presets (module docstring).
DETECTORS = {
    "silicon_cmos": Detector(
        "silicon_cmos",
        wavelengths=tuple(w * _UM for w in (0.35, 0.40, 0.45, 0.50, 0.55, 0.60, 0.65, 0.70, 0.80, 0.90, 1.00, 1.10)),
        qe_samples=(0.20, 0.45, 0.62, 0.70, 0.70, 0.64, 0.55, 0.46, 0.32, 0.18, 0.06, 0.0),
        read_noise_e=3.0, dark_e_per_px_s=10.0, full_well_e=10500.0, pixel_pitch=3.45 * _UM),
    "ingaas_swir": Detector(
        "ingaas_swir",
        wavelengths=tuple(w * _UM for w in (0.85, 0.90, 1.00, 1.10, 1.20, 1.30, 1.40, 1.50, 1.60, 1.65, 1.70, 1.75)),
        qe_samples=(0.0, 0.45, 0.70, 0.78, 0.80, 0.82, 0.83, 0.83, 0.80, 0.72, 0.40, 0.0),
        read_noise_e=50.0, dark_e_per_px_s=5000.0, full_well_e=500000.0, pixel_pitch=15.0 * _UM),
}


def detector(name):
    """The :class:`Detector` preset called ``name``; InputError naming the known ones otherwise."""
    try:
        return DETECTORS[name]
    except (KeyError, TypeError):
        raise InputError(f"unknown detector preset {name!r}; choose from {', '.join(DETECTORS)}") from None
