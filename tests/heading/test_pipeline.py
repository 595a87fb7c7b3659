"""Heading pipeline: causal calibration feeding the tightly coupled heading (sec. 3.3–3.5)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from vo_doppler.geo import wrap_angle
from vo_doppler.heading.calibration import GateConfig, estimate_gyro_bias
from vo_doppler.heading.conventional import ConventionalVelocity
from vo_doppler.heading.grade import grade_prior
from vo_doppler.heading.pipeline import (
    CalibrationMethod,
    CalibrationSeries,
    HeadingPipelineConfig,
    backfill_start,
    causal_calibration,
    heading_pipeline,
    tight_gyro_bias,
)
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import integral_at
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.sim.doppler_rows import gyro_from_heading, simulate_doppler

AZIMUTH = [30.0, 110.0, 200.0, 280.0, 330.0, 160.0]
ELEVATION = [60.0, 30.0, 45.0, 20.0, 70.0, 15.0]


def _drive(noise=0.05, seed=2):
    t = np.arange(0.0, 120.0, 0.1)
    scenario = simulate_doppler(
        t,
        lambda t: 1.0 + 0.5 * np.sin(0.05 * t) + 0.2 * np.sin(0.3 * t),
        lambda t: 10.0 + 4.0 * np.sin(0.04 * t),
        AZIMUTH,
        ELEVATION,
        sats_per_epoch=2,
        rotate=False,
        noise_mps=noise,
        seed=seed,
    )
    truth_velocity = scenario.speed[:, None] * np.stack(
        [np.cos(scenario.yaw), np.sin(scenario.yaw), np.zeros_like(t)], axis=1
    )
    return t, scenario, truth_velocity


def test_pipeline_calibrates_and_keeps_heading_with_two_satellites():
    t, scenario, velocity = _drive()
    rng = np.random.default_rng(5)
    open_sky = t < 60.0  # conventional velocity only in the first minute
    conv_velocity = velocity + rng.normal(0.0, 0.03, velocity.shape)
    bias = np.radians(0.5)
    t_gyro, rate = gyro_from_heading(
        t, scenario.yaw, np.ones(len(t), bool), bias, np.radians(0.05), rate_hz=50.0
    )
    wheel = SensorSeries(t, scenario.speed / 1.03)
    conventional = ConventionalVelocity(conv_velocity, open_sky)
    vehicle = VehicleSignals(wheel, SensorSeries(t_gyro, rate))
    table = heading_pipeline(t, scenario.rows, conventional, vehicle)
    assert abs(np.degrees(table.gyro_bias[-1] - bias)) < 0.05
    assert abs(table.wheel_scale[-1] / 1.03 - 1.0) < 0.003
    assert not table.conv_valid[~open_sky].any() and table.conv_valid[open_sky].mean() > 0.99
    late = t > 62.0
    error = np.degrees(np.abs(wrap_angle(table.yaw_tc - scenario.yaw)))
    assert table.tc_available[late].mean() > 0.95
    assert np.nanmedian(error[late]) < 1.0
    assert table.tc_reliable[late].mean() > 0.9
    # Without calibration the same run is worse (3 % speed error, 0.5 deg/s bias).
    plain = heading_pipeline(
        t, scenario.rows, conventional, vehicle, HeadingPipelineConfig(calibration="none")
    )
    plain_error = np.degrees(np.abs(wrap_angle(plain.yaw_tc - scenario.yaw)))
    assert np.nanmedian(plain_error[late]) > 2 * np.nanmedian(error[late])


def test_tight_gyro_bias_recovers_a_known_bias_from_tight_headings():
    t = np.arange(0.0, 120.0, 0.1)
    bias = np.radians(0.3)
    yaw = 1.0 + 0.5 * np.sin(0.05 * t)
    phi = yaw - yaw[0] + bias * t  # Φ = ∫ (ω + b) dt
    rng = np.random.default_rng(3)
    tight = yaw + rng.normal(0.0, np.radians(1.0), len(t))
    tight[::50] += np.radians(30.0)  # faults the Huber fit down-weights
    sigma = np.full(len(t), np.radians(1.0))
    reliable = np.ones(len(t), dtype=bool)
    reliable[200:300] = False
    tight[200:300] = np.nan
    speed = np.full(len(t), 10.0)
    config = HeadingPipelineConfig()
    value, value_sigma = tight_gyro_bias(t, tight, sigma, reliable, phi, speed, config)
    assert abs(value - bias) < np.radians(0.002)
    # σ: the fit's over √(epochs per window), then with the prior (which hardly counts).
    fit = estimate_gyro_bias(t, tight, phi, speed, reliable, config.gate)
    expected = fit.sigma * np.sqrt(config.tight.window_s / 0.1)
    np.testing.assert_allclose(value_sigma, expected, rtol=1e-3)
    # Vague headings do not calibrate; none left: no estimate.
    vague = np.full(len(t), 2.0 * config.tight_calibration_max_sigma_rad)
    assert tight_gyro_bias(t, tight, vague, reliable, phi, speed, config) is None


def _biased_drive():
    """:func:`_drive` with an exact wheel speed and a gyro biased by 0.3 deg/s."""
    t, scenario, velocity = _drive()
    bias = np.radians(0.3)
    t_gyro, rate = gyro_from_heading(
        t, scenario.yaw, np.ones(len(t), bool), bias, np.radians(0.05), rate_hz=50.0
    )
    return t, scenario, velocity, SensorSeries(t, scenario.speed), SensorSeries(t_gyro, rate), bias


def test_pipeline_calibrates_the_gyro_from_tight_headings_without_conventional_velocity():
    t, scenario, velocity, wheel, gyro, bias = _biased_drive()
    none = np.zeros(len(t), dtype=bool)  # a street canyon from the start
    args = (t, scenario.rows, ConventionalVelocity(velocity, none), VehicleSignals(wheel, gyro))
    table = heading_pipeline(*args)
    assert np.all(np.abs(np.degrees(table.gyro_bias - bias)) < 0.01)
    single = heading_pipeline(*args, HeadingPipelineConfig(tight_calibration=False))
    assert np.all(single.gyro_bias == 0.0)
    error = np.degrees(np.abs(wrap_angle(table.yaw_tc - scenario.yaw)))
    single_error = np.degrees(np.abs(wrap_angle(single.yaw_tc - scenario.yaw)))
    used, single_used = table.tc_reliable, single.tc_reliable
    assert np.percentile(error[used], 95) < 0.5 * np.percentile(single_error[single_used], 95)


@pytest.mark.slow
def test_tight_calibration_leaves_the_conventionally_calibrated_epochs():
    t, scenario, velocity, wheel, gyro, bias = _biased_drive()
    conv = velocity + np.random.default_rng(5).normal(0.0, 0.03, velocity.shape)
    valid = np.ones(len(t), dtype=bool)
    args = (t, scenario.rows, ConventionalVelocity(conv, valid), VehicleSignals(wheel, gyro))
    table = heading_pipeline(*args)
    single = heading_pipeline(*args, HeadingPipelineConfig(tight_calibration=False))
    raw_angle = integral_at(gyro.t, gyro.value, t)
    cal = causal_calibration(
        t,
        np.linalg.norm(conv, axis=1),
        np.arctan2(conv[:, 1], conv[:, 0]),
        valid,
        scenario.speed,
        raw_angle,
    )
    first = int(np.argmax(cal.bias_estimated))
    # the first seconds have no conventional estimate (a bias needs samples over 3 s)
    assert first > 0 and t[first] - t[0] < 5.0
    np.testing.assert_array_equal(table.gyro_bias[first:], single.gyro_bias[first:])
    assert abs(np.degrees(table.gyro_bias[0] - bias)) < 0.01  # the tight headings' bias there
    later = t > t[first] + 10.0 + 2.0 * HeadingPipelineConfig().tight.window_s
    # The same up to rounding: Φ_cal differs there by a constant (the early bias integral).
    np.testing.assert_allclose(table.yaw_tc[later], single.yaw_tc[later], rtol=0, atol=1e-8)
    np.testing.assert_array_equal(table.tc_reliable[later], single.tc_reliable[later])


def test_causal_calibration_holds_and_overrides():
    t = np.arange(0.0, 30.0, 1.0)
    speed = np.full(len(t), 10.0)
    valid = t < 15.0
    yaw = np.zeros(len(t))
    phi = 0.01 * t  # bias 0.01 rad/s, no real turn
    cal = causal_calibration(t, speed, yaw, valid, speed / 1.1, phi)
    bias, scale = cal.bias, cal.scale
    assert bias[0] == 0.0 and scale[0] == 1.0  # nothing estimated yet
    np.testing.assert_allclose(bias[-1], 0.01, atol=1e-12)
    np.testing.assert_allclose(scale[-1], 1.1, atol=1e-12)
    np.testing.assert_array_equal(bias[15:], bias[14])  # held once Doppler is gone
    fixed = HeadingPipelineConfig(fixed_gyro_bias_rad_s=0.02, fixed_wheel_scale=0.9)
    cal = causal_calibration(t, speed, yaw, valid, speed, phi, fixed)
    bias, scale = cal.bias, cal.scale
    assert np.all(bias == 0.02) and np.all(scale == 0.9)
    kalman = HeadingPipelineConfig(calibration="kalman")
    cal = causal_calibration(t, speed, yaw, valid, speed / 1.1, phi, kalman)
    bias, scale = cal.bias, cal.scale
    assert abs(bias[-1] - 0.01) < 1e-3 and abs(scale[-1] - 1.1) < 1e-3


@pytest.mark.slow
def test_conventional_speeds_far_from_the_wheel_speed_do_not_calibrate():
    t, scenario, velocity = _drive()
    rng = np.random.default_rng(6)
    conv_velocity = velocity + rng.normal(0.0, 0.03, velocity.shape)
    reflected = rng.random(len(t)) < 0.2  # NLOS-like bursts: speed 40 % too high
    conv_velocity[reflected] *= 1.4
    t_gyro, rate = gyro_from_heading(
        t, scenario.yaw, np.ones(len(t), bool), 0.0, np.radians(0.05), rate_hz=50.0
    )
    wheel = SensorSeries(t, scenario.speed / 1.03)
    valid = np.ones(len(t), bool)
    conventional = ConventionalVelocity(conv_velocity, valid)
    vehicle = VehicleSignals(wheel, SensorSeries(t_gyro, rate))
    gated = heading_pipeline(t, scenario.rows, conventional, vehicle)
    assert abs(gated.wheel_scale[-1] / 1.03 - 1.0) < 0.003
    for k, worse_than in ((np.inf, 0.02), (GateConfig().huber_k, None)):
        ungated = heading_pipeline(
            t,
            scenario.rows,
            conventional,
            vehicle,
            HeadingPipelineConfig(
                calibration_max_speed_mismatch_mps=np.inf, gate=GateConfig(huber_k=k)
            ),
        )
        error = abs(ungated.wheel_scale[-1] / 1.03 - 1.0)
        if worse_than is None:  # the Huber fit alone also holds
            assert error < 0.003
        else:  # least squares without the gate does not
            assert error > worse_than


def _with_accelerometer(t, scenario, velocity, wheel, gyro, acceleration):
    """The pipeline with every conventional velocity valid and a forward accelerometer."""
    valid = np.ones(len(t), bool)
    return heading_pipeline(
        t,
        scenario.rows,
        ConventionalVelocity(velocity, valid),
        VehicleSignals(wheel, gyro, forward_acceleration=acceleration),
    )


@pytest.mark.slow
def test_the_table_records_where_the_grade_prior_came_from():
    t, scenario, velocity = _drive(noise=0.0)
    wheel = SensorSeries(t, scenario.speed)
    gyro = SensorSeries(t, np.gradient(np.unwrap(scenario.yaw), t))
    config = HeadingPipelineConfig()
    conventional = ConventionalVelocity(velocity, np.ones(len(t), bool))
    plain = heading_pipeline(t, scenario.rows, conventional, VehicleSignals(wheel, gyro))
    assert not plain.grade_from_accelerometer.any()
    np.testing.assert_array_equal(plain.grade_prior_sigma, config.tight.grade_sigma)
    # a level road: the accelerometer reads dv/dt plus an offset of 0.2 m/s²
    acceleration = SensorSeries(t, np.gradient(scenario.speed, t) + 0.2)
    table = _with_accelerometer(t, scenario, velocity, wheel, gyro, acceleration)
    fitted = table.grade_from_accelerometer
    assert fitted[-100:].all() and not fitted[:10].any()
    np.testing.assert_array_equal(table.grade_prior_sigma[fitted], config.grade.min_sigma)
    np.testing.assert_array_equal(table.grade_prior_sigma[~fitted], config.tight.grade_sigma)


@pytest.mark.slow
def test_the_grade_prior_differentiates_the_calibrated_wheel_speed(monkeypatch):
    """A level road driven at 10 ± 6 m/s (up to 1.8 m/s² of acceleration) with wheels reading
    3 % fast: dv/dt of the raw wheel speed would put 0.55 % of grade where there is none."""
    t = np.arange(0.0, 120.0, 0.1)
    scenario = simulate_doppler(
        t,
        lambda t: 1.0 + 0.2 * np.sin(0.05 * t),
        lambda t: 10.0 + 6.0 * np.sin(0.3 * t),
        AZIMUTH,
        ELEVATION,
        seed=3,
    )
    velocity = scenario.speed[:, None] * np.stack(
        [np.cos(scenario.yaw), np.sin(scenario.yaw), np.zeros_like(t)], axis=1
    )
    t_fine = np.arange(0.0, 120.0, 0.01)
    wheel = SensorSeries(t_fine, 1.03 * (10.0 + 6.0 * np.sin(0.3 * t_fine)))
    acceleration = SensorSeries(t_fine, 1.8 * np.cos(0.3 * t_fine) + 0.2)
    gyro = SensorSeries(t, np.gradient(np.unwrap(scenario.yaw), t))
    priors = []

    def recording(*args, **kwargs):
        priors.append(grade_prior(*args, **kwargs))
        return priors[-1]

    monkeypatch.setattr("vo_doppler.heading.pipeline.grade_prior", recording)
    table = _with_accelerometer(t, scenario, velocity, wheel, gyro, acceleration)
    assert table.wheel_scale[-1] == pytest.approx(1 / 1.03, abs=1e-3)
    mean = priors[0][0]
    assert np.nanpercentile(np.abs(mean), 95) < 0.001


def test_the_epochs_before_the_first_estimate_take_the_median_value_with_the_prior_sigma():
    estimated = np.array([False, False, False, True, True, False, True, False])
    cal = CalibrationSeries(
        bias=np.array([0.0, 0.0, 0.0, 0.01, 0.02, 0.0, 0.004, 0.0]),
        scale=np.array([1.0, 1.0, 1.01, 1.02, 1.03, 1.04, 1.05, 1.06]),
        bias_sigma=np.array([0.5, 0.5, 0.5, 0.1, 0.05, 0.5, 0.02, 0.5]),
        scale_sigma=np.full(8, 0.03),
        bias_estimated=estimated.copy(),
        scale_estimated=np.array([False, True, True, True, True, True, True, True]),
    )
    backfill_start(cal)
    np.testing.assert_array_equal(cal.bias, [0.01] * 3 + [0.01, 0.02, 0.0, 0.004, 0.0])
    np.testing.assert_array_equal(cal.bias_sigma, [0.5] * 3 + [0.1, 0.05, 0.5, 0.02, 0.5])
    np.testing.assert_array_equal(cal.bias_estimated, [True] * 5 + [False, True, False])
    np.testing.assert_array_equal(cal.scale, [1.03, 1.0, 1.01, 1.02, 1.03, 1.04, 1.05, 1.06])
    assert cal.scale_estimated.all()


def test_the_bias_estimates_before_the_first_precise_one_take_the_median_of_the_rest():
    estimated = np.array([False, True, True, True, True, True])
    cal = CalibrationSeries(
        bias=np.array([0.0, 0.001, 0.002, 0.005, 0.006, 0.004]),
        scale=np.array([1.0, 1.01, 1.02, 1.03, 1.04, 1.05]),
        bias_sigma=np.array([0.5, 0.3, 0.1, 0.0008, 0.0006, 0.0005]),
        scale_sigma=np.array([0.03, 0.02, 0.01, 0.005, 0.004, 0.003]),
        bias_estimated=estimated.copy(),
        scale_estimated=estimated.copy(),
    )
    backfill_start(cal, max_bias_sigma=0.001)
    np.testing.assert_array_equal(cal.bias, [0.005] * 3 + [0.005, 0.006, 0.004])
    np.testing.assert_array_equal(cal.bias_sigma, [0.5, 0.3, 0.1, 0.0008, 0.0006, 0.0005])
    assert cal.bias_estimated.all()
    np.testing.assert_array_equal(cal.scale, [1.03, 1.01, 1.02, 1.03, 1.04, 1.05])


def test_without_a_precise_bias_estimate_the_first_estimate_bounds_the_backfill():
    cal = CalibrationSeries(
        bias=np.array([0.0, 0.01, 0.03]),
        scale=np.ones(3),
        bias_sigma=np.array([0.5, 0.2, 0.1]),
        scale_sigma=np.full(3, 0.03),
        bias_estimated=np.array([False, True, True]),
        scale_estimated=np.zeros(3, dtype=bool),
    )
    backfill_start(cal, max_bias_sigma=0.001)
    np.testing.assert_array_equal(cal.bias, [0.02, 0.01, 0.03])


def test_a_drive_without_any_estimate_keeps_the_prior_for_the_tight_pass():
    cal = CalibrationSeries(
        np.zeros(4), np.ones(4), np.full(4, 0.5), np.full(4, 0.03), *np.zeros((2, 4), dtype=bool)
    )
    backfill_start(cal)
    np.testing.assert_array_equal(cal.bias_sigma, 0.5)
    assert not cal.bias_estimated.any() and not cal.scale_estimated.any()


@pytest.mark.parametrize(
    ("rate_hz", "method"),
    [(1.0, "robust"), (5.0, "robust"), (10.0, "snooping"), (20.0, "snooping")],
)
def test_auto_takes_the_robust_settings_below_10_hz(rate_hz, method):
    """``--heading-method auto``: the robust settings (smoother on) below 10 Hz, the snooping
    ones from 10 Hz; the other settings are kept and the choice is made once."""
    t = 1000.0 + np.arange(0.0, 30.0, 1.0 / rate_hz)
    auto = replace(HeadingPipelineConfig.auto(), calibration="kalman")
    chosen = auto.for_rate(t)
    assert chosen.method == method and chosen.robust_below_rate_hz is None
    assert chosen.calibration == "kalman"
    expected = HeadingPipelineConfig.robust() if method == "robust" else HeadingPipelineConfig()
    assert chosen.tight == expected.tight and chosen.gate == expected.gate
    assert chosen.smoother == expected.smoother
    assert HeadingPipelineConfig().for_rate(t) == HeadingPipelineConfig()


def _two_satellites(t, yaw, seed):
    """Two satellites' Doppler rows (σ 0.05 m/s) of a drive at 10 m/s with heading ``yaw(t)``."""
    return simulate_doppler(
        t,
        yaw,
        lambda t: 10.0 + 0.0 * t,
        AZIMUTH,
        ELEVATION,
        2,
        rotate=False,
        noise_mps=0.05,
        seed=seed,
    )


