"""The GNSS velocity and position figures: axes scaled to the valid epochs, invalid epochs
marked apart, values beyond the axis drawn at its edge and counted."""

from __future__ import annotations

import numpy as np

from tests.helpers.velocity import velocity_solution
from vo_doppler.geo import EnuFrame, geodetic_to_ecef
from vo_doppler.model.gnss_solutions import SppSolution
from vo_doppler.report.gnss import (
    INVALID_STYLE,
    build_spp_figure,
    build_velocity_figure,
    robust_limits,
    spp_figure,
    velocity_figure,
)

T = 1.0e9 + np.arange(0.0, 30.0, 0.1)


def _texts(ax) -> str:
    return " ".join(text.get_text() for text in ax.texts)


def _invalid_points(ax) -> int:
    """How many points the axis draws in the invalid epochs' style."""
    return sum(
        len(line.get_xdata())
        for line in ax.get_lines()
        if line.get_marker() == INVALID_STYLE["marker"] and line.get_color() == "tab:red"
    )


def test_limits_come_from_the_valid_values_only():
    values = np.array([9.0, 10.0, 11.0, 2794.0, np.nan])
    valid = np.array([True, True, True, False, False])
    low, high = robust_limits(values, valid, min_pad=0.5, floor=0.0)
    assert 8.0 < low < 9.0 and 11.0 < high < 12.0
    assert robust_limits(values, np.zeros(5, bool), 0.5) is None
    assert robust_limits(np.full(3, 0.01), np.ones(3, bool), 0.5, floor=0.0) == (0.0, 0.51)


def test_velocity_figure_is_scaled_to_the_valid_epochs_and_marks_the_invalid(tmp_path):
    """Issue 30: vel.png scaled its speed axis to an invalid 2,794 m/s and did not mark the
    invalid epochs."""
    speed = 10.0 + np.sin(T - T[0])
    valid = np.ones(T.size, bool)
    valid[[50, 51, 200]] = False
    speed[50] = 2794.0
    north = np.column_stack([np.zeros(T.size), speed, np.zeros(T.size)])
    solution = velocity_solution(T, north, valid)
    fig = build_velocity_figure(solution, "t")
    speed_axis = fig.axes[0]
    low, high = speed_axis.get_ylim()
    assert low >= 0.0 and high < 13.0
    assert _invalid_points(speed_axis) == 3 and _invalid_points(fig.axes[2]) == 3
    assert "1 value beyond the axis" in _texts(speed_axis)
    assert "invalid epoch" in [t.get_text() for t in speed_axis.get_legend().get_texts()]
    velocity_figure(tmp_path / "vel.png", solution)
    assert (tmp_path / "vel.png").stat().st_size > 0


def test_position_figure_is_scaled_to_the_valid_fixes_and_marks_the_invalid(tmp_path):
    """Issue 30: pos.png scaled its axis to an invalid fix 6 km up."""
    enu = EnuFrame(np.radians(35.69), np.radians(139.70), 40.0)
    rng = np.random.default_rng(0)
    local = rng.normal(0.0, 3.0, (T.size, 3))
    local[100, 2] = 6000.0
    valid = np.ones(T.size, bool)
    valid[100] = False
    n = T.size
    solution = SppSolution(
        T,
        enu.enu_to_ecef(local),
        {"G": np.zeros(n)},
        np.full(n, 8),
        np.ones(n),
        np.full(n, 2.0),
        valid,
        0,
    )
    fig = build_spp_figure(solution)
    low, high = fig.axes[0].get_ylim()
    assert -30.0 < low < -5.0 and 5.0 < high < 30.0
    assert _invalid_points(fig.axes[0]) == 3  # the invalid epoch's east, north and up
    assert "1 value beyond the axis" in _texts(fig.axes[0])
    spp_figure(tmp_path / "pos.png", solution)
    assert (tmp_path / "pos.png").stat().st_size > 0


def test_without_a_valid_fix_the_position_figure_still_draws():
    n = 5
    origin = geodetic_to_ecef(np.radians(35.0), np.radians(139.0), 0.0)
    solution = SppSolution(
        T[:n],
        np.tile(origin, (n, 1)),
        {},
        np.zeros(n, int),
        np.full(n, np.nan),
        np.full(n, np.nan),
        np.zeros(n, bool),
        0,
    )
    fig = build_spp_figure(solution)
    assert _invalid_points(fig.axes[1]) == n
