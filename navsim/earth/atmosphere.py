"""The air above an observer: pressure and temperature of the U.S. Standard Atmosphere 1976, the extinction
of starlight in a band by the air above the observer's height, and the airmass of a curved atmosphere.

**Standard atmosphere** (COESA 1976, Table 4's seven layers of constant lapse rate in geopotential height
H = r0 h / (r0 + h), r0 = 6 356 766 m): T = T_b + L (H − H_b), p = p_b (T_b / T)^(g0 M / (R* L)), or
p = p_b exp(−g0 M (H − H_b) / (R* T_b)) where L = 0 (eq. 33a-b); above 84.852 km the last layer's
exponential goes on.

**Extinction** k [mag per airmass] in a band of centre λ for an observer at height h, the components of
Schaefer (1998, VISLIMIT.BAS lines 1150-1200; Schaefer 1993 §3) with their heights made physical:

    k_R = 0.1066 (λ/0.55 µm)⁻⁴ p(h)/p0                              Rayleigh, ∝ the air above (1)
    k_A = 1.086 τ_550 (λ/0.55 µm)^(−α) e^(−h/H_a)                    boundary-layer aerosol   (2)
    k_S = 1.086 τ_S (λ/0.55 µm)⁻¹·³ s(h)                             stratospheric aerosol    (3)
    k_O = OZ(band) o(h),  k_W = WT(band) 0.94 RH e^(T/15 °C) e^(−h/2000 m)   ozone and water vapour (4)

Schaefer's Rayleigh term falls as e^(−h/8200 m); (1) takes the pressure itself (at 12 km e^(−h/8200)
overstates the air above by 20 %).

**The boundary-layer aerosol** (2) is a stated model in place of Schaefer's humidity fit: an optical depth
τ_a(λ) = τ_550 (λ/0.55 µm)^(−α) (Ångström 1929; α = 1.3 his continental mean, the default) in an exponential layer
of scale height H_a = 1.5 km, so k_A = 2.5 log10(e) τ_a = 1.086 τ_a of the air above the observer. τ_550 is given
(:class:`Aerosol`) or follows from the ground's visibility V by Koschmieder's law (β_ext V = −ln 0.02 = 3.912 for
the 2 % contrast threshold; Middleton 1952): the aerosol's extinction coefficient at the ground is the total
3.912/V less the molecules' β_R = τ_R(550)/H_R (0.0116 km⁻¹ at sea level), and τ_550 = (3.912/V − β_R) H_a
(:meth:`Aerosol.from_visibility`; none for V ≥ 336 km, the molecules' own visibility). The default, V = 38 km,
is τ_550 = 0.137: Schaefer's 0.1 (1 − 0.32/ln RH)^1.33 at his 40 % humidity, the model's earlier aerosol, so
the default air is unchanged; 23 km (MODTRAN's "clear") gives τ_550 = 0.24, 5 km (haze) 1.16. The humidity now
sets only the water vapour (the visibility carries the aerosol's swelling). Schaefer's seasonal aerosol factor
is left out (no date/latitude climate).
(3) is the volcanically quiet stratosphere's background aerosol, τ_S = 0.005 at 550 nm (SAGE II's 525 nm
optical depth rose from about 0.004 to 0.008 over 2000-2010: Vernier et al. 2011), spread evenly between the
tropopause (12 km) and 30 km (s(h) the fraction above h): nothing next to the boundary layer on the ground,
but what scatters most above it. OZ and WT are Schaefer's UBVRI values (V 0.031 and
0.031; his Johnson R at 0.70 µm 0.008 and 0.020, I at 0.90 µm 0 and 0.015) interpolated in λ to the
bands' centres; most of the ozone column lies between 15 and 35 km (o(h) = 1 below 10 km, 0 above
40 km, linear between); water vapour falls with its own ~2 km scale height (Schaefer's 8.2 km keeps a
quarter of the sea-level water at 12 km where there is a few thousandths). In J and H the water vapour
of the band edges dominates; Schaefer gives no values there, and WT(J) = 0.12, WT(H) = 0.06 are this
module's assumption, for totals of 0.18 and 0.10 mag per airmass at sea level (0.02 and 0.01 at 4.2 km,
where measured J and H extinctions are several times larger: the band edges' saturated water lines do
not fall with the column as the linear law has them) -- uncertain by a factor 2, and 0.1 mag or less of a
star's light at any height but the lowest elevations.

**Airmass** of each component (relative to the zenith, from the observer's height): the Chapman function of
an exponential layer of scale height H_j seen from radius r = R + h, Ch(r/H, z) ≈ √(πx/2) erfcx(√(x/2) cos z)
(x = r/H; the leading term of its asymptotic expansion, Smith & Smith 1972, times x/(x − 1), its
zenith value's correction: within 0.1 % of the path integral's quadrature from the zenith to 3° below
the horizontal for the molecular layer, tested), and for a line of sight below the observer's horizontal plane (z > 90°, seen from altitude)
2 √(πx sin z/2) e^(x (1 − sin z)) − Ch(x, 180° − z) (the path down to its tangent point and up again);
thin shells (ozone, stratospheric aerosol) by the secant through a sphere of radius R + h_layer. Lines of
sight that meet the ground (tangent radius below R) see no star.
"""

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.special import erfcx

