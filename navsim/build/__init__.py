"""From the tables both run kinds share to model objects in SI units, built once per scenario: the
inertial sensors' datasheets (:mod:`navsim.build.inertial`), the star sensor at vector or image fidelity
with its per-frame observers (:mod:`navsim.build.star_sensor`) and the faults (:mod:`navsim.build.faults`).
Each kind's own tables are built by its package (``navsim.attitude.build``, ``navsim.navigation.build``).
"""
