"""The rows a figure draws of a long line: bounded, first, last, extremes and breaks kept, and
the picture the same as of every row (issue 30: a 30-min drive's figures drew 180,000
ground-truth rows and 27,000–36,000 poses per line, about 20 MiB of copies per figure)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from matplotlib.image import imread
from scipy.spatial.transform import Rotation

from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report import decimation, heading_figure, run_report
from vo_doppler.report.decimation import drawn_points, drawn_rows
from vo_doppler.report.heading_figure import build_heading_figure
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


def test_a_dot_per_occupied_cell_and_the_extremes_are_kept():
    x = np.repeat(np.arange(100.0), 50)  # 100 columns of 50 dots each
    y = np.tile(np.r_[np.zeros(49), 9.0], 100)  # two levels per column
    y[7] = np.nan
    rows = drawn_points(x, y, cells=(100, 10))
    assert np.all(np.diff(rows) > 0) and 7 not in rows
    np.testing.assert_array_equal(
        rows, np.sort(np.r_[np.arange(100) * 50, np.arange(100) * 50 + 49])
    )
    np.testing.assert_array_equal(drawn_points(x[:99], y[:99], cells=(100, 10)), np.arange(99))
    assert drawn_points(np.arange(500.0), np.full(500, np.nan), cells=(10, 10)).size == 0
    with pytest.raises(ValueError, match="cells must be at least 1"):
        drawn_points(x, y, cells=(0, 3))


def test_extreme_dots_are_kept_whatever_the_cells():
    rng = np.random.default_rng(8)
    x, y = np.sort(rng.uniform(0.0, 1.0, 20_000)), rng.standard_cauchy(20_000)
    rows = drawn_points(x, y, cells=(50, 5))
    assert len(rows) <= 50 * 5 + 4
    assert {int(np.argmin(y)), int(np.argmax(y)), 0, len(x) - 1} <= set(rows)


def every_row(monkeypatch) -> None:
    """Every figure of the report drawn from every row and point."""
    monkeypatch.setattr(run_report, "drawn_rows", lambda values: np.arange(len(values)))
    monkeypatch.setattr(decimation, "drawn_rows", lambda values: np.arange(len(values)))
    monkeypatch.setattr(heading_figure, "drawn_rows", lambda values: np.arange(len(values)))
    monkeypatch.setattr(heading_figure, "drawn_points", lambda x, y: np.arange(len(x)))


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
    truth = wandering(180_000, 1, 0.01)
    tracks = {"vo": wandering(36_000, 2, 0.05), "vo_gps_tc": wandering(36_000, 3, 0.05)}

    def pictures():
        top = png_pixels(lambda out: trajectories_figure(out, tracks, truth, "drive"))
        figure = build_heading_error_figure(tracks, truth, 0.0, "drive")
        errors = png_pixels(lambda out: figure.savefig(out, format="png", dpi=100))
        return top, errors

    decimated = pictures()
    every_row(monkeypatch)
    whole = pictures()
    for fewer, every in zip(decimated, whole, strict=True):
        assert fewer.shape == every.shape
        differs = np.abs(fewer - every).max(axis=2) > 0.1
        assert differs.mean() < 0.005


def test_the_heading_figure_looks_the_same_as_drawn_from_every_epoch(monkeypatch):
    """A 30-min drive's heading table at 20 Hz (36,000 epochs, gaps, a noisy conventional
    heading, a band that widens): at most 0.5 % of the pixels differ, by antialiasing, from the
    picture of every epoch."""
    rng = np.random.default_rng(4)
    m = 36_000
    yaw = np.cumsum(rng.normal(0.0, 0.01, m)) + np.linspace(0.0, 20.0, m)
    yaw_tc = yaw + rng.normal(0.0, 0.005, m)
    yaw_tc[5000:5600] = np.nan
    conv = rng.uniform(size=m) > 0.4
    table = HeadingTable(
        t=1.0e9 + 0.05 * np.arange(m),
        yaw_tc=yaw_tc,
        sigma_tc=0.005 + 0.02 * (np.arange(m) % 3000) / 3000,
        tc_reliable=np.isfinite(yaw_tc),
        n_obs_window=np.full(m, 40),
        n_sat_epoch=rng.integers(3, 9, m),
        yaw_conv=np.where(conv, yaw + rng.normal(0.0, 0.03, m), np.nan),
        conv_valid=conv,
        gyro_bias=np.zeros(m),
        wheel_scale=np.ones(m),
    )
    used = np.isfinite(yaw_tc) & (rng.uniform(size=m) > 0.1)

    def picture():
        figure = build_heading_figure(table, yaw, "drive", used)
        return png_pixels(lambda out: figure.savefig(out, format="png", dpi=110))

    decimated = picture()
    every_row(monkeypatch)
    whole = picture()
    assert decimated.shape == whole.shape
    differs = np.abs(decimated - whole).max(axis=2) > 0.1
    assert differs.mean() < 0.005
