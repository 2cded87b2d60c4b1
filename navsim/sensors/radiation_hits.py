"""Particle hits on a star sensor's detector (issue 51): transient bright pixels and short tracks where protons and
electrons cross the silicon, at the rate the orbit's flux sets (:mod:`navsim.orbit.radiation`).

Per frame f the hits are Poisson of mean Φ_f A T (the flux [cm⁻² s⁻¹], the detector's area, the exposure). Each
crosses the sensitive layer of thickness t at an incidence θ drawn from the cosine law of an isotropic flux through a
plane (cos θ = √U) and an azimuth uniform in [0, 2π): its track on the pixels is t tan θ / p long (p the pixel
pitch), from a uniform point; it leaves Q = q t / cos θ electrons (q per µm of path: ~80 e⁻/µm for a minimum-ionising
particle, several hundred for the tens of MeV of the anomaly's protons), spread by a log-normal of σ ``spread`` (a
stand-in for the Landau tail; its mean kept), along the track (:func:`startrack.image.render.cosmic_ray`, no optics).
"""

from dataclasses import dataclass

import numpy as np

from startrack import cosmic_ray


@dataclass(frozen=True)
class RadiationHits:
    """The hits of a detector along a run: ``expected`` (F,) the mean hits per frame, the sensitive layer's
    ``thickness_um``, the ``pixel_um`` pitch, ``electrons_per_um`` of path and the charge's log-normal ``spread``."""

    expected: np.ndarray
    thickness_um: float = 10.0
    pixel_um: float = 5.5
    electrons_per_um: float = 300.0
    spread: float = 0.5

    @classmethod
    def of_flux(cls, flux, width_px, height_px, exposure_s, **detector):
        """The hits of a detector of ``width_px`` x ``height_px`` pixels (of ``detector['pixel_um']``) in the flux
        (F,) [cm⁻² s⁻¹] of each frame over ``exposure_s`` [s]."""
        pixel_cm = 1e-4 * detector.get("pixel_um", cls.pixel_um)
        return cls(expected=np.asarray(flux, dtype=float) * width_px * height_px * pixel_cm**2 * exposure_s, **detector)

    def draw(self, frame, rng, width_px, height_px):
        """The hits of frame ``frame`` drawn from ``rng`` (module docstring): (start u, v (N,) [px], track du, dv (N,)
        [px], charge (N,) [e⁻])."""
        count = int(rng.poisson(self.expected[frame]))
        cos_theta = np.sqrt(rng.uniform(size=count))
        azimuth = rng.uniform(0.0, 2.0 * np.pi, count)
        length = np.minimum(self.thickness_um * np.sqrt(1.0 - cos_theta**2) / cos_theta / self.pixel_um,
                            np.hypot(width_px, height_px))
        u0, v0 = rng.uniform(0.0, width_px - 1.0, count), rng.uniform(0.0, height_px - 1.0, count)
        charge = (self.electrons_per_um * self.thickness_um / cos_theta
                  * np.exp(self.spread * rng.standard_normal(count) - 0.5 * self.spread**2))
        return u0, v0, length * np.cos(azimuth), length * np.sin(azimuth), charge

    @staticmethod
    def sources(hits):
        """The drawn ``hits`` (:meth:`draw`) as render sources, each track in pieces of at most :data:`PIECE_PX`."""
        return tuple(piece for hit in zip(*hits) for piece in _pieces(*hit))


#: The longest piece of a track drawn as one source [px] (the renderer draws a source on the square around it).
PIECE_PX = 4.0


def _pieces(u, v, du, dv, charge):
    """A track from (u, v) by (du, dv) as consecutive pieces of at most :data:`PIECE_PX`, the charge shared by length."""
    n = max(1, int(np.ceil(np.hypot(du, dv) / PIECE_PX)))
    return [cosmic_ray(u + k * du / n, v + k * dv / n, u + (k + 1) * du / n, v + (k + 1) * dv / n, charge / n)
            for k in range(n)]
