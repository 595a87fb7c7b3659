"""Which rows of a long line a figure draws: no more than it can show.

A 30-minute drive's ground truth has 180,000 rows and its trajectories 27,000–36,000 poses;
a figure 800–1,000 pixels wide shows none of that detail, while drawing every row costs its
copies in matplotlib (about 20 MiB per figure on such a drive). :func:`drawn_rows` splits the
rows, in their order, into at most ``runs`` consecutive runs of equal length and keeps of each
run its first and last rows and, per coordinate, the rows of its least and greatest finite
value (the min/max-per-column aggregation of M4, Jugel et al., PVLDB 7(10), 2014, applied to
runs of rows); and where the line breaks (a non-finite value), the last finite row before and
the first non-finite row of each break and the first finite row after it. Runs of rows that
each span less than a pixel then draw the same pixels as every row: within a run the line
moves less than a pixel, its extent in each coordinate is kept, and its ends join the
neighbouring runs as before; the axes' limits are unchanged (every extreme is kept).

Dots (the heading figure's per-epoch markers) are not a line: :func:`drawn_points` keeps one
point of each cell of a grid finer than the figure's pixels (``DOT_CELLS``), so the markers
cover the same pixels. Thin ticks are not decimated: dozens of them overlapping in a pixel make
its colour, which fewer would lighten."""

from __future__ import annotations

import numpy as np

FIGURE_RUNS = 4000
"""Runs per line (at most 4 + 2 per coordinate rows each): four or more per pixel column of the
report's figures (at most 990 pixels wide)."""


def drawn_rows(values: np.ndarray, runs: int = FIGURE_RUNS) -> np.ndarray:
    """Sorted indices of the rows of ``values`` (N, or N×D coordinates, rows in drawing order)
    that a line through them draws: all of them when there are at most ``runs`` rows, else
    the first and last rows of each of ``runs`` consecutive runs, the rows of each run's least
    and greatest finite value per coordinate, and the rows around every break (module
    docstring)."""
    if runs < 1:
        raise ValueError(f"runs must be at least 1, got {runs}")
    values = np.asarray(values, dtype=float)
    n = len(values)
    if n <= runs:
        return np.arange(n)
    points = values.reshape(n, -1)
    size = -(-n // runs)
    count = -(-n // size)
    starts = np.arange(count) * size
    keep = [starts, np.minimum(starts + size, n) - 1]
    finite = np.isfinite(points)
    padded = count * size - n
    for column in range(points.shape[1]):
        value, ok = points[:, column], finite[:, column]
        low = np.pad(np.where(ok, value, np.inf), (0, padded), constant_values=np.inf)
        high = np.pad(np.where(ok, value, -np.inf), (0, padded), constant_values=-np.inf)
        keep.append(starts + np.argmin(low.reshape(count, size), axis=1))
        keep.append(starts + np.argmax(high.reshape(count, size), axis=1))
    whole = finite.all(axis=1)
    change = np.flatnonzero(whole[1:] != whole[:-1])
    keep += [change, change + 1]
    return np.unique(np.concatenate(keep))


def drawn_line(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The points of a line over ``x`` (increasing) that a figure draws (:func:`drawn_rows` of
    ``y``, N or N×D)."""
    rows = drawn_rows(y)
    return x[rows], y[rows]


DOT_CELLS = (2000, 1000)
"""Columns and rows of the grid over a dot plot's extent of which :func:`drawn_points` keeps
one point per cell: at most half a pixel wide and high in the report's figures (at most 1,100
pixels wide, a panel at most 500 high), well below a marker's size."""


def drawn_points(x: np.ndarray, y: np.ndarray, cells: tuple[int, int] = DOT_CELLS) -> np.ndarray:
    """Sorted indices of the points (``x``, ``y``) that a dot or tick plot draws: all of them
    when there are at most ``cells[0]``, else the first finite point in each occupied cell of a
    grid of ``cells`` (columns, rows) over the finite points' extent, and the points of least
    and greatest x and y (the axes' limits unchanged). A point with a non-finite coordinate
    draws nothing and is left out."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    columns, levels = cells
    if min(columns, levels) < 1:
        raise ValueError(f"cells must be at least 1 × 1, got {cells}")
    if len(x) <= columns:
        return np.arange(len(x))
    finite = np.flatnonzero(np.isfinite(x) & np.isfinite(y))
    if finite.size == 0:
        return finite
    fx, fy = x[finite], y[finite]
    _, first = np.unique(_cell(fx, columns) * levels + _cell(fy, levels), return_index=True)
    extremes = [np.argmin(fx), np.argmax(fx), np.argmin(fy), np.argmax(fy)]
    return np.unique(np.concatenate([finite[first], finite[extremes]]))


def _cell(values: np.ndarray, count: int) -> np.ndarray:
    """Index (0 … count − 1) of each finite value's cell among ``count`` equal cells over their
    extent."""
    low, span = values.min(), values.max() - values.min()
    if not span > 0:
        return np.zeros(values.size, dtype=np.int64)
    return np.minimum(((values - low) * (count / span)).astype(np.int64), count - 1)
