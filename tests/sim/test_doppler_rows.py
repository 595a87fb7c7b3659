"""Synthetic Doppler rows exact by construction: lines of sight from azimuth and elevation, range
rates that the receiver's velocity and clock drift explain exactly, the satellites of each epoch,
and gyro samples whose rate integrates to the heading changes."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.sim.doppler_rows import gyro_from_heading, line_of_sight, simulate_doppler

AZIMUTH = np.array([0.0, 90.0, 180.0, 270.0, 45.0, 300.0])
ELEVATION = np.array([30.0, 45.0, 60.0, 20.0, 80.0, 10.0])


def test_lines_of_sight_point_east_north_up_from_azimuth_and_elevation():
    los = line_of_sight(np.radians([0.0, 90.0, 45.0]), np.radians([0.0, 0.0, 90.0]))
    np.testing.assert_allclose(los, [[0, 1, 0], [1, 0, 0], [0, 0, 1]], atol=1e-15)
    np.testing.assert_allclose(np.linalg.norm(line_of_sight(AZIMUTH, ELEVATION), axis=1), 1.0)


def test_the_reduced_range_rates_are_the_vehicles_velocity_and_clock_drift():
    t = np.arange(10.0)
    scenario = simulate_doppler(
        t, lambda t: 0.1 * t, lambda t: 5.0 + 0.0 * t, AZIMUTH, ELEVATION, clock_drift0=100.0
    )
    rows = scenario.rows
    assert len(rows) == 10 * 6
    epoch = np.repeat(np.arange(10), 6)
    velocity = 5.0 * np.column_stack([np.cos(0.1 * t), np.sin(0.1 * t), np.zeros(10)])
    # y = −G·v + ρ, with ρ = 100 + 0.3 (t − t0)
    expected = -np.einsum("ni,ni->n", rows.los, velocity[epoch]) + (100.0 + 0.3 * t)[epoch]
    np.testing.assert_allclose(rows.reduced(), expected, atol=1e-9)
    np.testing.assert_allclose(scenario.yaw_angle, 0.1 * t, atol=1e-15)
    np.testing.assert_allclose(rows.sigma(), 0.05)


def test_each_epoch_takes_the_next_satellites_in_turn_or_always_the_first():
    t = np.arange(3.0)
    still = (lambda t: 0.0 * t, lambda t: 0.0 * t)
    turning = simulate_doppler(t, *still, AZIMUTH, ELEVATION, sats_per_epoch=4)
    assert list(turning.rows.sat_id) == [f"G{k:02d}" for k in range(1, 7)] * 2
    fixed = simulate_doppler(t, *still, AZIMUTH, ELEVATION, sats_per_epoch=4, rotate=False)
    assert list(fixed.rows.sat_id) == ["G01", "G02", "G03", "G04"] * 3


def test_noise_has_the_asked_spread_and_sets_the_weights():
    t = np.arange(400.0)
    quiet = simulate_doppler(t, lambda t: 0.0 * t, lambda t: 0.0 * t + 3.0, AZIMUTH, ELEVATION)
    noisy = simulate_doppler(
        t, lambda t: 0.0 * t, lambda t: 0.0 * t + 3.0, AZIMUTH, ELEVATION, noise_mps=0.2
    )
    error = noisy.rows.range_rate - quiet.rows.range_rate
    assert np.std(error) == pytest.approx(0.2, rel=0.05) and abs(np.mean(error)) < 0.02
    np.testing.assert_allclose(noisy.rows.sigma(), 0.2)


def test_the_gyro_rate_is_each_intervals_heading_change_plus_its_bias():
    t = np.arange(0.0, 5.0)
    yaw = np.array([3.0, 3.1, -3.1, -3.0, np.nan])  # across ±π, then missing
    valid = np.array([True, True, True, True, False])
    t_gyro, rate = gyro_from_heading(t, yaw, valid, bias=0.01, noise_rad_s=0.0, rate_hz=2.0)
    np.testing.assert_allclose(t_gyro, [0.25, 0.75, 1.25, 1.75, 2.25, 2.75, 3.25, 3.75])
    step = 2 * np.pi - 6.2  # 3.1 → −3.1 is +0.0832 rad, not −6.2
    np.testing.assert_allclose(rate, np.array([0.1, 0.1, step, step, 0.1, 0.1, 0.0, 0.0]) + 0.01)