from startrack import InputError

#: The Earth's mean radius [m] for the atmosphere's curvature (the ellipsoid's flattening is below its accuracy).
EARTH_RADIUS = 6371000.0
#: COESA 1976: g0 M / R* [K/m], the radius r0 of the geopotential height [m].
G0_M_OVER_R = 9.80665 * 0.0289644 / 8.3144598
R0_GEOPOTENTIAL = 6356766.0
#: (base geopotential height [m], base temperature [K], lapse rate [K/m], base pressure [Pa]) of its layers.
LAYERS = ((0.0, 288.15, -0.0065, 101325.0), (11000.0, 216.65, 0.0, 22632.06), (20000.0, 216.65, 0.001, 5474.889),
          (32000.0, 228.65, 0.0028, 868.0187), (47000.0, 270.65, 0.0, 110.9063), (51000.0, 270.65, -0.0028, 66.93887),
          (71000.0, 214.65, -0.002, 3.956420), (84852.0, 186.87, 0.0, 0.3734))
SEA_LEVEL_PRESSURE = LAYERS[0][3]

#: Scale heights [m] of the boundary-layer aerosol and water vapour; the shells' heights [m].
AEROSOL_SCALE_HEIGHT = 1500.0
WATER_SCALE_HEIGHT = 2000.0
OZONE_SHELL_HEIGHT = 22000.0
STRATOSPHERIC_AEROSOL_SHELL_HEIGHT = 20000.0
#: Koschmieder's constant −ln 0.02: the visibility V [m] of a black target in air of extinction coefficient β [1/m]
#: is 3.912/β; the default visibility [km] (τ_550 = 0.137, Schaefer's aerosol at 40 % humidity) and Ångström exponent.
KOSCHMIEDER = 3.912
DEFAULT_VISIBILITY_KM = 38.0
DEFAULT_ANGSTROM_EXPONENT = 1.3
#: k [mag] = MAG_PER_OPTICAL_DEPTH τ: 2.5 log10(e).
MAG_PER_OPTICAL_DEPTH = 2.5 * np.log10(np.e)
#: Schaefer's sea-level Rayleigh extinction at 0.55 µm [mag per airmass] (VISLIMIT.BAS line 1160).
RAYLEIGH_550 = 0.1066
#: Background stratospheric aerosol optical depth at 550 nm and the layer it fills [m].
STRATOSPHERIC_AEROSOL_DEPTH = 0.005
STRATOSPHERIC_AEROSOL_LAYER = (12000.0, 30000.0)
#: Schaefer's ozone and water coefficients [mag/airmass] at his band centres [µm], and ours in J and H.
_SCHAEFER_CENTRES = (0.55, 0.70, 0.90)
_SCHAEFER_OZONE = (0.031, 0.008, 0.0)
_SCHAEFER_WATER = (0.031, 0.020, 0.015)
_INFRARED_WATER = {"J": 0.12, "H": 0.06}


def geopotential_height(h):
    """H = r0 h / (r0 + h) [m] of a geometric height h [m] (COESA 1976 eq. 18)."""
    h = np.asarray(h, dtype=float)
    return R0_GEOPOTENTIAL * h / (R0_GEOPOTENTIAL + h)


