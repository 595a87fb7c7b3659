"""The robust heading smoother (heading/smoother.py): exact cases, its RTS pass against
filterpy's, robustness to gross windows, the bias state, wrap-around and rate independence."""

from __future__ import annotations

import numpy as np
import pytest
from filterpy.kalman import KalmanFilter

from vo_doppler.geo import wrap_angle
from vo_doppler.heading.smoother import (
    GyroAngle,
    HeadingSmootherConfig,
    WindowHeadings,
    _Model,
    _rts,
    angle_random_walk,
    smooth_heading,
)

DEG = np.pi / 180.0
CONFIG = HeadingSmootherConfig(enabled=True)
ARW = 0.01 * DEG


def drive(rate_hz: float, duration_s: float = 120.0):
    """Times, the gyro's integrated yaw Φ (turns of 90° every 30 s) and the true yaw."""
    t = np.arange(0.0, duration_s, 1.0 / rate_hz)
    phi = 0.5 * np.pi * (1.0 + np.tanh((t % 30.0 - 15.0) / 2.0)) / 2.0 + 0.5 * np.pi * (t // 30)
    return t, phi, phi + 0.7


def smooth(t, yaw, sigma, window_s, phi, config=CONFIG, bias_sigma=0.001 * DEG):
    n = len(t)
    windows = WindowHeadings(t, yaw, np.full(n, sigma), np.full(n, window_s))
    return smooth_heading(windows, GyroAngle(phi, bias_sigma, ARW), config, 20.0 * DEG)


def test_exact_windows_give_the_true_heading_everywhere():
    t, phi, truth = drive(1.0)
    result = smooth(t, truth, 2.0 * DEG, 4.0, phi)
    assert result.available.all()
    np.testing.assert_allclose(wrap_angle(result.yaw - truth), 0.0, atol=1e-9)
    assert result.variance_factor == 1.0
    np.testing.assert_allclose(result.weight, 1.0)


def test_noise_averages_down_to_the_independent_windows():
    """σ 3° per window, 4-s windows at 1 Hz over 120 s: 30 independent windows; the smoothed
    heading's error and σ are about 3°/√(windows the gyro links), far below 3°."""
    t, phi, truth = drive(1.0)
    noise = np.random.default_rng(1).normal(0.0, 3.0 * DEG, len(t))
    result = smooth(t, truth + noise, 3.0 * DEG, 4.0, phi)
    error = np.abs(wrap_angle(result.yaw - truth))
    assert np.median(error) < 0.6 * DEG
    assert error.max() < 1.5 * DEG
    assert np.all(result.sigma < 1.5 * DEG)
    assert result.reliable.all()


def test_gross_windows_are_weighed_out():
    """A fifth of the windows 40° off (a mirror root, reflected satellites): they end with
    almost no weight and the heading stays within half a degree."""
    t, phi, truth = drive(1.0)
    rng = np.random.default_rng(2)
    yaw = truth + rng.normal(0.0, 1.0 * DEG, len(t))
    gross = rng.uniform(size=len(t)) < 0.2
    yaw[gross] += 40.0 * DEG
    result = smooth(t, yaw, 1.0 * DEG, 2.0, phi)
    assert np.max(np.abs(wrap_angle(result.yaw - truth))) < 0.5 * DEG
    assert np.all(result.weight[gross] < 0.1)
    assert np.median(result.weight[~gross]) > 0.9


def test_a_gyro_bias_error_is_tracked_by_the_bias_state():
    """Φ from a gyro whose calibrated bias is 0.02 °/s off drifts 2.4° over the drive; with the
    bias's σ given, the smoother follows the drift."""
    t, phi, truth = drive(1.0)
    drifting = phi + 0.02 * DEG * t
    noise = np.random.default_rng(3).normal(0.0, 1.0 * DEG, len(t))
    result = smooth(t, truth + noise, 1.0 * DEG, 2.0, drifting, bias_sigma=0.05 * DEG)
    assert np.max(np.abs(wrap_angle(result.yaw - truth))) < 0.6 * DEG


def test_headings_across_the_wrap():
    """A drive heading west (±π): no jump where the angle wraps."""
    t, phi, _ = drive(1.0)
    truth = np.pi - 0.01 + 0.02 * np.sin(t / 5.0)
    phi = truth - 3.0
    noise = np.random.default_rng(4).normal(0.0, 0.5 * DEG, len(t))
    result = smooth(t, wrap_angle(truth + noise), 0.5 * DEG, 2.0, phi)
    assert np.max(np.abs(wrap_angle(result.yaw - truth))) < 0.3 * DEG


def test_epochs_without_the_gyro_are_unavailable_and_split_the_runs():
    t, phi, truth = drive(1.0)
    phi = phi.copy()
    phi[50:60] = np.nan
    yaw = truth.copy()
    yaw[60:] += 10.0 * DEG  # a different offset after the gap: smoothed apart
    result = smooth(t, yaw, 1.0 * DEG, 2.0, phi)
    assert not result.available[50:60].any()
    np.testing.assert_allclose(wrap_angle(result.yaw[:50] - truth[:50]), 0.0, atol=1e-9)
    np.testing.assert_allclose(wrap_angle(result.yaw[60:] - yaw[60:]), 0.0, atol=1e-9)


def test_epochs_before_the_first_window_are_propagated_back_by_the_gyro():
    t, phi, truth = drive(1.0)
    yaw = truth.copy()
    yaw[:20] = np.nan
    result = smooth(t, yaw, 1.0 * DEG, 2.0, phi)
    np.testing.assert_allclose(wrap_angle(result.yaw[:20] - truth[:20]), 0.0, atol=1e-9)
    assert np.all(np.diff(result.sigma[:21]) < 0)


def test_an_isolated_window_is_not_reliable():
    """One window with nothing around it: the smoother carries it, but no consensus."""
    t, phi, truth = drive(1.0)
    yaw = np.full(len(t), np.nan)
    yaw[60] = truth[60]
    result = smooth(t, yaw, 0.5 * DEG, 2.0, phi)
    assert result.available[60]
    assert not result.reliable.any()


@pytest.mark.parametrize("rate_hz", [1.0, 5.0, 10.0, 20.0])
def test_the_same_drive_at_any_rate(rate_hz):
    """Windows of 4 s with the same σ: the information per second is the same at 1, 5, 10 and
    20 Hz, so the smoothed σ is too (within 15 %), and every epoch is reliable."""
    t, phi, truth = drive(rate_hz)
    result = smooth(t, truth, 2.0 * DEG, 4.0, phi)
    t_1hz, phi_1hz, truth_1hz = drive(1.0)
    reference = smooth(t_1hz, truth_1hz, 2.0 * DEG, 4.0, phi_1hz)
    middle = np.abs(t - 60.0) <= 0.5
    middle_1hz = np.abs(t_1hz - 60.0) <= 0.5
    assert result.reliable.all()
    np.testing.assert_allclose(
        np.median(result.sigma[middle]), np.median(reference.sigma[middle_1hz]), rtol=0.15
    )


def test_rts_pass_matches_filterpy():
    """The scalar forward filter and RTS pass of (S1)–(S2) equal filterpy's KalmanFilter and
    rts_smoother on the same model (no wrap: small offsets)."""
    rng = np.random.default_rng(5)
    t = np.cumsum(rng.uniform(0.5, 1.5, 60))
    phi = np.cumsum(rng.normal(0.0, 0.1, 60))
    z = 0.1 + rng.normal(0.0, 0.02, 60)
    variance = rng.uniform(1e-4, 1e-3, 60)
    rows = np.flatnonzero(rng.uniform(size=60) < 0.7)
    rows = np.concatenate([[0], rows[rows > 0]])
    q_a, scale, bias_sigma = 0.002, 0.01, 0.001
    config = HeadingSmootherConfig(bias_walk_rad_per_s_sqrt_s=1e-4)
    model = _Model(t, phi, q_a, scale, bias_sigma, config)
    offset, var = _rts(model, rows, z[rows], variance[rows])

    kf = KalmanFilter(dim_x=2, dim_z=1)
    kf.x = np.array([z[0], 0.0])
    kf.P = np.diag([variance[0], bias_sigma**2])
    kf.H = np.array([[1.0, 0.0]])
    fs, qs, rs, zs = [np.eye(2)], [np.zeros((2, 2))], [np.eye(1)], [None]
    measured = set(rows.tolist())
    for k in range(1, 60):
        dt = t[k] - t[k - 1]
        fs.append(np.array([[1.0, -dt], [0.0, 1.0]]))
        turn = scale * abs(phi[k] - phi[k - 1])
        qs.append(np.diag([q_a**2 * dt + turn**2, 1e-8 * dt]))
        rs.append(np.array([[variance[k]]]))
        zs.append(np.array([z[k]]) if k in measured else None)
    means, covariances, _, _ = kf.batch_filter(zs, Fs=fs, Qs=qs, Rs=rs)
    smoothed, smoothed_cov, _, _ = kf.rts_smoother(means, covariances, Fs=fs, Qs=qs)
    np.testing.assert_allclose(offset, smoothed[:, 0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(var, smoothed_cov[:, 0, 0], rtol=1e-9)


def test_angle_random_walk_from_sample_noise():
    """White rate noise of σ per sample every Δt integrates to σ·√Δt per √s."""
    assert angle_random_walk(0.01, 0.1) == pytest.approx(0.01 * np.sqrt(0.1), rel=1e-12)


def test_windows_the_gyro_does_not_link_give_a_large_variance_factor():
    """Course and yaw apart (a pedestrian: the offset jumps by 60° every 20 s): λ far above the
    pipeline's limit of 3, which then keeps the windows' own headings."""
    t, phi, truth = drive(1.0)
    noise = np.random.default_rng(6).normal(0.0, 1.0 * DEG, len(t))
    jumping = truth + np.radians(60.0) * ((t // 20) % 3) + noise
    result = smooth(t, wrap_angle(jumping), 1.0 * DEG, 2.0, phi)
    assert result.variance_factor > 3 * CONFIG.max_variance_factor
    assert smooth(t, truth + noise, 1.0 * DEG, 2.0, phi).variance_factor < 1.5
