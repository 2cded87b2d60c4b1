"""A spacecraft's orbit about the Earth, and what it sees from there (issue 51): Keplerian elements and states
(:mod:`navsim.orbit.elements`), the numerical two-body + J2 (+ drag) propagator (:mod:`navsim.orbit.numerical`),
SGP4 from a two-line element set with TEME -> GCRS (:mod:`navsim.orbit.sgp4_orbit`), the Earth's shadow
(:mod:`navsim.orbit.eclipse`) and the Earth's disc and limb seen from the orbit (:mod:`navsim.orbit.earth_disc`).

Positions and velocities are geocentric, in GCRS axes (the star catalog's ICRS axes at the geocentre) [m, m/s];
times are seconds after the scenario's UTC epoch (``epoch_utc``), as every run has them. An orbit is a strategy
object with one method, ``states(t) -> (r (N, 3), v (N, 3))``, seed-free like the rest of the truth.
"""
