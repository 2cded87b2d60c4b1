"""A Hipparcos star's magnitude in a sensor's band from its V and colours, through published colour tables.

Bands (Vega system): ``V`` (Johnson), ``R`` and ``I`` (Cousins R_C, I_C), ``J`` and ``H`` (2MASS).
Every band but ``I`` is read off a colour sequence as a function of the star's V - I_C (Hipparcos-2
bytes 166-171):

    m_band - V = f_band(V - I_C)                                                       (1)

linear in V - I_C between the sequence's rows, each row reproduced exactly, and held at the end row's
value outside the sequence (bluer than B1V, V - I_C < -0.325; redder than M9V, 4.66, or M5III, 3.05).
``I`` is the catalogue's own colour, I - V = -(V - I_C), at every colour.

The sequences (:data:`DWARFS`, :data:`GIANTS`):

- Dwarfs: E. Mamajek, "A Modern Mean Dwarf Stellar Color and Effective Temperature Sequence", version
  2024.05.15 (``EEM_dwarf_UBVIJHK_colors_Teff.txt`` of github.com/emamajek/SpectralType, commit 049272b),
  whose O9V-M9V part is Table 5 of Pecaut & Mamajek (2013, ApJS 208, 9): the rows B1V-M9V, the ones
  giving B-V, V-R_C, V-I_C, V-K_s, J-H, H-K_s (2MASS) and M_V. J - V = (H-K_s) + (J-H) - (V-K_s),
  H - V = (H-K_s) - (V-K_s), R - V = -(V-R_C). G1V, whose V - I_C (0.672) is below G0V's, is left out.
- Giants: Bessell & Brett (1988, PASP 100, 1134) Table III, G0III-M5III: V-I, V-K, H-K, J-K in their
  homogenized (Johnson-Glass) system, as transcribed in a public script ("INTERPOLATION OF BESSELL AND
  BRETT TABLES"; its V-I is that of the JMMC SearchCal giant table ``alxColorTableForGiantStar.cfg``,
  labelled V-I_C, but for G5 and M5, and the two V-K agree to 0.04 mag from G0 to M3, 0.12 at M4); G8III,
  whose V-I equals G5III's, is left out. To 2MASS by Carpenter (2001, AJ 121, 2851) as updated for the 2MASS All-Sky release
  (Explanatory Supplement VI.4b), K_BB = K_s + 0.044, (J-K)_BB = 1.029 (J-K_s) + 0.011,
  (H-K)_BB = 1.004 (H-K_s) - 0.028 (the coefficients of the public IDL routine ``twomass_to_bb``),
  inverted. Bluer than G0III (V - I_C < 0.81) the giant sequence is the dwarf one, and R - V of giants
  is the dwarfs' at the same V - I_C: no published giant V - R_C was found.

Why V - I_C: at the same V - I_C giants and dwarfs differ in V - K_s by at most 0.07 mag from G0 to K4
(V - I_C = 1.00: 2.29 dwarf, 2.35 giant) and in J - V by less than 0.1 mag up to M5, while at the same
B-V = 1.56 an M0III (B-V of the JMMC giant table) has V - K_s = 3.89 and a dwarf (M3-M3.5V) 4.77: B-V
saturates near 1.5 in the M types, V - I_C keeps growing. The giant sequence still matters in H for M
stars (V - I_C = 2.05, M2III: H - V = -3.83 dwarf, -4.10 giant), so :func:`band_magnitude` tells giants by the absolute
magnitude (:func:`is_giant`).

Missing colours (NaN): without V - I_C it is read off the dwarf sequence at the star's B-V (a poor
stand-in: against 2MASS it doubles the RMS below, 0.18 mag in J over 685 stars), without both the solar
V - I_C (G2V, 0.713) is used.

Measured against 2MASS (tests/startrack/test_colours.py): over 45 normal single Hipparcos stars of B-V
-0.15 to +1.57, dwarfs and giants, RMS 0.10 mag in J and 0.14 mag in H, worst 0.36 and 0.54 mag; over
all 685 Hipparcos stars of those SearchCal fields with 2MASS errors below 0.05 mag, variables and
binaries included, RMS 0.09 and 0.12 mag, worst 0.64 and 0.69 mag. The relation misrepresents stars
whose colours are not a normal single star's:

- reddened stars: no extinction is applied. With the extinction ratios of Mamajek's notes E(B-V) = 0.3
  makes a B3V star only 0.08 mag too bright in J and 0.14 mag in H (reddening moves it nearly along the
  sequence), but the worst of the 685, HIP 80371, a B5III at B-V = 0.55 in the rho Oph field, comes out
  0.64 mag too faint in J;
- M giants and supergiants redder than M5III, and Miras: the held end values make them too faint in J
  and H, the more the redder;
- carbon and S stars, Be stars (infrared excess), variables (colours and V of other epochs), binaries
  with mixed colours;
- stars with wrong catalogue colours: the worst of the 45, HIP 1321 (typed F8 V, B-V = 0.24,
  V - I_C = 0.37, but a G star's 2MASS J - H = 0.29), is 0.36 mag too faint in J.
"""

