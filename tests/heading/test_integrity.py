"""Conventional velocity integrity against the gyro and the wheel speed (design (I1))."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.geo import EnuFrame, wrap_angle
from vo_doppler.gnss.doppler_velocity import solve_velocity
from vo_doppler.heading.from_gnss import heading_from_gnss
from vo_doppler.heading.integrity import (
    ConsistencyConfig,
    consistency_test,
    windowed_line_residuals,
)
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.series import SensorSeries
from vo_doppler.sim.doppler_rows import gyro_from_heading, line_of_sight

FRAME = EnuFrame(np.radians(35.69), np.radians(139.70), 40.0)
AZIMUTH = np.radians([10.0, 80.0, 150.0, 220.0, 290.0, 340.0])
ELEVATION = np.radians([70.0, 35.0, 50.0, 25.0, 40.0, 20.0])
NOISE_MPS = 0.05
SPEED_MPS = 10.0
FAULT = slice(300, 303)
"""Epochs (0.3 s) where three satellites are reflected at once."""
COURSE_FAULT = np.radians(4.0)


def test_line_residuals_are_exact_on_a_line_with_one_outlier():
    t = np.arange(0.0, 10.0, 0.1)
    values = 0.3 + 0.02 * t
    values[50] += 0.5
    sigma = np.full(t.size, 0.01)
    usable = np.ones(t.size, bool)
    residual, variance = windowed_line_residuals(t, values, sigma, usable, 2.0, 5)
    assert residual[50] == pytest.approx(0.5, abs=1e-12)
    # 40 neighbours at ±0.1–2 s: var(c₀) = σ²·Σdt²/(n·Σdt² − (Σdt)²) = σ²/40 (symmetric)
    assert variance[50] == pytest.approx(0.01**2 / 40, rel=1e-9)
    others = np.delete(np.arange(t.size), 50)
    # the outlier's Huber weight k·σ/0.5 leaves at most 1 % of it in a neighbour's line
    assert np.max(np.abs(residual[others])) < 5e-3
    # a slope prior of zero makes the line a constant: the drift shows in the residuals
    flat, _ = windowed_line_residuals(t, values, sigma, usable, 2.0, 5, slope_sigma=np.zeros(100))
    assert flat[20] == pytest.approx(0.0, abs=1e-9)  # symmetric window: the drift cancels
    assert flat[5] < -0.005  # the window is cut at the start: the later epochs pull it up
    # without enough neighbours: untested
    lonely = np.zeros(t.size, bool)
    lonely[[10, 40, 90]] = True
    residual, _ = windowed_line_residuals(t, values, sigma, lonely, 2.0, 1)
    assert np.isnan(residual).all()


def test_angular_residuals_wrap_across_pi():
    t = np.arange(0.0, 5.0, 0.1)
    values = wrap_angle(np.pi - 0.01 + 0.004 * t / 0.1)  # crosses ±π
    usable = np.ones(t.size, bool)
    residual, _ = windowed_line_residuals(t, values, np.ones(t.size), usable, 1.0, 5, angular=True)
    np.testing.assert_allclose(residual, 0.0, atol=1e-9)


def test_consistency_test_threshold_and_sigma_factor():
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 200.0, 0.1)
    sigma = np.full(t.size, 0.1)
    values = rng.normal(0.0, 0.2, t.size)  # twice the stated σ
    values[1000] += 3.0
    test = consistency_test(t, values, sigma, np.ones(t.size, bool), ConsistencyConfig())
    assert test.sigma_factor == pytest.approx(2.0, rel=0.1)
    assert test.failed[1000]
    assert test.failed.mean() < 0.005
    assert ConsistencyConfig().threshold == pytest.approx(3.2905, abs=1e-4)
    honest = consistency_test(t, values, 2 * sigma, np.ones(t.size, bool), ConsistencyConfig())
    assert honest.sigma_factor == pytest.approx(1.0, abs=0.1)


def _fault_direction(los_enu: np.ndarray, clean: np.ndarray, yaw: float) -> np.ndarray:
    """(δv ENU, δρ) that leaves the ``clean`` satellites' range rates unchanged (the null
    space of their rows [−G, 1]), scaled to turn the course by ``COURSE_FAULT``."""
    design = np.hstack([-los_enu[clean], np.ones((clean.sum(), 1))])
    null = np.linalg.svd(design)[2][-1]
    across = np.array([-np.sin(yaw), np.cos(yaw)])
    return null * SPEED_MPS * np.tan(COURSE_FAULT) / (null[:2] @ across)


def _drive():
    """A minute at 10 m/s, turning gently, six satellites; at ``FAULT`` three of them carry the
    range-rate errors of a velocity 4° off course (with a clock-drift error), which the other
    three do not see: a consistent wrong solution."""
    t = np.arange(0.0, 60.0, 0.1)
    yaw = 0.6 * np.sin(0.1 * t)
    velocity = SPEED_MPS * np.stack([np.cos(yaw), np.sin(yaw), np.zeros_like(t)], axis=1)
    los_enu = line_of_sight(AZIMUTH, ELEVATION)
    n_sat = len(AZIMUTH)
    reflected = np.zeros(n_sat, bool)
    reflected[[1, 3, 4]] = True
    rng = np.random.default_rng(7)
    y = -(velocity @ los_enu.T) + 120.0 + rng.normal(0.0, NOISE_MPS, (t.size, n_sat))
    for k in range(FAULT.start, FAULT.stop):
        fault = _fault_direction(los_enu, ~reflected, yaw[k])
        y[k, reflected] += (-los_enu[reflected] @ fault[:3]) + fault[3]
    receiver = FRAME.origin_ecef
    rows = DopplerRows(
        t=np.repeat(t, n_sat),
        los=np.tile(los_enu @ FRAME.rotation, (t.size, 1)),
        sat_velocity=np.zeros((t.size * n_sat, 3)),
        sat_clock_drift=np.zeros(t.size * n_sat),
        range_rate=y.ravel(),
        weight=np.full(t.size * n_sat, NOISE_MPS**-2),
        sat_id=np.tile([f"G{i + 1:02d}" for i in range(n_sat)], t.size),
        frame="ecef",
        epoch=np.repeat(np.arange(t.size), n_sat),
        system=np.full(t.size * n_sat, "G"),
        prn=np.tile(np.arange(1, n_sat + 1), t.size),
        receiver_ecef=np.tile(receiver, (t.size * n_sat, 1)),
    )
    t_gyro, rate = gyro_from_heading(
        t, yaw, np.ones(t.size, bool), np.radians(0.3), np.radians(0.05), rate_hz=50.0
    )
    wheel = SensorSeries(t, np.full(t.size, SPEED_MPS / 1.02))
    return t, yaw, rows, wheel, SensorSeries(t_gyro, rate)


def test_reflections_that_pass_the_chi_square_fail_the_gyro_test():
    t, yaw, rows, wheel, gyro = _drive()
    velocity = solve_velocity(rows, t)
    course_error = np.degrees(
        np.abs(wrap_angle(np.arctan2(*velocity.velocity_enu[:, 1::-1].T) - yaw))
    )
    # the GNSS stage cannot see it: chi-square and vertical test passed, 3.2° off course (the
    # fault also slows the velocity down) at seven times its own σ
    assert velocity.valid[FAULT].all()
    assert np.all(course_error[FAULT] > 3.0)
    assert np.all(np.radians(course_error[FAULT]) > 7.0 * velocity.course_sigma_rad[FAULT])
    table = heading_from_gnss(t, rows, velocity, wheel, gyro, FRAME, HeadingPipelineConfig())
    assert not table.conv_valid[FAULT].any()
    clean = np.ones(t.size, bool)
    clean[FAULT] = False
    assert table.conv_valid[clean].mean() >= 0.98
    # the stated σ is honest here (white noise at the weights' σ): factor near one
    factor = table.sigma_conv[clean] / velocity.course_sigma_rad[clean]
    assert np.nanmedian(factor) == pytest.approx(1.0, abs=0.15)
    off = HeadingPipelineConfig(integrity=ConsistencyConfig(enabled=False))
    unchecked = heading_from_gnss(t, rows, velocity, wheel, gyro, FRAME, off)
    assert unchecked.conv_valid[FAULT].all()
    np.testing.assert_array_equal(unchecked.yaw_tc, table.yaw_tc)  # tight heading untouched


def test_threshold_is_the_normal_two_sided_quantile():
    from scipy.stats import norm

    for false_alarm in (0.001, 0.01, 0.05):
        config = ConsistencyConfig(false_alarm=false_alarm)
        assert config.threshold == norm.isf(false_alarm / 2.0)