@pytest.mark.parametrize(("step_s", "method"), [(1.0, "robust"), (0.1, "snooping")])
def test_the_table_names_the_settings_auto_chose(step_s, method):
    t = np.arange(0.0, 60.0, step_s)
    scenario = _two_satellites(t, lambda t: 1.0 + 0.5 * np.sin(0.05 * t), seed=2)
    velocity = scenario.speed[:, None] * np.stack(
        [np.cos(scenario.yaw), np.sin(scenario.yaw), np.zeros_like(t)], axis=1
    )
    t_gyro, rate = gyro_from_heading(
        t, scenario.yaw, np.ones(len(t), bool), 0.0, np.radians(0.05), rate_hz=50.0
    )
    table = heading_pipeline(
        t,
        scenario.rows,
        ConventionalVelocity(velocity, np.ones(len(t), bool)),
        VehicleSignals(SensorSeries(t, scenario.speed), SensorSeries(t_gyro, rate)),
        HeadingPipelineConfig.auto(),
    )
    assert table.method == method
    error = np.degrees(np.abs(wrap_angle(table.yaw_tc - scenario.yaw)))
    assert np.nanmedian(error[t > 10.0]) < 1.0


def test_the_calibration_is_a_checked_choice():
    config = HeadingPipelineConfig(calibration="kalman")
    assert config.calibration is CalibrationMethod.KALMAN
    with pytest.raises(
        ValueError,
        match=r"^HeadingPipelineConfig.calibration: unknown calibration method 'rls'; choose "
        r"from ls, kalman, none$",
    ):
        HeadingPipelineConfig(calibration="rls")


