"""The rows a figure draws of a long line: bounded, first, last, extremes and breaks kept, and
the picture the same as of every row (issue 30: a 30-min drive's figures drew 180,000
ground-truth rows and 27,000–36,000 poses per line, about 20 MiB of copies per figure)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from matplotlib.image import imread
from scipy.spatial.transform import Rotation

from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report.decimation import drawn_rows
from vo_doppler.report.run_report import build_heading_error_figure, trajectories_figure


def test_short_lines_are_drawn_whole():
    np.testing.assert_array_equal(drawn_rows(np.arange(50.0), runs=50), np.arange(50))
    assert drawn_rows(np.zeros((0, 2))).size == 0 and drawn_rows(np.zeros(0)).size == 0
    with pytest.raises(ValueError, match="runs must be at least 1"):
        drawn_rows(np.zeros(3), runs=0)


def test_first_last_and_every_runs_extremes_are_kept_and_the_count_bounded():
    rng = np.random.default_rng(5)
    values = rng.normal(size=(100_003, 2))
    rows = drawn_rows(values, runs=1000)
    assert rows[0] == 0 and rows[-1] == len(values) - 1
    assert np.all(np.diff(rows) > 0) and len(rows) <= 1000 * 6
    size = -(-len(values) // 1000)
    for start in range(0, len(values), size):
        run = values[start : start + size]
        kept = set(rows[(rows >= start) & (rows < start + size)])
        for column in (0, 1):
            assert start + int(np.argmin(run[:, column])) in kept
            assert start + int(np.argmax(run[:, column])) in kept
        assert {start, start + len(run) - 1} <= kept
    assert values[rows, 0].max() == values[:, 0].max()  # the axes' limits stay


def test_breaks_stay_breaks():
    y = np.sin(np.arange(10_000) / 50.0)
    y[3000:3500] = np.nan
    y[7777] = np.inf
    rows = drawn_rows(y, runs=100)
    assert {2999, 3000, 3500, 7776, 7777, 7778} <= set(rows)
    finite = np.isfinite(y[rows])
    assert np.count_nonzero(finite[:-1] & ~finite[1:]) == 2  # the line breaks twice, as before


def png_pixels(draw) -> np.ndarray:
    buffer = io.BytesIO()
    draw(buffer)
    buffer.seek(0)
    return imread(buffer)


def wandering(n: int, seed: int, dt: float) -> Trajectory:
    rng = np.random.default_rng(seed)
    yaw = np.cumsum(rng.normal(0.0, 0.004, n)) + np.linspace(0.0, 12.0, n)
    steps = 10.0 * dt * np.column_stack([np.cos(yaw), np.sin(yaw), np.zeros(n)])
    return Trajectory(
        np.arange(n) * dt, np.cumsum(steps, axis=0), Rotation.from_euler("z", yaw[:, None])
    )


def test_the_figures_look_the_same_as_drawn_from_every_row(monkeypatch):
    """The top view of a 30-min drive (180,000 truth rows, 36,000 poses) and its heading
    errors: at most 0.5 % of the pixels differ, by antialiasing, from the pictures of every
    row."""
    import vo_doppler.report.run_report as run_report

    truth = wandering(180_000, 1, 0.01)
    tracks = {"vo": wandering(36_000, 2, 0.05), "vo_gps_tc": wandering(36_000, 3, 0.05)}

    def pictures():
        top = png_pixels(lambda out: trajectories_figure(out, tracks, truth, "drive"))
        figure = build_heading_error_figure(tracks, truth, 0.0, "drive")
        errors = png_pixels(lambda out: figure.savefig(out, format="png", dpi=100))
        return top, errors

    decimated = pictures()
    monkeypatch.setattr(run_report, "drawn_rows", lambda values: np.arange(len(values)))
    whole = pictures()
    for fewer, every in zip(decimated, whole, strict=True):
        assert fewer.shape == every.shape
        differs = np.abs(fewer - every).max(axis=2) > 0.1
        assert differs.mean() < 0.005
