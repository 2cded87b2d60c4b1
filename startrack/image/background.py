"""Background and noise of a frame: one robust level for the whole frame, or a mesh that follows
vignetting, sky gradients and nebulosity (SExtractor's background map, Bertin & Arnouts 1996 §3.1).

Global (:func:`estimate_background`): iterated 3-sigma-clipped mean and standard deviation of a regular
subsample, started from the median and 1.4826 MAD.

Mesh (:func:`mesh_background`): the frame is cut into square cells of ``cell_px`` (a remainder of half a cell
or more is a last, smaller cell, a smaller one joins the last cell); in each cell a regular subsample (at most
256 pixels, or as many as the caller asks: the level's error is ~σ_n/√k for k of them) gives a clipped level
and noise as above, computed for all cells at once. A cell whose level lies more than 3 sigma from the median
of its 3 x 3 cells, or whose noise is over twice theirs (a bright star or a cluster filling it), takes those
medians (SExtractor's filter with its threshold, so that a smooth gradient -- vignetting -- is kept to the
edges); the cell values are interpolated bilinearly between cell centres to every pixel, linearly extrapolated
beyond the outer centres.
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage
from scipy.special import ndtr

#: Pixels used for the global estimate (regular subsample of the frame).
_GLOBAL_SAMPLE = 16384
#: Pixels per cell used for a mesh estimate by default (regular subsample of the cell).
CELL_SAMPLE = 256
#: 1.4826 * MAD is sigma for a normal law.
_MAD_TO_SIGMA = 1.482602218505602


def _truncation(clip):
    """Standard deviation of a unit normal law truncated at +-clip (divides a clipped standard deviation)."""
    density = np.exp(-0.5 * clip * clip) / np.sqrt(2.0 * np.pi)
    return float(np.sqrt(1.0 - 2.0 * clip * density / (2.0 * ndtr(clip) - 1.0)))


def _clipped_level(samples, clip=3.0, iterations=5):
    """(level, sigma) (m,) of each row of ``samples`` (m, k) [DN]: median and 1.4826 MAD (the standard
    deviation if the MAD is 0), then the mean and standard deviation (divided by that of the normal law
    truncated at +-clip) of the values within ``clip`` sigma, repeated until the kept set stops changing
    (at most ``iterations`` times).  A row without spread gives sigma = 0.  Each row is sorted once: the
    kept values are a contiguous run of it, summed from cumulative sums."""
    ordered = np.sort(np.asarray(samples, dtype=float), axis=1)
    m, k = ordered.shape
    level = np.median(ordered, axis=1)
    sigma = _MAD_TO_SIGMA * np.median(np.abs(ordered - level[:, None]), axis=1)
    flat = sigma == 0.0
    sigma[flat] = np.std(ordered[flat], axis=1)
    sums = np.concatenate([np.zeros((m, 1)), np.cumsum(ordered, axis=1)], axis=1)
    squares = np.concatenate([np.zeros((m, 1)), np.cumsum(ordered * ordered, axis=1)], axis=1)
    truncation = _truncation(clip)
    active = sigma > 0.0
    n_kept = np.full(m, -1)
    rows = np.arange(m)
    for _ in range(iterations):
        low = (ordered < (level - clip * sigma)[:, None]).sum(axis=1)
        high = (ordered <= (level + clip * sigma)[:, None]).sum(axis=1)
        count = high - low
        active &= (count != n_kept) & (count >= 2)
        if not active.any():
            break
        n_kept = count
        total = np.maximum(count, 1)
        mean = (sums[rows, high] - sums[rows, low]) / total
        variance = np.maximum((squares[rows, high] - squares[rows, low]) / total - mean * mean, 0.0)
        level = np.where(active, mean, level)
        sigma = np.where(active, np.sqrt(variance) / truncation, sigma)
    return level, sigma


def estimate_background(image, clip=3.0, iterations=5):
    """Robust (b, sigma_n) [DN] of the whole frame (module text); a flat frame gives sigma_n = 0."""
    array = np.asarray(image)
    step = max(1, int(np.ceil(np.sqrt(array.size / _GLOBAL_SAMPLE))))
    sample = np.asarray(array[::step, ::step], dtype=float).reshape(1, -1)
    level, sigma = _clipped_level(sample, clip, iterations)
    return float(level[0]), float(sigma[0])


def _cell_edges(size, cell_px):
    """Cell boundaries along one axis: cells of ``cell_px``; a remainder of half a cell or more is a cell of
    its own, a smaller one joins the last cell."""
    n = size // cell_px
    if n == 0:
        return np.array([0, size])
    edges = list(np.arange(n + 1) * cell_px)
    if size - edges[-1] >= cell_px / 2.0:
        edges.append(size)
    edges[-1] = size
    return np.array(edges)


def _cell_samples(array, rows, cols, cell_sample):
    """(cells_y, cells_x, k) subsamples of every cell: the same ny x nx grid (k <= ``cell_sample`` pixels) spread
    evenly over each cell, whatever its size."""
    heights, widths = np.diff(rows), np.diff(cols)
    step = max(1.0, np.sqrt(heights.min() * widths.min() / cell_sample))
    ny, nx = max(1, int(heights.min() / step)), max(1, int(widths.min() / step))
    r = (rows[:-1, None] + (np.arange(ny)[None, :] + 0.5) * heights[:, None] / ny).astype(np.int64)  # (cells_y, ny)
    c = (cols[:-1, None] + (np.arange(nx)[None, :] + 0.5) * widths[:, None] / nx).astype(np.int64)
    samples = array[r[:, None, :, None], c[None, :, None, :]]  # (cells_y, cells_x, ny, nx)
    return samples.reshape(len(rows) - 1, len(cols) - 1, ny * nx)


def _linear_weights(x, centres):
    """(low (n,), frac (n,)): x = centres[low] + frac (centres[low + 1] - centres[low]); frac runs below 0
    and above 1 beyond the outer centres (linear extrapolation over the last half cell, so a gradient
    is followed to the image edge); low = 0, frac = 0 for a single centre."""
    if centres.size == 1:
        return np.zeros(x.size, np.int64), np.zeros(x.size)
    low = np.clip(np.searchsorted(centres, x, side="right") - 1, 0, centres.size - 2)
    return low, (x - centres[low]) / (centres[low + 1] - centres[low])


class Background:
    """Level b and noise sigma_n [DN] of a frame: cell values ``level``, ``sigma`` (gy, gx) at the centres
    of the cells bounded by ``rows`` and ``cols``, interpolated bilinearly (a 1 x 1 grid is the global
    estimate).  ``median_level`` and ``median_sigma`` summarise it in one number each."""

    def __init__(self, level, sigma, rows, cols):
        self.level, self.sigma = np.atleast_2d(level).astype(float), np.atleast_2d(sigma).astype(float)
        self.rows, self.cols = np.asarray(rows), np.asarray(cols)
        centre_r, centre_c = 0.5 * (self.rows[:-1] + self.rows[1:]) - 0.5, 0.5 * (self.cols[:-1] + self.cols[1:]) - 0.5
        self._rows = _linear_weights(np.arange(self.rows[-1]), centre_r)
        self._cols = _linear_weights(np.arange(self.cols[-1]), centre_c)

    @classmethod
    def uniform(cls, level, sigma, shape):
        """The same level and noise everywhere in a frame of ``shape``."""
        return cls([[level]], [[sigma]], [0, shape[0]], [0, shape[1]])

    @property
    def median_level(self) -> float:
        """Median of the cell levels [DN]."""
        return float(np.median(self.level))

    @property
    def median_sigma(self) -> float:
        """Median of the cell noises [DN]."""
        return float(np.median(self.sigma))

    def _along_rows(self, grid, rows):
        """The grid interpolated to ``rows`` (len(rows), gx) (or every row)."""
        low, frac = self._rows if rows is None else (self._rows[0][rows], self._rows[1][rows])
        upper = np.minimum(low + 1, grid.shape[0] - 1)
        return grid[low] * (1.0 - frac)[:, None] + grid[upper] * frac[:, None]

    def threshold(self, a):
        """V_th = b + a sigma_n at every pixel (H, W) float32, or one number for a uniform background."""
        grid = self.level + a * self.sigma
        if grid.size == 1:
            return float(grid[0, 0])
        partial = self._along_rows(grid, None).astype(np.float32)
        low, frac = self._cols
        upper = np.minimum(low + 1, grid.shape[1] - 1)
        frac = frac.astype(np.float32)
        return partial[:, low] * (1.0 - frac) + partial[:, upper] * frac

    def at(self, rows, cols):
        """(b, sigma_n) at the pixels (rows, cols)."""
        low, frac = self._cols[0][cols], self._cols[1][cols]
        out = []
        for grid in (self.level, self.sigma):
            partial = self._along_rows(grid, rows)
            index = np.arange(len(rows))
            out.append(partial[index, low] * (1.0 - frac) + partial[index, np.minimum(low + 1, grid.shape[1] - 1)] * frac)
        return tuple(out)


def mesh_background(image, cell_px=64, clip=3.0, iterations=5, cell_sample=CELL_SAMPLE):
    """The :class:`Background` of a frame on a mesh of ``cell_px`` cells, each from at most ``cell_sample`` of
    its pixels (module text)."""
    array = np.asarray(image)
    rows, cols = _cell_edges(array.shape[0], int(cell_px)), _cell_edges(array.shape[1], int(cell_px))
    samples = _cell_samples(array, rows, cols, cell_sample)
    level, sigma = _clipped_level(samples.reshape(-1, samples.shape[-1]), clip, iterations)
    shape = samples.shape[:2]
    level, sigma = level.reshape(shape), sigma.reshape(shape)
    level_median = ndimage.median_filter(level, size=3, mode="nearest")
    sigma_median = ndimage.median_filter(sigma, size=3, mode="nearest")
    odd = (np.abs(level - level_median) > 3.0 * sigma_median) | (sigma > 2.0 * sigma_median)
    level[odd], sigma[odd] = level_median[odd], sigma_median[odd]
    return Background(level, sigma, rows, cols)