def temperature_pressure(h):
    """(T [K], p [Pa]) of the U.S. Standard Atmosphere 1976 at geometric height h [m] (module docstring)."""
    H = np.atleast_1d(geopotential_height(np.maximum(h, -1000.0)))
    base = np.array(LAYERS)
    layer = np.clip(np.searchsorted(base[:, 0], H, side="right") - 1, 0, len(LAYERS) - 1)
    Hb, Tb, L, pb = (base[layer, k] for k in range(4))
    T = Tb + L * (H - Hb)
    flat = L == 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        p = np.where(flat, pb * np.exp(-G0_M_OVER_R * (H - Hb) / Tb), pb * (Tb / T) ** (G0_M_OVER_R / np.where(flat, 1.0, L)))
    shape = np.shape(h)
    return T.reshape(shape), p.reshape(shape)


def pressure_scale_height(h):
    """R* T / (g0 M) [m] at height h [m]: the molecular layer's scale height there."""
    return temperature_pressure(h)[0] / G0_M_OVER_R


@dataclass(frozen=True)
class Extinction:
    """The extinction components [mag per airmass] of a band for an observer at height ``h`` [m] (eq. 1-4):
    Rayleigh, boundary-layer aerosol, stratospheric aerosol, ozone and water vapour."""

    h: np.ndarray
    rayleigh: np.ndarray
    aerosol: np.ndarray
    stratospheric: np.ndarray
    ozone: np.ndarray
    water: np.ndarray

    @property
    def total(self):
        """k [mag per zenith airmass]: every component."""
        return self.rayleigh + self.aerosol + self.stratospheric + self.ozone + self.water

    @property
    def scattering(self):
        """The part of k that scatters light into the sky (molecules and aerosols; ozone and water absorb)."""
        return self.rayleigh + self.aerosol + self.stratospheric

    def at(self, index):
        """The components at ``index`` of their per-observer arrays (one observer per line of sight, say)."""
        return Extinction(*(np.asarray(getattr(self, f.name))[index] for f in dataclasses.fields(self)))

    def along(self, zenith_distance):
        """The extinction [mag] along lines of sight at ``zenith_distance`` [rad] (broadcast with ``h``):
        each component times its own airmass; +inf where the line of sight meets the ground."""
        z, h = np.broadcast_arrays(np.asarray(zenith_distance, dtype=float), self.h)
        r = EARTH_RADIUS + h
        total = (self.rayleigh * chapman(r / pressure_scale_height(h), z)
                 + self.aerosol * chapman(r / AEROSOL_SCALE_HEIGHT, z)
                 + self.water * chapman(r / WATER_SCALE_HEIGHT, z)
                 + self.ozone * shell_airmass(h, OZONE_SHELL_HEIGHT, z)
                 + self.stratospheric * shell_airmass(h, STRATOSPHERIC_AEROSOL_SHELL_HEIGHT, z))
        return np.where(meets_ground(h, z), np.inf, total)


@dataclass(frozen=True)
class Aerosol:
    """The boundary-layer aerosol (module docstring, eq. 2): optical depth at 550 nm from sea level and Ångström
    exponent α of τ_a(λ) = τ_550 (λ/0.55 µm)^(−α)."""

    optical_depth_550: float = 0.0
    angstrom_exponent: float = DEFAULT_ANGSTROM_EXPONENT

    def __post_init__(self):
        if not np.isfinite(self.optical_depth_550) or self.optical_depth_550 < 0.0:
            raise InputError(f"aerosol optical depth {self.optical_depth_550!r}: must be 0 or more")
        if not np.isfinite(self.angstrom_exponent):
            raise InputError(f"Ångström exponent {self.angstrom_exponent!r}: must be a finite number")

    @classmethod
    def from_visibility(cls, visibility_km=DEFAULT_VISIBILITY_KM, angstrom_exponent=DEFAULT_ANGSTROM_EXPONENT):
        """The aerosol of a ground visibility [km] by Koschmieder's law: τ_550 = (3.912/V − β_R) H_a with β_R the
        molecules' extinction coefficient at 550 nm at sea level (module docstring)."""
        if not np.isfinite(visibility_km) or visibility_km <= 0.0:
            raise InputError(f"visibility {visibility_km!r} km: must be more than 0")
        beta_rayleigh = RAYLEIGH_550 / MAG_PER_OPTICAL_DEPTH / float(pressure_scale_height(0.0))
        beta_aerosol = max(KOSCHMIEDER / (1000.0 * visibility_km) - beta_rayleigh, 0.0)
        return cls(beta_aerosol * AEROSOL_SCALE_HEIGHT, angstrom_exponent)

    @classmethod
    def of_site(cls, visibility_km=DEFAULT_VISIBILITY_KM, optical_depth_550=None,
                angstrom_exponent=DEFAULT_ANGSTROM_EXPONENT):
        """The aerosol of a site: its optical depth where given, else its visibility's."""
        if optical_depth_550 is None:
            return cls.from_visibility(visibility_km, angstrom_exponent)
        return cls(float(optical_depth_550), angstrom_exponent)

    def optical_depth(self, wavelength_um):
        """τ_a(λ) = τ_550 (λ/0.55 µm)^(−α) of the whole layer (Ångström's law)."""
        return self.optical_depth_550 * (np.asarray(wavelength_um, dtype=float) / 0.55) ** -self.angstrom_exponent


