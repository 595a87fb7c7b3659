"""Conventional velocity integrity against the gyro and the wheel speed (design (I1))."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.geo import EnuFrame, wrap_angle
from vo_doppler.gnss.doppler_velocity import solve_velocity
from vo_doppler.gnss.windowed_line import ConsistencyConfig
from vo_doppler.heading.from_gnss import heading_from_gnss
from vo_doppler.heading.integrity import conventional_integrity
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.series import SensorSeries
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
    table = heading_from_gnss(t, rows, velocity, wheel, gyro, FRAME, HeadingPipelineConfig())
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
    unchecked = heading_from_gnss(t, rows, velocity, wheel, gyro, FRAME, off)
    np.testing.assert_array_equal(unchecked.conv_valid, velocity.valid)
    np.testing.assert_array_equal(unchecked.yaw_tc, table.yaw_tc)  # tight heading untouched


def test_a_speed_while_the_wheels_stand_fails_whatever_its_sigma():
    t = np.arange(20.0)
    valid = np.ones(20, bool)
    speed = np.full(20, 0.05)
    speed[10] = 0.75  # reflected satellites pulled the fix
    wheel = np.zeros(20)
    result = conventional_integrity(
        t, valid, np.zeros(20), None, np.zeros(20), speed, np.full(20, 0.3), wheel, np.zeros(20)
    )
    assert not result.valid[10] and result.valid[[9, 11]].all()
    moving = conventional_integrity(
        t,
        valid,
        np.zeros(20),
        None,
        np.zeros(20),
        speed + 5,
        np.full(20, 0.3),
        wheel + 5,
        np.zeros(20),
    )
    assert moving.valid[10]  # 0.75 m/s off at 5 m/s is within the speed test's 3σ here
