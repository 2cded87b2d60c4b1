"""Replays of a recorded IMU (``navsim replay``): a real log through the strapdown mechanization and the navigation
filter, aided by the recording's GNSS fixes outside simulated outages, its error measured against the fixes held out.

Its modules: ``recording`` (the IMU log, its time tags and gaps), ``fixes`` (the GNSS solution), ``outages`` (the
windows held out), ``alignment`` (mounting, levelling, heading), ``scenario`` (the replay file), ``run`` (the filter
over the recording), ``summary`` (the errors by outage) and ``output`` (the run directory).
"""