def test_courses_beyond_a_cars_vertical_bound_calibrate_no_gyro_bias():
    """Most epochs (60 %) turned by an error growing 0.23 °/s, a gyro bias to the fit: while
    they stay level, the calibrated bias follows them (0.3 − 0.23 °/s); climbing at 8 m/s, beyond
    any road (design (I1b)), they calibrate no bias and the true 0.3 °/s comes back. Their speeds
    still calibrate the wheels, the same either way."""
    t, scenario, velocity = _drive()
    rng = np.random.default_rng(6)
    conv_velocity = velocity + rng.normal(0.0, 0.03, velocity.shape)
    faulty = rng.random(len(t)) < 0.6
    turn = 0.004 * t
    east, north = conv_velocity[:, 0].copy(), conv_velocity[:, 1].copy()
    conv_velocity[faulty, 0] = (np.cos(turn) * east - np.sin(turn) * north)[faulty]
    conv_velocity[faulty, 1] = (np.sin(turn) * east + np.cos(turn) * north)[faulty]
    t_gyro, rate = gyro_from_heading(
        t, scenario.yaw, np.ones(len(t), bool), np.radians(0.3), np.radians(0.05), rate_hz=50.0
    )
    wheel = SensorSeries(t, scenario.speed / 1.03)
    tables = []
    for up in (0.0, 8.0):
        conv_velocity[faulty, 2] = up
        tables.append(
            heading_pipeline(
                t,
                scenario.rows,
                ConventionalVelocity(conv_velocity, np.ones(len(t), bool)),
                VehicleSignals(wheel, SensorSeries(t_gyro, rate)),
            )
        )
    level, climbing = (np.degrees(table.gyro_bias[-1]) for table in tables)
    assert level < 0.15
    assert climbing == pytest.approx(0.3, abs=0.01)
    assert tables[0].wheel_scale[-1] == tables[1].wheel_scale[-1]
    assert tables[1].wheel_scale[-1] == pytest.approx(1.03, rel=0.003)
    assert not tables[1].conv_valid[faulty].any()