def extinction(band, h, relative_humidity=0.4, temperature_c=15.0, aerosol=None):
    """The :class:`Extinction` of ``band`` (a :class:`startrack.photometry.bands.Band`) for observers at heights ``h``
    [m], the ground air's relative humidity (0-1) and temperature [°C] (Schaefer's defaults 40 %, 15 °C; they set
    the water vapour) and its :class:`Aerosol` (default: the visibility of 38 km)."""
    h = np.asarray(h, dtype=float)
    aerosol = Aerosol.from_visibility() if aerosol is None else aerosol
    x = band.centre_um / 0.55
    _, p = temperature_pressure(h)
    low, high = STRATOSPHERIC_AEROSOL_LAYER
    strat_above = np.clip((high - h) / (high - low), 0.0, 1.0)
    ozone_above = np.clip((40000.0 - h) / 30000.0, 0.0, 1.0)
    water = _INFRARED_WATER.get(band.name, np.interp(band.centre_um, _SCHAEFER_CENTRES, _SCHAEFER_WATER))
    return Extinction(
        h=h,
        rayleigh=RAYLEIGH_550 * x**-4 * p / SEA_LEVEL_PRESSURE,
        aerosol=MAG_PER_OPTICAL_DEPTH * aerosol.optical_depth(band.centre_um) * np.exp(-h / AEROSOL_SCALE_HEIGHT),
        stratospheric=1.086 * STRATOSPHERIC_AEROSOL_DEPTH * x**-1.3 * strat_above,
        ozone=np.interp(band.centre_um, _SCHAEFER_CENTRES, _SCHAEFER_OZONE) * ozone_above,
        water=water * 0.94 * relative_humidity * np.exp(temperature_c / 15.0) * np.exp(-h / WATER_SCALE_HEIGHT),
    )


def chapman(x, z):
    """Ch(x, z): the airmass relative to the zenith of an exponential layer of scale height H seen from radius
    r (x = r/H) at zenith distance z [rad] (module docstring; z > 90° passes below the observer)."""
    x, z = (np.array(v, dtype=float) for v in np.broadcast_arrays(x, z))
    cos_z, sin_z = np.cos(z), np.sin(z)
    above = np.sqrt(0.5 * np.pi * x) * erfcx(np.sqrt(0.5 * x) * np.abs(cos_z))
    low = cos_z < 0.0
    ch = np.atleast_1d(above)
    ch[np.atleast_1d(low)] = (2.0 * np.sqrt(0.5 * np.pi * x[low] * sin_z[low]) * np.exp(x[low] * (1.0 - sin_z[low]))
                              - above[low])
    return (ch * x / (x - 1.0)).reshape(x.shape)


def shell_airmass(h, shell_height, z):
    """The secant through a thin shell at ``shell_height`` [m] seen from height h [m] at zenith distance z [rad]
    (Schaefer 1998's ozone airmass, from any height; a shell below the observer counts once, 1 km above it)."""
    r = EARTH_RADIUS + np.asarray(h, dtype=float)
    shell = EARTH_RADIUS + np.maximum(shell_height, np.asarray(h, dtype=float) + 1000.0)
    return 1.0 / np.sqrt(np.maximum(1.0 - (r / shell * np.sin(z)) ** 2, 1e-12))


def meets_ground(h, z):
    """True where the straight line of sight from height h [m] at zenith distance z [rad] meets the ground."""
    r = EARTH_RADIUS + np.asarray(h, dtype=float)
    return (np.cos(z) < 0.0) & (r * np.sin(z) < EARTH_RADIUS)

