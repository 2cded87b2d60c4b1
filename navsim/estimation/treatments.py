"""How a group of error states is treated by a filter: estimated, kept as consider states (Schmidt: in P
and Φ, never corrected) or left out. Each filter's configuration record (``AttitudeFilterConfig``,
``NavFilterConfig``) takes one per group, and the scenario keys that choose them offer exactly these."""

TREATMENTS = ("estimate", "consider", "ignore")