@pytest.mark.parametrize("step_s", [1.0, 0.1])
def test_two_headings_that_fit_alike_give_no_tight_heading_and_a_warning(step_s):
    # Two satellites on a straight road from the first epoch, no conventional velocity: each
    # window fits the heading and its mirror alike and nothing earlier chooses between them.
    t = np.arange(0.0, 60.0, step_s)
    scenario = _two_satellites(t, lambda t: 0.7 + 0.0 * t, seed=4)
    vehicle = VehicleSignals(SensorSeries(t, scenario.speed), SensorSeries(t, 0.0 * t))
    conventional = ConventionalVelocity(np.zeros((len(t), 3)), np.zeros(len(t), bool))
    table = heading_pipeline(t, scenario.rows, conventional, vehicle)
    assert not table.tc_available.any()
    warning = [w for w in table.warnings if w.startswith("tight heading:")]
    assert len(warning) == 1
    unresolved = int(warning[0].split()[2])
    assert unresolved >= 0.9 * len(t) and f"of {len(t)} moving epochs" in warning[0]


def test_a_drive_whose_windows_decide_has_no_ambiguity_warning():
    t, scenario, velocity = _drive()
    t_gyro, rate = gyro_from_heading(t, scenario.yaw, np.ones(len(t), bool), 0.0, 0.0)
    vehicle = VehicleSignals(SensorSeries(t, scenario.speed), SensorSeries(t_gyro, rate))
    conventional = ConventionalVelocity(velocity, np.ones(len(t), bool))
    table = heading_pipeline(t, scenario.rows, conventional, vehicle)
    assert table.tc_available[t > 5.0].mean() > 0.95
    assert not [w for w in table.warnings if w.startswith("tight heading:")]
