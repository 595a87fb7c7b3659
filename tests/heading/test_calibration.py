"""Wheel scale (sec. 3.3) and gyro bias (sec. 3.4) from Doppler: exact, streaming, Kalman, real."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.geo import course_to_yaw, ecef_to_enu_rotation, ecef_to_geodetic, wrap_angle
from vo_doppler.heading.calibration import (
    PRIOR_GYRO_BIAS_SIGMA,
    PRIOR_WHEEL_SCALE_SIGMA,
    GateConfig,
    GyroBiasCalibrator,
    GyroBiasKalman,
    WheelScaleCalibrator,
    WheelScaleKalman,
    estimate_gyro_bias,
    estimate_wheel_scale,
    huber_line,
    variation_gate,
)
from vo_doppler.heading.pipeline import HeadingPipelineConfig, causal_calibration
from vo_doppler.io.can import read_can_motion
from vo_doppler.io.comma2k19 import gps_minus_log
from vo_doppler.model.timeseries import integral_at, sample

COMMA = "comma2k19_example1"
GPS_MINUS_UTC_2018_S = 18.0
GPS_EPOCH_UNIX_S = 315964800.0


def _drive(n=300, rate_hz=10.0, seed=0):
    """A car weaving at 5–15 m/s with the heading crossing ±π; returns truth arrays."""
    t = np.arange(n) / rate_hz
    speed = 10.0 + 5.0 * np.sin(0.2 * t)
    yaw_rate = 0.3 * np.sin(0.35 * t) + 0.05
    yaw = wrap_angle(
        3.0 + np.concatenate([[0.0], np.cumsum(0.5 * (yaw_rate[1:] + yaw_rate[:-1]) / rate_hz)])
    )
    return t, speed, yaw_rate, yaw


def test_exact_wheel_scale_and_spikes_rejected():
    t, speed, _, _ = _drive()
    wheel = speed / 1.0123
    doppler = speed.copy()
    doppler[[40, 41 + 60, 200]] += [3.0, -2.0, 5.0]  # Doppler glitches
    estimate = estimate_wheel_scale(t, doppler, wheel)
    assert estimate.value == pytest.approx(1.0123, abs=1e-12)
    assert estimate.n_rejected == 3 and estimate.n_used == len(t) - 3
    assert estimate.sigma < 1e-10


def test_huber_line_is_least_squares_on_clean_data_and_ignores_a_coherent_burst():
    rng = np.random.default_rng(3)
    x = np.linspace(-30.0, 30.0, 601)
    y = 2.0 - 0.005 * x + rng.normal(0.0, 0.01, x.size)
    plain = huber_line(x, y, np.zeros(x.size, int), k=np.inf)
    xc, yc = x - x.mean(), y - y.mean()
    assert plain.slope == pytest.approx((xc @ yc) / (xc @ xc), rel=1e-12)
    assert huber_line(x, y, np.zeros(x.size, int)).slope == pytest.approx(-0.005, abs=1e-4)
    burst = y.copy()
    burst[400:460] += 0.35  # six seconds of a course 20° off, all together
    robust = huber_line(x, burst, np.zeros(x.size, int))
    least = huber_line(x, burst, np.zeros(x.size, int), k=np.inf)
    assert robust.slope == pytest.approx(-0.005, abs=2e-4)
    assert abs(least.slope + 0.005) > 10 * abs(robust.slope + 0.005)
    assert robust.weights[400:460].max() < 0.1 and np.median(robust.weights[:400]) == 1.0


def test_gyro_bias_and_wheel_scale_hold_through_reflected_conventional_velocities():
    """A burst of conventional velocities from reflected signals: course 25° off and speed
    0.8 m/s off for 4 s of a 30 s drive, passing the variation gate together."""
    rng = np.random.default_rng(5)
    t, speed, yaw_rate, yaw = _drive()
    bias = np.radians(0.3)
    phi = integral_at(t, yaw_rate + bias, t)
    doppler_yaw = wrap_angle(yaw + rng.normal(0.0, np.radians(0.3), len(t)))
    doppler_speed = speed + rng.normal(0.0, 0.03, len(t))
    doppler_yaw[200:240] = wrap_angle(doppler_yaw[200:240] + np.radians(25.0))
    doppler_speed[200:240] += 0.8
    wheel = speed / 0.98
    b = estimate_gyro_bias(t, doppler_yaw, phi, doppler_speed)
    k = estimate_wheel_scale(t, doppler_speed, wheel)
    assert b.n_rejected < 5 and k.n_rejected < 5  # the gate lets the burst through
    assert abs(np.degrees(b.value) - 0.3) < 0.02 and abs(k.value - 0.98) < 0.001
    least = GateConfig(huber_k=np.inf)
    b_ls = estimate_gyro_bias(t, doppler_yaw, phi, doppler_speed, config=least)
    assert abs(np.degrees(b_ls.value) - 0.3) > 0.2


def test_exact_gyro_bias_across_the_wrap():
    t, speed, yaw_rate, yaw = _drive()
    bias = np.radians(0.5)
    phi = integral_at(t, yaw_rate + bias, t)  # trapezoid, same rule as the truth
    doppler_yaw = yaw.copy()
    doppler_yaw[[100, 250]] += np.radians([20.0, -15.0])
    estimate = estimate_gyro_bias(t, doppler_yaw, phi, speed)
    assert estimate.value == pytest.approx(bias, abs=1e-12)
    assert estimate.n_rejected == 2


def test_low_speed_course_is_not_used_and_too_few_samples_is_unavailable():
    t, speed, yaw_rate, yaw = _drive(n=40)
    slow = np.full_like(speed, 0.5)
    phi = integral_at(t, yaw_rate, t)
    assert not estimate_gyro_bias(t, yaw, phi, slow).valid
    assert not estimate_wheel_scale(t[:5], speed[:5], speed[:5]).valid
    valid = np.zeros(len(t), dtype=bool)
    assert not estimate_wheel_scale(t, speed, speed, doppler_valid=valid).valid


def test_the_gyro_bias_needs_samples_over_the_minimum_span():
    """Exact courses give the exact bias once they span 3 s, and none before; a half-second
    reflection episode at the start (courses 1° off) tilts a 1-s fit by 1.4 deg/s but a 3-s one
    by a fifth of that (least squares: 6·δ·e·(T − e)/T³ for an offset δ over the first e of T
    seconds)."""
    t, speed, yaw_rate, yaw = _drive(n=40)
    bias = np.radians(0.3)
    phi = integral_at(t, yaw_rate + bias, t)

    def first(span, course=yaw, config=None):
        n = int(np.sum(t <= span + 1e-9))
        config = config or GateConfig()
        return estimate_gyro_bias(t[:n], course[:n], phi[:n], speed[:n], config=config)

    assert not first(2.9).valid
    assert first(3.0).value == pytest.approx(bias, abs=1e-12)
    episode = yaw + np.where(t < 0.45, np.radians(1.0), 0.0)
    short = GateConfig(min_bias_span_s=0.0, huber_k=np.inf)
    tilted = {span: first(span, episode, short).value - bias for span in (1.0, 3.0)}
    assert abs(np.degrees(tilted[1.0])) > 1.2
    assert abs(tilted[3.0]) < 0.25 * abs(tilted[1.0])


def test_variation_gate_keeps_neighbours_of_a_spike():
    t = np.arange(6.0)
    d = np.array([0.0, 0.0, 9.0, 0.0, 0.0, 0.0])
    keep = variation_gate(t, d, 0.5, 0.0, np.ones(6, dtype=bool))
    np.testing.assert_array_equal(keep, [True, True, False, True, True, True])


@pytest.mark.slow
def test_streaming_least_squares_follows_a_change_after_one_window():
    config = GateConfig(window_s=20.0)
    t, speed, yaw_rate, yaw = _drive(n=800)
    bias = np.where(t < 40.0, np.radians(0.2), np.radians(-0.3))
    phi = integral_at(t, yaw_rate + bias, t)
    gyro = GyroBiasCalibrator(config)
    wheel = WheelScaleCalibrator(config)
    scale = np.where(t < 40.0, 1.01, 0.98)
    history = []
    for i in range(len(t)):
        b = gyro.add(t[i], yaw[i], phi[i], speed[i])
        k = wheel.add(t[i], speed[i], speed[i] / scale[i])
        history.append((b.value, k.value))
    history = np.array(history)
    i_before = np.searchsorted(t, 39.0)
    assert history[i_before, 0] == pytest.approx(np.radians(0.2), abs=1e-9)
    assert history[i_before, 1] == pytest.approx(1.01, abs=1e-12)
    assert history[-1, 0] == pytest.approx(np.radians(-0.3), abs=1e-9)
    assert history[-1, 1] == pytest.approx(0.98, abs=1e-12)


def test_kalman_variants_converge_with_noise():
    rng = np.random.default_rng(3)
    t, speed, yaw_rate, yaw = _drive(n=1200)
    bias = np.radians(0.4)
    phi = integral_at(t, yaw_rate + bias + rng.normal(0, np.radians(0.2), len(t)), t)
    doppler_yaw = yaw + rng.normal(0, np.radians(0.3), len(t))
    doppler_speed = speed + rng.normal(0, 0.05, len(t))
    wheel = speed / 1.02
    kb, kw = GyroBiasKalman(), WheelScaleKalman()
    sigmas = []
    for i in range(len(t)):
        b = kb.add(t[i], doppler_yaw[i], phi[i], doppler_speed[i])
        k = kw.add(t[i], doppler_speed[i], wheel[i])
        sigmas.append(b.sigma)
    assert abs(b.value - bias) < max(3 * b.sigma, np.radians(0.02))
    assert abs(k.value - 1.02) < max(3 * k.sigma, 5e-4)
    assert sigmas[-1] < sigmas[50] / 3


def test_kalman_with_the_prior_equals_least_squares_with_the_prior():
    """Linear-Gaussian case: no random walk, Kalman measurement noise equal to the residual
    spread that least squares estimates (the Huber fits with k = ∞), every sample accepted by
    both gates. The Kalman filters started at the prior then give least squares combined with
    the same prior."""
    rng = np.random.default_rng(11)
    t, speed, yaw_rate, yaw = _drive(n=100)
    bias, scale = np.radians(0.7), 1.04
    phi = integral_at(t, yaw_rate + bias, t)
    doppler_yaw = wrap_angle(yaw + rng.normal(0.0, np.radians(0.5), len(t)))
    doppler_speed = speed + rng.normal(0.0, 0.05, len(t))
    wheel = speed / scale
    valid = np.ones(len(t), dtype=bool)
    least_squares = GateConfig(huber_k=np.inf)
    config = HeadingPipelineConfig(gate=least_squares)
    ls = causal_calibration(t, doppler_speed, doppler_yaw, valid, wheel, phi, config)

    fit_b = estimate_gyro_bias(t, doppler_yaw, phi, doppler_speed, config=least_squares)
    fit_k = estimate_wheel_scale(t, doppler_speed, wheel, config=least_squares)
    assert fit_b.n_used == fit_k.n_used == len(t)
    yaw_sigma = fit_b.sigma * np.sqrt(np.sum((t - t.mean()) ** 2))
    speed_sigma = fit_k.sigma * np.sqrt(wheel @ wheel)
    kb = GyroBiasKalman(yaw_sigma, bias_walk_rad_s_per_sqrt_s=0.0)
    kw = WheelScaleKalman(speed_sigma, q_per_sqrt_s=0.0)
    for i in range(len(t)):
        b = kb.add(t[i], doppler_yaw[i], phi[i], doppler_speed[i])
        k = kw.add(t[i], doppler_speed[i], wheel[i])
    assert b.n_used == k.n_used == len(t)
    assert b.value == pytest.approx(ls.bias[-1], abs=1e-9)
    assert b.sigma == pytest.approx(ls.bias_sigma[-1], rel=1e-9)
    assert k.value == pytest.approx(ls.scale[-1], abs=1e-9)
    assert k.sigma == pytest.approx(ls.scale_sigma[-1], rel=1e-9)
    # The prior pulls both estimates off the data's own by far more than the tolerance.
    assert abs(ls.bias[-1] - fit_b.value) > 1e-6 and abs(ls.scale[-1] - fit_k.value) > 1e-6


def test_kalman_stays_at_the_prior_without_informative_samples():
    assert HeadingPipelineConfig().prior_gyro_bias_sigma_rad_s == PRIOR_GYRO_BIAS_SIGMA
    assert HeadingPipelineConfig().prior_wheel_scale_sigma == PRIOR_WHEEL_SCALE_SIGMA
    kb = GyroBiasKalman(config=GateConfig(min_bias_span_s=0.0))  # the filter alone
    kw = WheelScaleKalman()
    for estimate, prior, sigma in (
        (kb.estimate, 0.0, PRIOR_GYRO_BIAS_SIGMA),
        (kw.estimate, 1.0, PRIOR_WHEEL_SCALE_SIGMA),
    ):
        assert (estimate.value, estimate.sigma, estimate.n_used) == (prior, sigma, 0)
        assert estimate.valid
    # Too slow to carry a course or a wheel speed: nothing changes.
    b = kb.add(0.0, 1.0, 0.2, 0.5)
    k = kw.add(0.0, 0.5, 0.4)
    assert (b.value, b.sigma, k.value, k.sigma) == (
        0.0,
        PRIOR_GYRO_BIAS_SIGMA,
        1.0,
        PRIOR_WHEEL_SCALE_SIGMA,
    )
    # One course sample fixes the heading offset and says nothing about the bias.
    b = kb.add(1.0, 1.0, 0.2, 10.0)
    assert (b.value, b.sigma, b.n_used) == (0.0, PRIOR_GYRO_BIAS_SIGMA, 1)
    # A 1.5° step 0.1 s later would be a 15 deg/s bias alone; the prior holds it near zero.
    b = kb.add(1.1, 1.0 + np.radians(1.5), 0.2, 10.0)
    assert b.n_used == 2
    assert abs(np.degrees(b.value)) < 0.1 and 0.99 < b.sigma / PRIOR_GYRO_BIAS_SIGMA < 1.0


def test_the_kalman_bias_needs_samples_spanning_the_minimum():
    """The bias is a slope: the filter's estimate counts only once its accepted samples span
    ``min_bias_span_s`` (as the least-squares fit's, ``GateConfig``); until then it is NaN and
    the causal calibration holds the prior."""
    t = np.arange(0.0, 4.0, 0.25)
    phi = np.radians(0.4) * t  # a 0.4 deg/s bias on a straight road heading 0
    kb = GyroBiasKalman(config=GateConfig(min_bias_span_s=3.0))
    spans = []
    for tk, phik in zip(t, phi, strict=True):
        spans.append((tk - t[0], kb.add(tk, 0.0, phik, 10.0)))
    for span, estimate in spans:
        assert estimate.valid == (span >= 3.0)
    assert spans[-1][1].n_used == len(t)
    assert spans[-1][1].value == pytest.approx(np.radians(0.4), rel=0.05)
    config = HeadingPipelineConfig(calibration="kalman")
    cal = causal_calibration(
        t,
        np.full(t.size, 10.0),
        np.zeros(t.size),
        np.ones(t.size, bool),
        np.full(t.size, 10.0),
        phi,
        config,
    )
    early = t < 3.0
    np.testing.assert_array_equal(cal.bias_estimated, ~early)
    np.testing.assert_array_equal(cal.bias[early], 0.0)
    np.testing.assert_array_equal(cal.bias_sigma[early], config.prior_gyro_bias_sigma_rad_s)


def _comma_ground_truth():
    """Ground-truth yaw and speed of the comma2k19 minute from ``global_pose``.

    * yaw ψ_gt: each ECEF velocity is rotated into the local ENU frame of its own position
      (geo.ecef_to_enu_rotation at the geodetic latitude/longitude of ``frame_positions``),
      ψ = atan2(v_north, v_east), unwrapped — the course as a counter-clockwise yaw.
      The camera's forward axis from ``frame_orientations`` (quaternion w,x,y,z, device x
      forward) gives the same yaw up to a constant 0.9° mounting offset (std 0.1°), which a
      bias fit absorbs; the velocity course is used because the Doppler reference is a course.
    * speed: |frame_velocities| (3-D: wheels roll along the road, which climbs here).
    """
    gp = require_shared(f"{COMMA}/global_pose")
    t = np.load(gp / "frame_times")
    velocity = np.load(gp / "frame_velocities")
    lat, lon, _ = ecef_to_geodetic(np.load(gp / "frame_positions"))
    rotation = np.stack([ecef_to_enu_rotation(a, b) for a, b in zip(lat, lon, strict=True)])
    enu = np.einsum("nij,nj->ni", rotation, velocity)
    yaw = np.unwrap(np.arctan2(enu[:, 1], enu[:, 0]))
    return t, yaw, np.linalg.norm(velocity, axis=1)


@pytest.mark.shared_data
def test_comma_can_bias_and_scale_from_receiver_doppler():
    base = require_shared(COMMA)
    motion = read_can_motion(
        base / "can_motion.log",
        base / "toyota_2017_motion.dbc",
        "KINEMATICS.YAW_RATE",  # counter-clockwise positive as decoded (checked vs the gyro)
        "WHEEL_SPEEDS.WHEEL_SPEED_RL,WHEEL_SPEEDS.WHEEL_SPEED_RR",
    )
    t_gt, yaw_gt, speed_gt = _comma_ground_truth()
    # Time bases: CAN log stamps and processed_log/global_pose `t` share the logger's
    # monotonic clock (CAN wheel-speed times equal processed_log's to 1 µs, see test_can);
    # the receiver's own time tags map it to GPS time (io.comma2k19.gps_minus_log).

    # Ground-truth values, fitted with the same models the calibration uses.
    phi_gt = integral_at(motion.yaw_rate.t, motion.yaw_rate.value, t_gt)
    ok = np.isfinite(phi_gt)
    tau = t_gt[ok] - t_gt[ok].mean()
    design = np.column_stack([np.ones(ok.sum()), tau])
    bias_gt = np.linalg.lstsq(design, phi_gt[ok] - yaw_gt[ok], rcond=None)[0][1]
    wheel_gt = sample(motion.speed.t, motion.speed.value, t_gt)
    scale_gt = np.nansum(wheel_gt * speed_gt) / np.nansum(wheel_gt**2)
    assert np.degrees(bias_gt) == pytest.approx(-0.41, abs=0.02)  # README: ≈0.4 deg/s

    # Doppler reference: the receiver's own speed/course. Its fixes carry UTC time (ms); the
    # fix epoch on the monotonic clock is GPS time − (GPS − log clock).
    gnss = require_shared(f"{COMMA}/processed_log/GNSS/live_gnss_ublox")
    fixes = np.load(gnss / "value")
    gps_s = fixes[:, 3] / 1000.0 - GPS_EPOCH_UNIX_S + GPS_MINUS_UTC_2018_S
    t_fix = gps_s - gps_minus_log(base)
    log_delay = np.load(gnss / "t") - t_fix
    assert 0.0 < np.median(log_delay) < 0.5  # fixes are logged ≈0.2 s after their epoch
    doppler_speed = fixes[:, 2]
    doppler_yaw = course_to_yaw(np.radians(fixes[:, 5]))
    phi = integral_at(motion.yaw_rate.t, motion.yaw_rate.value, t_fix)
    wheel = sample(motion.speed.t, motion.speed.value, t_fix)

    bias = estimate_gyro_bias(t_fix, doppler_yaw, phi, doppler_speed)
    scale = estimate_wheel_scale(t_fix, doppler_speed, wheel)
    assert abs(np.degrees(bias.value - bias_gt)) <= 0.05
    assert abs(scale.value / scale_gt - 1.0) <= 0.003
    assert bias.n_used > 500 and scale.n_used > 500

    kalman_bias, kalman_scale = GyroBiasKalman(), WheelScaleKalman()
    for i in np.flatnonzero(np.isfinite(phi) & np.isfinite(wheel)):
        kalman_bias.add(t_fix[i], doppler_yaw[i], phi[i], doppler_speed[i])
        kalman_scale.add(t_fix[i], doppler_speed[i], wheel[i])
    assert abs(np.degrees(kalman_bias.estimate.value - bias_gt)) <= 0.05
    assert abs(kalman_scale.estimate.value / scale_gt - 1.0) <= 0.003


def test_standstill_runs_give_the_bias_without_a_course():
    t, speed, yaw_rate, yaw = _drive(n=600)
    stopped = (t < 15.0) | ((t > 40.0) & (t < 45.0))
    true_rate = np.where(stopped, 0.0, yaw_rate)
    speed = np.where(stopped, 0.03, speed)
    bias = np.radians(-0.3)
    phi = integral_at(t, true_rate + bias, t)
    doppler_yaw = np.where(stopped, np.nan, yaw)  # no course while stopped
    only_stopped = estimate_gyro_bias(
        t[t < 15.0], doppler_yaw[t < 15.0], phi[t < 15.0], speed[t < 15.0]
    )
    assert only_stopped.value == pytest.approx(bias, abs=1e-12)
    heading_true = 3.0 + integral_at(t, true_rate, t)
    both = estimate_gyro_bias(t, np.where(stopped, np.nan, heading_true), phi, speed)
    assert both.value == pytest.approx(bias, abs=1e-12)
    assert both.n_used == len(t)
    disabled = estimate_gyro_bias(
        t[t < 15.0],
        doppler_yaw[t < 15.0],
        phi[t < 15.0],
        speed[t < 15.0],
        config=GateConfig(stationary_speed_mps=0.0),
    )
    assert not disabled.valid


def test_kalman_calibration_starts_from_the_configured_prior():
    m = 5
    t = np.arange(m, dtype=float)
    config = HeadingPipelineConfig(
        calibration="kalman",
        prior_gyro_bias_sigma_rad_s=np.radians(0.2),
        prior_wheel_scale_sigma=0.01,
    )
    out = causal_calibration(
        t, np.full(m, 10.0), np.zeros(m), np.zeros(m, bool), np.full(m, 10.0), np.zeros(m), config
    )
    np.testing.assert_allclose(out.bias, 0.0)
    np.testing.assert_allclose(out.scale, 1.0)
    np.testing.assert_allclose(out.bias_sigma, np.radians(0.2))
    np.testing.assert_allclose(out.scale_sigma, 0.01)
