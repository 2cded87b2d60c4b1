"""The strapdown inertial navigation system: the compiled NED mechanization (:mod:`navsim.ins.strapdown`)
and the navigation runs of a scenario with a ``[trajectory]`` table through the closed loop
(:mod:`navsim.ins.simulation`, their series and summary: :mod:`navsim.ins.summary`)."""
