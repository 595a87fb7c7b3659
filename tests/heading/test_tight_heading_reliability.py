"""Reliability of the tightly coupled heading against an independent earlier window: a fault
that lasts longer than the window passes the consecutive-epoch check but not this one."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.geo import wrap_angle
from vo_doppler.heading.tight_heading import (
    HeadingSeries,
    TightHeadingConfig,
    _independent_agreement,
    tight_heading_series,
)
from vo_doppler.sim.doppler_rows import simulate_doppler

AZIMUTH = [30.0, 110.0, 200.0, 280.0, 330.0, 160.0]
ELEVATION = [60.0, 30.0, 45.0, 20.0, 70.0, 15.0]


def fixed_windows(t) -> np.ndarray:
    """Every window of the default minimum length (as before windows could grow)."""
    return np.full(len(t), TightHeadingConfig().window_s)


def test_the_threshold_combines_both_sigmas_and_the_propagated_gyro_bias():
    config = TightHeadingConfig(window_s=2.0, reliability_gate_rad=0.01, reliability_n_sigma=3.0)
    t = np.array([0.0, 1.0, 5.0, 5.5])
    sigma = np.array([0.03, 0.1, 0.04, 0.04])
    bias_sigma = np.full(4, 0.004)
    # Epoch 2 (t = 5) refers to epoch 1 (the last at t ≤ 3): allowed 3·√(0.04² + 0.1² + 0.016²).
    allowed = 3.0 * np.sqrt(0.04**2 + 0.1**2 + (0.004 * 4.0) ** 2)
    yaw_angle = np.array([0.0, 0.2, 0.5, 0.5])
    for offset, expected in ((0.999 * allowed, True), (1.001 * allowed, False)):
        yaw = np.array([1.0, 1.0, 1.3 + offset, 1.3])
        every = np.ones(4, bool)
        agree = _independent_agreement(
            every,
            every,
            HeadingSeries(yaw, sigma, every, t),
            (yaw_angle, bias_sigma),
            fixed_windows(t),
            config,
        )
        # Epochs 0 and 1 have no window before theirs; epoch 3 refers to epoch 1 as well.
        np.testing.assert_array_equal(agree, [True, True, expected, True])


def test_unavailable_epochs_are_never_the_reference():
    config = TightHeadingConfig(window_s=2.0, reliability_gate_rad=0.05)
    t = np.arange(6.0)
    yaw = np.array([0.0, 1.0, 0.0, 0.0, 0.0, 0.0])
    gyro = (np.zeros(6), np.zeros(6))
    sigma = np.full(6, 0.01)
    available = np.array([True, False, True, True, True, True])
    agree = _independent_agreement(
        available,
        available,
        HeadingSeries(yaw, sigma, available, t),
        gyro,
        fixed_windows(t),
        config,
    )
    np.testing.assert_array_equal(agree, available)
    every = np.ones(6, bool)
    # Epoch 1 has no window before it; epoch 3 refers to it and disagrees.
    agree = _independent_agreement(
        every, every, HeadingSeries(yaw, sigma, every, t), gyro, fixed_windows(t), config
    )
    np.testing.assert_array_equal(agree, [True, True, True, False, True, True])


def test_a_wrong_reliable_heading_cannot_lock_the_right_ones_out():
    config = TightHeadingConfig(window_s=2.0, reliability_gate_rad=0.05, prior_max_age_s=10.0)
    t = np.arange(20.0)
    yaw = np.where(t < 2.0, 1.0, 0.0)  # the first window's headings are wrong
    every = np.ones(20, bool)
    agree = _independent_agreement(
        every,
        every,
        HeadingSeries(yaw, np.full(20, 0.01), every, t),
        (np.zeros(20), np.zeros(20)),
        fixed_windows(t),
        config,
    )
    # Until the wrong reference at t = 1 is older than 10 s (epoch 12), the right headings
    # disagree with it; then the last available heading a window earlier (right) serves.
    np.testing.assert_array_equal(agree, (t < 2.0) | (t >= 12.0))


def test_a_vague_reference_confirms_nothing_and_the_window_must_verify_itself():
    config = TightHeadingConfig(
        window_s=2.0, reliability_gate_rad=0.05, reference_max_sigma_rad=0.2, prior_max_age_s=10.0
    )
    t = np.array([0.0, 3.0])
    yaw = np.array([0.0, 1.5])  # 86° apart, within 3σ of the vague reference
    gyro = (np.zeros(2), np.zeros(2))
    every = np.ones(2, bool)
    for sigma_reference, verifiable, expected in (
        (0.5, np.array([True, False]), False),
        (0.5, np.array([True, True]), True),
        (0.19, np.array([True, True]), False),  # informative: it disagrees
    ):
        sigma = np.array([sigma_reference, 0.01])
        agree = _independent_agreement(
            every, verifiable, HeadingSeries(yaw, sigma, every, t), gyro, fixed_windows(t), config
        )
        np.testing.assert_array_equal(agree, [True, expected])


def test_the_first_windows_of_a_drive_verify_themselves_or_a_later_window_confirms_them():
    config = TightHeadingConfig(window_s=2.0, reliability_gate_rad=0.05, prior_max_age_s=10.0)
    gyro = (np.zeros(3), np.zeros(3))
    sigma = np.full(3, 0.01)
    every = np.ones(3, bool)
    verifiable = np.array([False, True, False])
    for t, yaw, expected in (
        # epoch 0 has no window before it; epoch 2 (t ≥ 2) is the first one after it
        ([0.0, 1.0, 2.5], [0.0, 0.0, 0.0], [True, True, True]),
        ([0.0, 1.0, 2.5], [0.0, 0.0, 1.0], [False, True, False]),
        # nothing within 10 s after epoch 0: only its own window could vouch for it
        ([0.0, 1.0, 12.5], [0.0, 0.0, 0.0], [False, True, True]),
    ):
        agree = _independent_agreement(
            every,
            verifiable,
            HeadingSeries(np.array(yaw), sigma, every, np.array(t)),
            gyro,
            fixed_windows(t),
            config,
        )
        np.testing.assert_array_equal(agree, expected)


def test_the_gyro_drift_since_the_reference_counts_towards_its_vagueness():
    config = TightHeadingConfig(
        window_s=2.0, reliability_gate_rad=0.05, reference_max_sigma_rad=0.1
    )
    t = np.array([0.0, 5.0])
    sigma = np.array([0.06, 0.01])
    yaw = np.array([0.0, 0.0])
    every = np.ones(2, bool)
    first_only = np.array([True, False])
    # √(0.06² + (b·5)²) against 0.1: b = 0.0159 gives 0.0996, b = 0.0161 gives 0.1004.
    for bias_sigma, expected in ((0.0159, True), (0.0161, False)):
        gyro = (np.zeros(2), np.full(2, bias_sigma))
        agree = _independent_agreement(
            every, first_only, HeadingSeries(yaw, sigma, every, t), gyro, fixed_windows(t), config
        )
        np.testing.assert_array_equal(agree, [True, expected])


def test_a_fault_longer_than_the_window_is_not_reliable():
    """Four seconds of Doppler rows consistent with a velocity 0.5 rad off the gyro's (as when
    snooping keeps a consistent set of reflected satellites): the windows inside that stretch
    fit it closely and agree with each other, but not with the window before it."""
    t = np.arange(0.0, 30.0, 0.05)

    def true_yaw(s):
        return 0.7 + 0.02 * s

    def doppler_yaw(s):
        return true_yaw(s) + 0.5 * ((s >= 10.0) & (s < 14.0))

    speed = lambda s: 10.0 + 0.0 * s  # noqa: E731
    common = (AZIMUTH, ELEVATION, None)
    truth = simulate_doppler(t, true_yaw, speed, *common, noise_mps=0.05, seed=3)
    faulty = simulate_doppler(t, doppler_yaw, speed, *common, noise_mps=0.05, seed=3)
    result = tight_heading_series(faulty.rows, t, truth.speed, truth.yaw_angle)
    error = np.abs(wrap_angle(result.yaw - truth.yaw))
    wrong = result.available & (error > np.radians(5.0))
    inside = (t >= 12.0) & (t < 14.0)
    assert wrong[inside].mean() > 0.9  # the solver does follow the faulty rows
    assert not np.any(result.reliable & wrong)
    before, after = t < 9.9, t > 16.0 + 0.05 * TightHeadingConfig().reliability_epochs
    assert result.reliable[before & (t > 0.5)].mean() == pytest.approx(1.0)
    assert result.reliable[after].mean() == pytest.approx(1.0)