import numpy as np

from startrack.base.units import ARCSEC
from startrack.photometry.bands import band as photometric_band

#: Pecaut & Mamajek (2013) Table 5 / Mamajek v2024.05.15 rows: B-V, V-R_C, V-I_C, V-K_s, J-H, H-K_s, M_V [mag].
_MAMAJEK = np.array(
    [
        [-0.278, -0.115, -0.325, -0.874, -0.148, -0.059, -3.00],  # B1V
        [-0.252, -0.114, -0.281, -0.752, -0.132, -0.047, -2.60],  # B1.5V
        [-0.215, -0.094, -0.230, -0.602, -0.113, -0.032, -1.80],  # B2V
        [-0.198, -0.087, -0.210, -0.544, -0.105, -0.026, -1.50],  # B2.5V
        [-0.178, -0.080, -0.192, -0.492, -0.098, -0.021, -1.20],  # B3V
        [-0.165, -0.074, -0.176, -0.447, -0.092, -0.016, -1.00],  # B4V
        [-0.156, -0.070, -0.165, -0.380, -0.084, -0.010, -0.85],  # B5V
        [-0.140, -0.062, -0.145, -0.358, -0.081, -0.007, -0.55],  # B6V
        [-0.128, -0.058, -0.133, -0.325, -0.077, -0.004, -0.40],  # B7V
        [-0.109, -0.048, -0.108, -0.254, -0.067, 0.003, 0.00],  # B8V
        [-0.070, -0.028, -0.061, -0.121, -0.050, 0.016, 0.50],  # B9V
        [-0.050, -0.017, -0.035, -0.048, -0.044, 0.021, 0.60],  # B9.5V
        [0.000, 0.001, 0.004, 0.041, -0.032, 0.028, 0.99],  # A0V
        [0.035, 0.019, 0.044, 0.090, -0.025, 0.030, 1.16],  # A1V
        [0.070, 0.042, 0.091, 0.178, -0.012, 0.034, 1.35],  # A2V
        [0.100, 0.050, 0.108, 0.253, 0.003, 0.035, 1.70],  # A3V
        [0.140, 0.078, 0.164, 0.353, 0.022, 0.037, 1.94],  # A4V
        [0.160, 0.089, 0.186, 0.403, 0.031, 0.038, 2.01],  # A5V
        [0.185, 0.094, 0.197, 0.465, 0.043, 0.039, 2.12],  # A6V
        [0.210, 0.117, 0.242, 0.528, 0.055, 0.040, 2.23],  # A7V
        [0.250, 0.140, 0.288, 0.601, 0.070, 0.042, 2.32],  # A8V
        [0.270, 0.143, 0.294, 0.674, 0.086, 0.044, 2.43],  # A9V
        [0.295, 0.166, 0.339, 0.734, 0.096, 0.045, 2.57],  # F0V
        [0.330, 0.190, 0.385, 0.819, 0.117, 0.047, 2.76],  # F1V
        [0.370, 0.213, 0.432, 0.925, 0.140, 0.050, 2.97],  # F2V
        [0.390, 0.222, 0.449, 0.964, 0.148, 0.051, 3.08],  # F3V
        [0.410, 0.236, 0.476, 1.012, 0.159, 0.052, 3.20],  # F4V
        [0.440, 0.252, 0.506, 1.079, 0.173, 0.054, 3.37],  # F5V
        [0.486, 0.276, 0.553, 1.190, 0.199, 0.057, 3.69],  # F6V
        [0.500, 0.290, 0.579, 1.221, 0.213, 0.060, 3.80],  # F7V
        [0.530, 0.300, 0.599, 1.290, 0.225, 0.061, 4.05],  # F8V
        [0.560, 0.312, 0.620, 1.335, 0.236, 0.063, 4.25],  # F9V
        [0.580, 0.323, 0.640, 1.403, 0.249, 0.065, 4.35],  # F9.5V
        [0.595, 0.341, 0.673, 1.437, 0.262, 0.067, 4.48],  # G0V
        [0.622, 0.340, 0.672, 1.500, 0.279, 0.070, 4.62],  # G1V (V-I_C below G0V's: dropped, see _increasing)
        [0.650, 0.363, 0.713, 1.564, 0.293, 0.073, 4.80],  # G2V
        [0.660, 0.368, 0.722, 1.588, 0.299, 0.074, 4.87],  # G3V
        [0.670, 0.374, 0.733, 1.611, 0.304, 0.075, 4.93],  # G4V
        [0.680, 0.377, 0.738, 1.635, 0.310, 0.076, 4.98],  # G5V
        [0.700, 0.388, 0.758, 1.691, 0.324, 0.079, 5.10],  # G6V
        [0.710, 0.393, 0.766, 1.705, 0.327, 0.080, 5.20],  # G7V
        [0.730, 0.404, 0.786, 1.768, 0.342, 0.082, 5.30],  # G8V
        [0.775, 0.423, 0.820, 1.857, 0.364, 0.087, 5.55],  # G9V
        [0.816, 0.443, 0.853, 1.953, 0.387, 0.091, 5.78],  # K0V
        [0.857, 0.457, 0.879, 2.060, 0.404, 0.094, 5.95],  # K1V
        [0.884, 0.482, 0.920, 2.130, 0.427, 0.098, 6.07],  # K2V
        [0.990, 0.560, 1.030, 2.350, 0.490, 0.110, 6.53],  # K3V
        [1.090, 0.635, 1.182, 2.700, 0.539, 0.123, 6.99],  # K4V
        [1.150, 0.685, 1.272, 2.880, 0.568, 0.132, 7.28],  # K5V
        [1.240, 0.759, 1.420, 3.080, 0.601, 0.148, 7.64],  # K6V
        [1.340, 0.802, 1.519, 3.350, 0.619, 0.164, 8.20],  # K7V
        [1.363, 0.843, 1.632, 3.480, 0.626, 0.171, 8.43],  # K8V
        [1.400, 0.866, 1.699, 3.550, 0.631, 0.180, 8.56],  # K9V
        [1.420, 0.889, 1.766, 3.650, 0.627, 0.190, 8.80],  # M0V
        [1.445, 0.924, 1.886, 3.840, 0.620, 0.208, 9.20],  # M0.5V
        [1.485, 0.956, 2.005, 4.000, 0.614, 0.222, 9.64],  # M1V
        [1.495, 0.978, 2.089, 4.100, 0.608, 0.227, 9.85],  # M1.5V
        [1.505, 1.001, 2.173, 4.230, 0.600, 0.234, 10.21],  # M2V
        [1.522, 1.041, 2.306, 4.430, 0.589, 0.244, 10.61],  # M2.5V
        [1.530, 1.079, 2.420, 4.600, 0.579, 0.252, 11.15],  # M3V
        [1.600, 1.178, 2.680, 5.000, 0.558, 0.269, 12.10],  # M3.5V
        [1.650, 1.241, 2.831, 5.250, 0.557, 0.280, 12.61],  # M4V
        [1.690, 1.345, 3.073, 5.650, 0.564, 0.301, 13.58],  # M4.5V
        [1.830, 1.446, 3.278, 5.950, 0.580, 0.312, 14.15],  # M5V
        [1.940, 1.656, 3.664, 6.500, 0.588, 0.329, 15.30],  # M5.5V
        [2.010, 1.950, 4.100, 7.100, 0.605, 0.352, 16.32],  # M6V
        [2.070, 1.988, 4.260, 7.600, 0.609, 0.360, 17.10],  # M6.5V
        [2.120, 2.180, 4.500, 8.000, 0.613, 0.390, 17.70],  # M7V
        [2.140, 2.160, 4.560, 8.350, 0.650, 0.422, 18.16],  # M7.5V
        [2.150, 2.150, 4.620, 8.700, 0.677, 0.450, 18.60],  # M8V
        [2.160, 1.967, 4.630, 8.900, 0.690, 0.465, 19.20],  # M8.5V
        [2.170, 1.890, 4.660, 9.000, 0.720, 0.470, 19.40],  # M9V
    ]
)

