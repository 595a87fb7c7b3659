"""Conventional velocity integrity against the gyro and the wheel speed (design (I1))."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.heading_table import plain_heading_table
from tests.helpers.velocity import velocity_solution
from vo_doppler.geo import EnuFrame, wrap_angle
from vo_doppler.gnss.doppler_velocity import solve_velocity
from vo_doppler.gnss.windowed_line import ConsistencyConfig, epochs_in_window
from vo_doppler.heading.from_gnss import heading_from_gnss
from vo_doppler.heading.integrity import (
    AT_REST_MAX_MPS,
    CarReference,
    ConventionalEpochs,
    car_checked_velocity,
    car_vertical_bound,
    conventional_integrity,
    course_protection,
    integrity_rate_warning,
    rest_speed_bound,
    velocity_integrity,
)
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.sim.doppler_rows import gyro_from_heading, line_of_sight

FRAME = EnuFrame(np.radians(35.69), np.radians(139.70), 40.0)
AZIMUTH = np.radians([10.0, 80.0, 150.0, 220.0, 290.0, 340.0])
ELEVATION = np.radians([70.0, 35.0, 50.0, 25.0, 40.0, 20.0])
NOISE_MPS = 0.05
SPEED_MPS = 10.0
FAULT = slice(300, 330)
"""Epochs (3 s) where three satellites are reflected at once: too long for the GNSS stage's
continuity test over ±0.5 s, well within the gyro test's ±5 s."""
COURSE_FAULT = np.radians(4.0)


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


@pytest.mark.slow
def test_reflections_that_pass_the_chi_square_fail_the_gyro_test():
    t, yaw, rows, wheel, gyro = _drive()
    velocity = solve_velocity(rows, t)
    course_error = np.degrees(
        np.abs(wrap_angle(np.arctan2(*velocity.velocity_enu[:, 1::-1].T) - yaw))
    )
    # the GNSS stage cannot see it: chi-square, vertical and continuity tests passed (bar the
    # fault's first and last half second), 3.2° off course (the fault also slows the velocity
    # down) at seven times its own σ
    assert velocity.verified[FAULT].all()
    assert velocity.valid[FAULT][5:-5].all()
    assert np.all(course_error[FAULT] > 2.9)
    assert np.all(np.radians(course_error[FAULT]) > 7.0 * velocity.course_sigma_rad[FAULT])
    table = heading_from_gnss(
        t, rows, velocity, VehicleSignals(wheel, gyro), FRAME, HeadingPipelineConfig()
    )
    assert not table.conv_valid[FAULT].any()
    clean = np.ones(t.size, bool)
    clean[FAULT] = False
    # a 3-s fault is 30 % of a neighbour's ±5-s window: the robust line leans towards it and
    # clean epochs up to 2.5 s away may fail too; beyond, nearly all stay valid
    away = clean & (np.abs(t - t[FAULT].mean()) > 4.0)
    assert table.conv_valid[away].mean() >= 0.98
    assert table.conv_valid[clean].mean() >= 0.9
    # the stated σ is honest here (white noise at the weights' σ): factor near one
    factor = table.sigma_conv[clean] / velocity.course_sigma_rad[clean]
    assert np.nanmedian(factor) == pytest.approx(1.0, abs=0.15)
    off = HeadingPipelineConfig(integrity=ConsistencyConfig(enabled=False))
    unchecked = heading_from_gnss(t, rows, velocity, VehicleSignals(wheel, gyro), FRAME, off)
    np.testing.assert_array_equal(unchecked.conv_valid, velocity.valid)
    np.testing.assert_array_equal(unchecked.yaw_tc, table.yaw_tc)  # tight heading untouched


