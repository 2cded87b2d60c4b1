"""The image chain: rendering, background, detection, the position fit, stacking, image files, synthetic frames and a sensor's light budget."""
