"""The camera: its model, its file, FITS WCS, the compiled projection kernels and the least-squares fit."""