def test_a_speed_while_the_wheels_stand_fails_whatever_its_sigma():
    t = np.arange(20.0)
    valid = np.ones(20, bool)
    speed = np.full(20, 0.05)
    speed[10] = 0.75  # reflected satellites pulled the fix
    wheel = np.zeros(20)
    result = conventional_integrity(
        ConventionalEpochs(t, valid, np.zeros(20), None, speed, np.full(20, 0.3)),
        CarReference(np.zeros(20), wheel, np.zeros(20)),
    )
    assert not result.valid[10] and result.valid[[9, 11]].all()
    moving = conventional_integrity(
        ConventionalEpochs(t, valid, np.zeros(20), None, speed + 5, np.full(20, 0.3)),
        CarReference(np.zeros(20), wheel + 5, np.zeros(20)),
    )
    assert moving.valid[10]  # 0.75 m/s off at 5 m/s is within the speed test's 3σ here


RATES_HZ = (1.0, 5.0, 10.0, 20.0)
STATED_SIGMA = np.radians(3.0)
"""The course σ the velocity states: four times the actual noise (0.7°)."""


def _courses(rate_hz: float, fault_deg: float = 0.0):
    """Two minutes weaving at 8 m/s at ``rate_hz``: the true yaw, the calibrated gyro's
    integrated angle (an unknown constant off), and conventional courses with 0.7° of noise
    (stated 3°), ``fault_deg`` off from 60 to 63 s."""
    t = np.arange(0.0, 120.0, 1.0 / rate_hz)
    yaw = np.radians(40.0) * np.sin(2.0 * np.pi * t / 30.0)
    rng = np.random.default_rng(int(rate_hz))
    course = yaw + rng.normal(0.0, np.radians(0.7), t.size)
    fault = (t >= 60.0) & (t < 63.0)
    course[fault] += np.radians(fault_deg)
    return t, wrap_angle(course), yaw - 1.3, fault


def _judged(
    t,
    course,
    angle,
    valid=None,
    wheel=8.0,
    speed=8.0,
    course_sigma=STATED_SIGMA,
    speed_sigma=0.3,
    vertical_bound=None,
):
    n = t.size
    epochs = ConventionalEpochs(
        t,
        np.ones(n, bool) if valid is None else valid,
        course,
        np.full(n, course_sigma),
        np.broadcast_to(speed, n),
        np.full(n, speed_sigma),
        vertical_bound,
    )
    return conventional_integrity(
        epochs, CarReference(angle, np.broadcast_to(wheel, n), np.full(n, 1e-4))
    )


@pytest.mark.parametrize("rate_hz", RATES_HZ)
def test_the_gyro_bounds_the_course_error_at_any_rate(rate_hz):
    """An 8° fault within its stated 3° σ (z below 2.7 < 3.29) passes the consistency test,
    but the gyro-propagated course of its neighbours shows it 8° off: beyond the alert limit
    of 5°, not valid, at 1, 5, 10 and 20 Hz; the clean epochs stay valid."""
    t, course, angle, fault = _courses(rate_hz, fault_deg=8.0)
    result = _judged(t, course, angle)
    assert not result.course.failed[fault].any()  # the consistency test alone passes it
    assert not result.valid[fault].any()
    away = np.abs(t - 61.5) > 6.5  # windows free of the fault
    assert result.valid[away].all()
    clean = _judged(*_courses(rate_hz)[:3])
    assert clean.valid.all() and not clean.untested.any()


@pytest.mark.parametrize("rate_hz", RATES_HZ)
def test_the_protection_is_the_residual_plus_the_references_sigma(rate_hz):
    """Exact: a course at a constant offset from the gyro has no residual, and the line through
    its n neighbours within ±5 s (equal σ, symmetric in time) has σ/√n at its centre, so the
    bound is 1.96·σ/√n (λ 1: the stated σ is not exceeded)."""
    t = np.arange(0.0, 60.0, 1.0 / rate_hz)
    result = _judged(t, np.full(t.size, 0.7), np.zeros(t.size))
    middle = np.abs(t - 30.0) < 20.0
    n = epochs_in_window(t, 5.0)[middle]  # 10·rate, or one less where ±5 s falls between floats
    assert np.all(np.abs(n - 10 * rate_hz) <= 1)
    protection = course_protection(result.course)
    np.testing.assert_allclose(result.course.residual[middle], 0.0, atol=1e-12)
    np.testing.assert_allclose(protection[middle], 1.96 * STATED_SIGMA / np.sqrt(n), rtol=1e-6)
    assert result.course.sigma_factor == 1.0


