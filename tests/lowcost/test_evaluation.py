"""The low-cost chain's evaluation helpers on exact cases: a constant gyro bias seen as the
per-block rate error, scatter figures of points about a known path, the time offset between
fixes and a reference, and the raw fixes' scatter."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial import cKDTree

from vo_doppler.geo import EnuFrame, ecef_to_geodetic
from vo_doppler.lowcost.evaluation import (
    block_rate_errors,
    fitted_time_offset,
    gps_scatter,
    scatter_metrics,
)

FRAME = EnuFrame(np.radians(35.0), np.radians(139.0), 40.0)


def _geodetic(enu: np.ndarray) -> np.ndarray:
    """(N, 3) latitude, longitude (rad) and height (m) of ENU points of ``FRAME``."""
    return np.column_stack(ecef_to_geodetic(FRAME.enu_to_ecef(enu)))


def _reference(duration_s: float = 60.0, rate_hz: float = 10.0) -> SimpleNamespace:
    """A car driving east at 10 m/s along a gentle sine (yaw from the path), at 40 m height."""
    t = np.arange(0.0, duration_s + 1e-9, 1.0 / rate_hz)
    east, north = 10.0 * t, 20.0 * np.sin(t / 10.0)
    yaw = np.arctan2(2.0 * np.cos(t / 10.0), 10.0)
    lat, lon, height = _geodetic(np.column_stack([east, north, np.zeros_like(t)])).T
    return SimpleNamespace(t=t, yaw=yaw, lat=lat, lon=lon, height=height)


def test_a_constant_gyro_bias_is_the_error_of_every_block():
    truth = _reference()
    t = np.arange(0.0, 60.0, 0.01)
    rate = np.gradient(np.interp(t, truth.t, truth.yaw), t) + 0.002
    errors = block_rate_errors(t, rate, truth, block_s=5.0)
    assert len(errors) == 11  # blocks starting 0, 5, …, 50 s (one must fit before the end)
    np.testing.assert_allclose(errors, 0.002, atol=2e-5)


def test_scatter_metrics_of_points_about_a_straight_path():
    # the path is the east axis; the points sit 3 m north of their time-matched truth, the
    # third 1 m further east, the last 5 m north
    path = np.column_stack([np.linspace(-10.0, 20.0, 3001), np.zeros(3001)])
    truth = np.column_stack([np.arange(5.0), np.zeros(5)])
    points = truth + np.array([0.0, 3.0])
    points[2, 0] += 1.0
    points[4, 1] = 5.0
    metrics = scatter_metrics(points, truth, cKDTree(path))
    assert metrics["rms_m"] == pytest.approx(np.sqrt(62.0 / 5.0), rel=1e-12)
    assert metrics["cross_track_rms_m"] == pytest.approx(np.sqrt(61.0 / 5.0), abs=1e-9)
    # about the mean error (0.2, 3.4): 0.8 east and 3.2 north squared in all
    assert metrics["std_about_mean_m"] == pytest.approx(np.sqrt(4.0 / 5.0), rel=1e-12)
    # second differences of the error: (1, 0), (−2, 0), (1, 2)
    assert metrics["jitter_rms_m"] == pytest.approx(np.sqrt(10.0 / 3.0), rel=1e-12)


def test_the_time_offset_of_fixes_that_run_behind_the_reference():
    truth = _reference()
    # each fix shows where the car was 0.3 s later than its time stamp says
    t = np.arange(2.0, 58.0, 1.0)
    at = np.column_stack([np.interp(t + 0.3, truth.t, v) for v in (truth.lat, truth.lon)])
    fixes = SimpleNamespace(t=t, lat=at[:, 0], lon=at[:, 1])
    assert fitted_time_offset(truth, fixes) == pytest.approx(0.3, abs=1e-3)


def test_raw_fixes_on_the_path_have_no_scatter_and_offset_ones_show_it():
    truth = _reference()
    t = np.arange(0.0, 61.0, 1.0)
    on = SimpleNamespace(
        t=t, lat=np.interp(t, truth.t, truth.lat), lon=np.interp(t, truth.t, truth.lon)
    )
    results, (matched_t, matched), raw, tracks = gps_scatter(truth, on, [], 5.0)
    np.testing.assert_array_equal(matched_t, t)
    assert results["raw"]["rms_m"] < 0.05 and tracks == {}  # the heights differ by 40 m only
    np.testing.assert_allclose(raw, matched, atol=0.05)
    # 4 m north of the truth at every fix
    shifted = _geodetic(np.column_stack([matched[:, 0], matched[:, 1] + 4.0, np.zeros(len(t))]))
    off = SimpleNamespace(t=t, lat=shifted[:, 0], lon=shifted[:, 1])
    results, *_ = gps_scatter(truth, off, [], 5.0)
    assert results["raw"]["rms_m"] == pytest.approx(4.0, abs=0.05)
    assert results["raw"]["std_about_mean_m"] < 0.05  # a constant offset
