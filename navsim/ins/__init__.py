"""The strapdown inertial navigation system: the compiled NED mechanization (:mod:`navsim.ins.strapdown`).
Navigation runs, their series and summaries are the navigation kind's (:mod:`navsim.navigation`)."""
