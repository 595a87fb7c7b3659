"""Heading error and drift figures: exact cases."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.lowcost.dead_reckoning import (
    track_yaw,
)
from vo_doppler.lowcost.drift import (
    closed_loop_gap,
    drift_rate_deg_per_min,
    heading_error,
    route_closes,
)


def test_track_yaw_and_heading_error_unwrapping():
    yaw = track_yaw(np.array([0.0, 1.0, 1.0, 1.0]), np.array([0.0, 0.0, 5.0, 5.1]))
    np.testing.assert_allclose(yaw[:2], [0.0, np.pi / 2])
    assert np.isnan(yaw[2]) and np.isnan(yaw[3])
    t = np.arange(0.0, 600.0, 1.0)
    error = heading_error(np.radians(t), np.zeros_like(t))
    np.testing.assert_allclose(error, np.radians(t), atol=1e-9)
    assert drift_rate_deg_per_min(t, error) == pytest.approx(60.0)
    assert drift_rate_deg_per_min(t, error, window_s=10.0) == pytest.approx(60.0)


def test_the_loop_gap_is_given_only_on_a_route_that_closes():
    """A square of 400 m driven with its last side 4 % short: closed (within 5 % of its
    length), gap = the trajectory's start-end distance; the same trajectory against a straight
    1-km route: open, no gap, and the end error is the distance between the two ends."""
    side = np.linspace(0.0, 100.0, 101)
    zeros, full = np.zeros(101), np.full(101, 100.0)
    east = np.concatenate([side, full, side[::-1], zeros[:97]])
    north = np.concatenate([zeros, side, full, side[::-1][:97]])
    square = np.column_stack([east, north])
    closed = closed_loop_gap(east, north, square)
    assert closed.closed and closed.gap_m == pytest.approx(4.0)
    assert closed.length_m == pytest.approx(396.0) and closed.end_error_m == 0.0
    assert closed.percent == pytest.approx(100 * 4.0 / 396.0)

    road = np.column_stack([np.linspace(0.0, 1000.0, east.size), np.zeros(east.size)])
    assert not route_closes(road[:, 0], road[:, 1])
    open_route = closed_loop_gap(east, north, road)
    assert not open_route.closed and np.isnan(open_route.gap_m) and np.isnan(open_route.percent)
    assert open_route.end_error_m == pytest.approx(np.hypot(1000.0, 4.0))
    assert open_route.end_error_percent == pytest.approx(100 * np.hypot(1000.0, 4.0) / 396.0)


@pytest.mark.parametrize(("end_m", "closes"), [(9.9, True), (10.1, False)])
def test_a_short_route_closes_within_ten_metres(end_m, closes):
    """40 m out and back: 5 % would be 2 m, below a GPS fix's error, so 10 m is the floor."""
    north = np.concatenate([np.linspace(0.0, 20.0, 21), np.linspace(20.0, 0.0, 21)[1:]])
    east = np.zeros_like(north)
    east[-1] = end_m
    assert route_closes(east, north) == closes
