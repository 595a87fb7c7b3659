"""The conventional heading ([TK18] sec. 3.2) on exact cases: the yaw of a velocity, its σ from
the velocity covariance, and the vehicle's yaw and speed from an antenna off its origin."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.heading.conventional import (
    heading_from_velocity,
    vehicle_heading_from_antenna,
    velocity_heading_sigma,
)


def test_the_yaw_of_a_velocity_counter_clockwise_from_east():
    velocity = np.array(
        [[1.0, 1.0, 0.0], [0.0, -2.0, 5.0], [-3.0, 0.0, 0.0], [0.3, 0.3, 9.0], [np.nan, 1, 0]]
    )
    yaw, ok = heading_from_velocity(velocity)
    np.testing.assert_allclose(yaw[:3], [np.pi / 4, -np.pi / 2, np.pi], atol=1e-15)
    np.testing.assert_array_equal(ok, [True, True, True, False, False])  # 0.42 m/s: too slow
    assert np.isnan(yaw[3:]).all()
    yaw, ok = heading_from_velocity(velocity[:3], valid=[True, False, True], min_speed_mps=2.5)
    np.testing.assert_array_equal(ok, [False, False, True])
    assert np.isnan(yaw[:2]).all() and yaw[2] == pytest.approx(np.pi)


def test_the_yaw_sigma_is_the_cross_track_velocity_sigma_over_the_speed():
    covariance = np.diag([0.04, 0.01, 9.0, 1.0])  # σ_e 0.2, σ_n 0.1 m/s; up and clock ignored
    velocity = np.array([[10.0, 0.0, 0.0], [0.0, -5.0, 0.0], [3.0, 4.0, 0.0], [0.0, 0.0, 1.0]])
    sigma = velocity_heading_sigma(velocity, np.tile(covariance, (4, 1, 1)), np.eye(3))
    # east: the north σ across; south: the east σ across; (3, 4): u = (−0.8, 0.6)
    cross = np.sqrt(0.8**2 * 0.04 + 0.6**2 * 0.01)
    np.testing.assert_allclose(sigma[:3], [0.1 / 10.0, 0.2 / 5.0, cross / 5.0], rtol=1e-12)
    assert np.isnan(sigma[3])  # no horizontal speed


def test_the_covariance_is_turned_from_ecef_to_enu():
    ecef_to_enu = Rotation.from_euler("z", np.pi / 2).as_matrix()  # ECEF x → ENU north
    covariance = np.diag([0.04, 0.01, 1.0])[None]  # σ 0.2 along ECEF x, the ENU north
    sigma = velocity_heading_sigma(np.array([[10.0, 0.0, 0.0]]), covariance, ecef_to_enu)
    assert sigma[0] == pytest.approx(0.2 / 10.0, rel=1e-12)


@pytest.mark.parametrize("lever_xy", [(0.0, 1.0), (2.0, 0.0), (-1.5, -0.8)])
def test_the_vehicles_yaw_and_speed_from_an_antenna_off_its_origin(lever_xy):
    # a vehicle at yaw 3.1 rad and 10 m/s turning at 0.4 rad/s, the antenna at r: the antenna
    # moves at (s − ω·r_y, ω·r_x) in the vehicle frame
    yaw, speed, omega = 3.1, 10.0, 0.4
    r_x, r_y = lever_xy
    along, across = speed - omega * r_y, omega * r_x
    antenna_yaw = yaw + np.arctan2(across, along)
    antenna_speed = np.hypot(along, across)
    offset = np.array([[-omega * r_y, omega * r_x]])  # ω × r
    got_yaw, got_speed = vehicle_heading_from_antenna(
        np.array([antenna_yaw]), np.array([antenna_speed]), np.array([speed]), offset
    )
    assert got_yaw[0] == pytest.approx(yaw, abs=1e-12)
    assert got_speed[0] == pytest.approx(speed, abs=1e-12)


def test_the_vehicles_yaw_is_wrapped():
    got_yaw, _ = vehicle_heading_from_antenna(
        np.array([-3.1]), np.array([10.0]), np.array([10.0]), np.array([[0.0, -1.0]])
    )
    delta = np.arctan2(-1.0, 10.0)
    assert got_yaw[0] == pytest.approx(-3.1 - delta, abs=1e-12)  # within ±π already
    got_yaw, _ = vehicle_heading_from_antenna(
        np.array([-3.1]), np.array([10.0]), np.array([10.0]), np.array([[0.0, 1.0]])
    )
    assert got_yaw[0] == pytest.approx(-3.1 - np.arctan2(1.0, 10.0) + 2 * np.pi, abs=1e-12)
