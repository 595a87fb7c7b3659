"""The road grade prior from a forward accelerometer and the wheel speed: exact cases."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.heading.grade import (
    STANDARD_GRAVITY,
    GradePriorConfig,
    accelerometer_grade,
    grade_prior,
)
from vo_doppler.model.series import SensorSeries

T_SENSOR = np.arange(0.0, 30.0, 0.01)
T_EPOCH = np.arange(2.0, 30.0, 0.1)
WINDOW = 2.0
OFFSET = -0.07  # f₀/g₀: the device pitched about 4° down


def _sine_grade(t):
    """sin γ of a road whose slope grows linearly: 2 % at t = 0, +0.1 % per second."""
    return 0.02 + 0.001 * t


def _signals():
    """Speed 10 + 0.5 t (constant acceleration) and the specific force f = dv/dt + g₀ sin γ + f₀;
    both linear in time, so the trapezoid integral and the interpolation are exact."""
    speed = SensorSeries(T_SENSOR, 10.0 + 0.5 * T_SENSOR)
    force = 0.5 + STANDARD_GRAVITY * (_sine_grade(T_SENSOR) + OFFSET)
    return SensorSeries(T_SENSOR, force), speed


def test_window_mean_grade_is_exact():
    force, speed = _signals()
    grade = accelerometer_grade(T_EPOCH, WINDOW, force, speed)
    # the window mean of a linear sin γ is its value mid-window
    expected = np.tan(np.arcsin(_sine_grade(T_EPOCH - WINDOW / 2) + OFFSET))
    np.testing.assert_allclose(grade, expected, rtol=0, atol=1e-12)


def test_windows_outside_the_signals_have_no_grade():
    force, speed = _signals()
    grade = accelerometer_grade(np.array([1.0, 31.0]), WINDOW, force, speed)
    assert np.isnan(grade).all()


def _doppler(t, grade, speed=15.0):
    """Conventional velocities heading north-east on a road of ``grade`` (tan γ)."""
    horizontal = np.full_like(t, speed)
    return np.column_stack([horizontal / np.sqrt(2), horizontal / np.sqrt(2), grade * horizontal])


def test_offset_calibrated_on_the_doppler_grade():
    force, speed = _signals()
    raw = accelerometer_grade(T_EPOCH, WINDOW, force, speed)
    truth = np.tan(np.arcsin(_sine_grade(T_EPOCH - WINDOW / 2)))
    # the Doppler sees the true grade; the accelerometer's offset is a constant in sin γ, so
    # in tan γ it varies a little with the grade: the median leaves 1.5e-5 here
    valid = np.ones(T_EPOCH.size, dtype=bool)
    config = GradePriorConfig(min_samples=20)
    mean, sigma = grade_prior(raw, _doppler(T_EPOCH, truth), valid, config)
    np.testing.assert_allclose(mean, truth, atol=3e-5)
    np.testing.assert_array_equal(sigma, config.min_sigma)  # scatter 1e-5: the floor
    # with fewer velocities than min_samples there is no prior at all
    few = np.arange(T_EPOCH.size) < 19
    mean, sigma = grade_prior(raw, _doppler(T_EPOCH, truth), few, config)
    assert np.isnan(mean).all() and np.isnan(sigma).all()


def test_exact_offset_when_the_difference_is_constant():
    grade = np.linspace(-0.04, 0.05, 60)
    raw = grade + OFFSET
    valid = np.ones(60, dtype=bool)
    mean, sigma = grade_prior(raw, _doppler(np.zeros(60), grade), valid)
    np.testing.assert_allclose(mean, grade, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(sigma, GradePriorConfig().min_sigma)


def test_invalid_and_slow_epochs_do_not_calibrate_and_one_offset_serves_the_recording():
    rng = np.random.default_rng(1)
    n = 100
    grade = rng.uniform(-0.05, 0.05, n)
    velocity = _doppler(np.zeros(n), grade)
    velocity[::3] = _doppler(np.zeros(n), grade, speed=3.0)[::3]  # too slow to calibrate
    raw = grade + OFFSET + rng.normal(0.0, 0.01, n)
    valid = np.ones(n, dtype=bool)
    valid[1::3] = False
    wild = raw.copy()
    wild[~valid] += 5.0  # what invalid or slow epochs would say must not matter
    wild[::3] += 5.0
    mean, sigma = grade_prior(raw, velocity, valid)
    mean_wild, sigma_wild = grade_prior(wild, velocity, valid)
    used = valid & (np.arange(n) % 3 != 0)
    np.testing.assert_array_equal(sigma, sigma_wild)
    np.testing.assert_array_equal((raw - mean)[used], (wild - mean_wild)[used])
    # f₀ is a constant: the first epochs get the offset that the later ones give
    np.testing.assert_allclose(raw - mean, np.median((raw - grade)[used]), rtol=0, atol=1e-15)
    assert np.ptp(sigma) == 0.0
    # 1 % white noise on the accelerometer grade: σ is about 1 %
    assert sigma[0] == pytest.approx(0.01, rel=0.5)


def test_the_doppler_share_of_the_scatter_is_taken_out_of_the_prior_sigma():
    rng = np.random.default_rng(4)
    n = 4000
    grade = rng.uniform(-0.05, 0.05, n)
    speed = 10.0
    vertical_sigma = np.full(n, 0.4)  # 4 % of grade at 10 m/s: a canyon's VDOP
    velocity = _doppler(np.zeros(n), grade, speed)
    velocity[:, 2] += rng.normal(0.0, 1.0, n) * vertical_sigma
    raw = grade + OFFSET + rng.normal(0.0, 0.006, n)  # the accelerometer's own error: 0.6 %
    valid = np.ones(n, dtype=bool)
    _, blind = grade_prior(raw, velocity, valid)
    mean, sigma = grade_prior(raw, velocity, valid, vertical_sigma_mps=vertical_sigma)
    assert blind[0] == pytest.approx(np.hypot(0.04, 0.006), rel=0.1)
    assert sigma[0] == pytest.approx(0.006, abs=0.003)
    assert np.median(np.abs(mean - grade)) < 0.006