#: Bessell & Brett (1988) Table III giants: V-I, V-K, H-K, J-K [mag], Bessell & Brett system.
_BESSELL_BRETT_GIANTS = np.array(
    [
        [0.81, 1.75, 0.065, 0.45],  # G0III
        [0.91, 2.05, 0.080, 0.55],  # G4III
        [0.94, 2.15, 0.085, 0.58],  # G5III
        [0.94, 2.16, 0.085, 0.58],  # G8III (same V-I as G5III: dropped, see _increasing)
        [1.00, 2.31, 0.095, 0.63],  # K0III
        [1.08, 2.50, 0.100, 0.68],  # K1III
        [1.17, 2.70, 0.115, 0.74],  # K2III
        [1.36, 3.00, 0.140, 0.82],  # K3III
        [1.50, 3.26, 0.150, 0.88],  # K4III
        [1.63, 3.60, 0.165, 0.95],  # K5III
        [1.78, 3.85, 0.190, 1.01],  # M0III
        [1.90, 4.05, 0.205, 1.05],  # M1III
        [2.05, 4.30, 0.215, 1.08],  # M2III
        [2.25, 4.64, 0.235, 1.13],  # M3III
        [2.55, 5.10, 0.245, 1.17],  # M4III
        [3.05, 5.96, 0.285, 1.23],  # M5III
    ]
)

