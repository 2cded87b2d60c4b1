"""Truth motion: prescribed attitude profiles and rigid-body dynamics (:mod:`navsim.truth.profiles`)."""