@pytest.mark.parametrize("rate_hz", RATES_HZ)
def test_an_epoch_among_failed_neighbours_is_not_valid_at_any_rate(rate_hz):
    """Every other epoch within ±5 s failed its GNSS tests: the window holds epochs enough
    (±5 s: 10 at 1 Hz) but none to compare with, so the epoch cannot be confirmed and is not
    valid, flagged untested; where the sensors do not cover it, it keeps the GNSS verdict."""
    t, course, angle, _ = _courses(rate_hz)
    valid = np.abs(t - 60.0) > 5.5
    k = int(np.argmin(np.abs(t - 60.0)))
    valid[k] = True
    result = _judged(t, course, angle, valid)
    assert result.untested[k] and not result.valid[k]
    assert result.untested.sum() == 1
    uncovered = angle.copy()
    uncovered[k] = np.nan
    kept = _judged(t, course, uncovered, valid)
    assert kept.valid[k] and not kept.untested[k]


@pytest.mark.parametrize(
    "interval_s, warns", [(0.05, False), (1.0, False), (2.0, True), (5.0, True)]
)
def test_a_rate_the_window_cannot_judge_is_named(interval_s, warns):
    """±5 s holds 200, 10, 4 or 2 other epochs at 20, 1, 0.5 and 0.2 Hz; the test needs 5."""
    t = np.arange(0.0, 300.0, interval_s)
    warning = integrity_rate_warning(t)
    assert (warning is not None) is warns
    if warns:
        assert warning == (
            "conventional velocity against the gyro and wheels (I1): 100% of the epochs have "
            f"fewer than 5 others within ±5 s (they are {interval_s:g} s apart) and keep the "
            "GNSS stage's verdict"
        )
    assert integrity_rate_warning(t, ConsistencyConfig(enabled=False)) is None


def test_a_velocity_climbing_beyond_a_cars_road_is_not_valid_whatever_its_sigma():
    """3·√((0.1·s)² + 0.1²): 2.419 m/s at 8 m/s, 0.3 m/s at rest; unknown is not a car's."""
    velocity = np.array(
        [[8.0, 0.0, 2.41], [0.0, -8.0, -2.43], [0.0, 0.0, 0.29], [0.0, 0.0, 0.31], [np.nan] * 3]
    )
    np.testing.assert_array_equal(car_vertical_bound(velocity), [True, False, True, False, False])
    t, course, angle, _ = _courses(1.0)
    bound = np.ones(t.size, bool)
    bound[60] = False
    result = _judged(t, course, angle, vertical_bound=bound)
    assert not result.valid[60] and np.isnan(result.course.z[60])  # not tested: not usable
    assert result.valid[bound].all()


def test_the_rest_bound_is_the_rayleigh_quantile_of_the_measured_rest_noise():
    """Exact: speeds whose median is m give σ = m / √(2 ln 2) and the bound σ·√(−2 ln 0.01);
    up to half of them faulty leave it; too few epochs or noisy rest give the fixed cap."""
    speed = np.full(21, 0.05)
    speed[:10] = 5.0  # ten faulty fixes among 21 epochs at rest
    sigma = 0.05 / np.sqrt(2.0 * np.log(2.0))
    expected = sigma * np.sqrt(-2.0 * np.log(0.01))
    assert rest_speed_bound(speed, np.ones(21, bool)) == pytest.approx(expected, rel=1e-12)
    assert expected == pytest.approx(0.1289, abs=1e-4)
    assert rest_speed_bound(speed, np.arange(21) < 9) == AT_REST_MAX_MPS  # nine epochs
    assert rest_speed_bound(np.full(30, 0.5), np.ones(30, bool)) == AT_REST_MAX_MPS
    healthy = np.hypot(*np.random.default_rng(4).normal(0.0, 0.03, (2, 20000)))
    bound = rest_speed_bound(healthy, np.ones(healthy.size, bool))
    assert np.mean(healthy > bound) == pytest.approx(0.01, abs=0.003)