#: V - I_C of the Sun [mag] (G2V row of the dwarf sequence), for stars with no colour at all.
SOLAR_V_I = 0.713
#: A parallax is good when it exceeds this many standard errors.
_PARALLAX_SNR = 5.0
#: A star with a good parallax is a giant when brighter than a dwarf of its colour by more than this
#: [mag]: half the 4.8-mag gap between K0III (M_V = 1.0, Mamajek's K0III notes) and K0V (M_V = 5.78).
_GIANT_MARGIN = 2.4


def _increasing(table, column):
    """The rows of ``table`` whose ``column`` exceeds every earlier row's: the interpolation abscissae."""
    x = table[:, column]
    return table[np.concatenate([[True], x[1:] > np.maximum.accumulate(x)[:-1]])]


def _dwarfs():
    b_v, v_r, v_i, v_k, j_h, h_k, mv = _increasing(_MAMAJEK, 2).T
    return {"v_i": v_i, "b_v": b_v, "mv": mv, "R": -v_r, "J": h_k + j_h - v_k, "H": h_k - v_k}


def _giants(dwarfs):
    v_i, v_k, h_k, j_k = _increasing(_BESSELL_BRETT_GIANTS, 0).T
    ks_v = -v_k - 0.044  # K_s = K_BB - 0.044
    giants = {"v_i": v_i, "J": ks_v + (j_k - 0.011) / 1.029, "H": ks_v + (h_k + 0.028) / 1.004}
    giants["R"] = np.interp(v_i, dwarfs["v_i"], dwarfs["R"])
    bluer = dwarfs["v_i"] < v_i[0]
    return {key: np.concatenate([dwarfs[key][bluer], giants[key]]) for key in ("v_i", "R", "J", "H")}


#: The sequences: V - I_C and, per band, m_band - V at each row [mag].
DWARFS = _dwarfs()
GIANTS = _giants(DWARFS)


def v_minus_i(b_v, v_i):
    """V - I_C [mag]: ``v_i`` where given, else from B-V through the dwarf sequence, else solar."""
    v_i = np.asarray(v_i, dtype=float)
    from_b_v = np.interp(np.asarray(b_v, dtype=float), DWARFS["b_v"], DWARFS["v_i"])
    return np.where(np.isfinite(v_i), v_i, np.where(np.isfinite(from_b_v), from_b_v, SOLAR_V_I))


def band_minus_v(band, b_v, v_i, giant=None):
    """m_band - V [mag] (eq. 1) for colours B-V and V - I_C [mag]; ``giant`` (bool array) picks the
    giant sequence, None the dwarf one for every star."""
    band = photometric_band(band).name
    colour = v_minus_i(b_v, v_i)
    if band == "V":
        return np.zeros_like(colour)
    if band == "I":
        return -colour
    dwarf = np.interp(colour, DWARFS["v_i"], DWARFS[band])
    if giant is None:
        return dwarf
    return np.where(giant, np.interp(colour, GIANTS["v_i"], GIANTS[band]), dwarf)


def is_giant(v_mag, b_v, v_i, parallax, parallax_error):
    """True for giants: a good parallax (> _PARALLAX_SNR errors) putting the star more than _GIANT_MARGIN
    [mag] above the dwarf sequence's M_V at its V - I_C (V [mag], parallax and error [rad]; no
    extinction), or no good parallax: a dwarf redder than V - I_C = 0.81 (M_V > 5.5) with a parallax
    below 5 mas (5 errors of 1 mas) is fainter than V = 12, at the catalogue's limit; bluer, the
    sequences are one."""
    parallax = np.asarray(parallax, dtype=float)
    good = parallax > _PARALLAX_SNR * np.asarray(parallax_error, dtype=float)
    absolute = np.asarray(v_mag, dtype=float) + 5.0 + 5.0 * np.log10(np.where(good, parallax, ARCSEC) / ARCSEC)
    dwarf_mv = np.interp(v_minus_i(b_v, v_i), DWARFS["v_i"], DWARFS["mv"])
    return ~good | (absolute < dwarf_mv - _GIANT_MARGIN)


def band_magnitude(band, v_mag, b_v, v_i, parallax, parallax_error):
    """m_band [mag] of stars of V, B-V, V - I_C [mag] and parallax with its error [rad] (eq. 1)."""
    giant = is_giant(v_mag, b_v, v_i, parallax, parallax_error)
    return np.asarray(v_mag, dtype=float) + band_minus_v(band, b_v, v_i, giant)
