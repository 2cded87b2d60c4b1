"""Light: photometric bands, detector presets, colours, a star's signal and the detection limits of 004."""