@pytest.mark.parametrize("rate_hz", RATES_HZ)
def test_a_velocity_at_rest_is_valid_within_the_rest_noise_and_moving_by_the_course_bound(
    rate_hz,
):
    """A drive at any rate: 20 s at rest (speeds 0.02–0.06 m/s, one fix pulled to 0.5 m/s),
    then 8 m/s with an 8° course fault of 3 s. At rest the velocity is valid within the rest
    bound (the course is undefined there, and the course table says not valid), moving the
    course bound judges it as it judges the course; without wheels the GNSS verdict stays."""
    t, course, angle, fault = _courses(rate_hz, fault_deg=8.0)
    rest = t < 20.0
    rng = np.random.default_rng(7)
    speed = np.where(rest, rng.uniform(0.02, 0.06, t.size), 8.0)
    pulled = int(np.argmin(np.abs(t - 10.0)))
    speed[pulled] = 0.5
    wheel = np.where(rest, 0.0, 8.0)
    n = t.size
    integrity = _judged(t, course, angle, ~rest, wheel, speed)
    checked = velocity_integrity(integrity, np.ones(n, bool), speed, wheel)
    assert 0.06 < checked.rest_bound_mps < 0.12
    expected_rest = rest & (np.arange(n) != pulled)
    np.testing.assert_array_equal(checked.valid[rest], expected_rest[rest])
    np.testing.assert_array_equal(checked.valid[~rest], integrity.valid[~rest])
    assert not checked.valid[fault].any() and checked.valid[~rest & ~fault].mean() > 0.8
    without_wheels = velocity_integrity(integrity, ~fault, speed, np.full(n, np.nan))
    np.testing.assert_array_equal(without_wheels.valid, ~fault)


def test_a_slow_cars_course_may_be_as_uncertain_as_the_rest_noise():
    """At 0.5 m/s a course 10° off is 0.09 m/s across the track, within the rest bound: the
    velocity is valid though the course (5° alert limit) is not; at 8 m/s it is neither."""
    t = np.arange(0.0, 60.0)
    n = t.size
    yaw = np.zeros(n)
    course = np.where(t == 30.0, np.radians(10.0), 0.0)
    result = {}
    for speed_mps in (0.5, 8.0):
        speed = np.full(n, speed_mps)
        integrity = _judged(t, course, yaw, None, speed, speed, np.radians(12.0), 0.05)
        checked = velocity_integrity(integrity, np.ones(n, bool), speed, speed)
        assert not integrity.valid[30]
        result[speed_mps] = checked.valid[30]
    assert result == {0.5: True, 8.0: False}


def test_the_checked_velocity_carries_the_tables_verdict_only():
    t = np.arange(5.0)
    velocity = velocity_solution(t, np.tile([3.0, 4.0, 0.1], (5, 1)))
    verdict = np.array([1, 0, 1, 0, 0], bool)
    checked = car_checked_velocity(velocity, plain_heading_table(t, conv_velocity_valid=verdict))
    np.testing.assert_array_equal(checked.valid, verdict)
    np.testing.assert_array_equal(checked.velocity_enu, velocity.velocity_enu)
    assert car_checked_velocity(velocity, plain_heading_table(t)) is velocity
    shorter = plain_heading_table(t[:4], conv_velocity_valid=verdict[:4])
    with pytest.raises(ValueError, match="4 epochs, the velocity 5"):
        car_checked_velocity(velocity, shorter)
