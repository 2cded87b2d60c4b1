"""The strapdown inertial navigation system: the compiled NED mechanization
(:mod:`navsim.ins.strapdown`) and the small drivers that run it with sensors and aiding
(:mod:`navsim.ins.driver`)."""
