"""The receiver track for the Doppler rows: SPP fixes smoothed along the Doppler velocities."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.geo import ecef_to_enu_rotation
from vo_doppler.gnss.receiver_track import smoothed_track

ORIGIN = np.array([-3_959_000.0, 3_352_000.0, 3_697_000.0])
LAT, LON = np.radians(35.69), np.radians(139.70)
RATE_HZ = 20.0


def drive(
    seconds: float = 60.0, radius_m: float = 60.0, speed_mps: float = 10.0, rate_hz: float = RATE_HZ
):
    """Times, ECEF positions and velocities of a car circling at constant speed."""
    t = np.arange(0.0, seconds, 1.0 / rate_hz)
    angle = speed_mps * t / radius_m
    enu = radius_m * np.stack([np.sin(angle), 1.0 - np.cos(angle), np.zeros_like(t)], axis=1)
    velocity = speed_mps * np.stack([np.cos(angle), np.sin(angle), np.zeros_like(t)], axis=1)
    rotation = ecef_to_enu_rotation(LAT, LON)
    return t, enu @ rotation + ORIGIN, velocity @ rotation


def covariance(n: int, sigma_mps: float) -> np.ndarray:
    return np.broadcast_to(np.eye(4) * sigma_mps**2, (n, 4, 4)).copy()


def horizontal_error(track: np.ndarray, truth: np.ndarray) -> np.ndarray:
    rotation = ecef_to_enu_rotation(LAT, LON)
    return np.linalg.norm(((track - truth) @ rotation.T)[:, :2], axis=1)


def test_exact_fixes_and_velocities_on_a_straight_road_give_the_track_exactly():
    t = np.arange(0.0, 10.0, 0.05)
    velocity = np.array([3.0, -4.0, 1.0])
    truth = ORIGIN + t[:, None] * velocity
    track = smoothed_track(
        t,
        truth,
        np.full(t.size, 5.0),
        np.broadcast_to(velocity, truth.shape),
        covariance(t.size, 0.05),
        np.ones(t.size, bool),
    )
    np.testing.assert_allclose(track, truth, atol=1e-6)


def test_noisy_fixes_average_down_along_the_velocities():
    rng = np.random.default_rng(1)
    t, truth, velocity = drive()
    fixes = truth + rng.normal(0.0, 10.0, truth.shape)
    track = smoothed_track(
        t,
        fixes,
        np.full(t.size, 14.0),
        velocity + rng.normal(0.0, 0.05, velocity.shape),
        covariance(t.size, 0.05),
        np.ones(t.size, bool),
    )
    assert np.median(horizontal_error(fixes, truth)) > 10.0
    assert np.max(horizontal_error(track, truth)) < 2.0


def test_fixes_reflected_for_seconds_at_a_time_are_weighted_down():
    rng = np.random.default_rng(2)
    t, truth, velocity = drive()
    fixes = truth + rng.normal(0.0, 5.0, truth.shape)
    rotation = ecef_to_enu_rotation(LAT, LON)
    for start in range(0, t.size, 200):
        fixes[start : start + 40] += np.array([150.0, -80.0, 0.0]) @ rotation
    track = smoothed_track(
        t,
        fixes,
        np.full(t.size, 7.0),
        velocity,
        covariance(t.size, 0.05),
        np.ones(t.size, bool),
    )
    assert np.max(horizontal_error(track, truth)) < 4.0


def test_epochs_without_velocity_or_fix_are_bridged():
    rng = np.random.default_rng(3)
    t, truth, velocity = drive()
    fixes = truth + rng.normal(0.0, 5.0, truth.shape)
    fixes[(t > 20.0) & (t < 30.0)] = np.nan
    known = ~((t > 24.0) & (t < 26.0))
    velocity = np.where(known[:, None], velocity, np.nan)
    track = smoothed_track(
        t, fixes, np.full(t.size, 7.0), velocity, covariance(t.size, 0.05), known
    )
    assert np.all(np.isfinite(track))
    assert np.max(horizontal_error(track, truth)) < 5.0


@pytest.mark.parametrize("fixes", [0, 1])
def test_fewer_than_two_fixes_give_no_track(fixes):
    t, truth, velocity = drive(seconds=5.0)
    given = np.full_like(truth, np.nan)
    given[:fixes] = truth[:fixes]
    track = smoothed_track(
        t, given, np.full(t.size, 5.0), velocity, covariance(t.size, 0.05), np.ones(t.size, bool)
    )
    assert track is None
