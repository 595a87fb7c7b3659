"""The wheel scale from the Doppler rows given the headings (a canyon from the start)."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.heading.conventional import ConventionalVelocity
from vo_doppler.heading.pipeline import HeadingPipelineConfig, heading_pipeline
from vo_doppler.heading.tight_heading import (
    MIN_SCALE_WINDOWS,
    TightHeadingConfig,
    speed_scale_ratio,
)
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.sim.doppler_rows import gyro_from_heading, simulate_doppler

AZIMUTH = [30.0, 110.0, 200.0, 280.0, 330.0]
ELEVATION = [60.0, 30.0, 45.0, 20.0, 70.0]
T = np.arange(0.0, 60.0, 0.1)
TRUE_SCALE = 0.98


def _speed(t):
    """Accelerating and braking between 4 and 16 m/s: the scale shows against the clock."""
    return 10.0 + 6.0 * np.sin(0.5 * t)


def _scenario(noise=0.0, seed=0):
    return simulate_doppler(
        T,
        lambda t: 0.7 + 0.2 * np.sin(0.1 * t),
        _speed,
        AZIMUTH,
        ELEVATION,
        2,
        noise_mps=noise,
        seed=seed,
    )


def test_exact_rows_give_the_exact_speed_ratio():
    scenario = _scenario()
    config = TightHeadingConfig(grade_sigma=0.0)
    wheel = scenario.speed / TRUE_SCALE
    every = np.ones(len(T), dtype=bool)
    ratio, sigma = speed_scale_ratio(
        scenario.rows, T, wheel, scenario.yaw_angle, scenario.yaw, every, config
    )
    assert ratio == pytest.approx(TRUE_SCALE, abs=1e-9)
    assert sigma < 1e-3


def test_too_few_disjoint_windows_give_no_ratio():
    scenario = _scenario()
    config = TightHeadingConfig(grade_sigma=0.0)
    # every window ends within one window length of the last: MIN_SCALE_WINDOWS − 1 disjoint
    few = (MIN_SCALE_WINDOWS - 1) * config.window_s - 0.05 > T
    assert (
        speed_scale_ratio(
            scenario.rows, T, scenario.speed, scenario.yaw_angle, scenario.yaw, few, config
        )
        is None
    )


def test_a_canyon_from_the_start_calibrates_the_wheel_scale_from_the_rows():
    """Two satellites, no conventional velocity: the prior's 2 % scale error drops to 0.35 %
    (the first pass's headings, solved with the prior's scale, pull the fit towards it) and
    the headings' median error halves or better; with the calibration off the scale stays at
    the prior."""
    scenario = _scenario(noise=0.03, seed=3)
    none = np.zeros(len(T), dtype=bool)
    t_gyro, rate = gyro_from_heading(T, scenario.yaw, np.ones(len(T), bool), 0.0, 0.0, rate_hz=50.0)
    vehicle = VehicleSignals(
        SensorSeries(T, scenario.speed / TRUE_SCALE), SensorSeries(t_gyro, rate)
    )
    args = (T, scenario.rows, ConventionalVelocity(np.zeros((len(T), 3)), none), vehicle)
    table = heading_pipeline(*args)
    prior = heading_pipeline(*args, HeadingPipelineConfig(tight_calibration=False))
    assert np.all(prior.wheel_scale == 1.0)
    assert abs(table.wheel_scale[0] / TRUE_SCALE - 1.0) < 0.005
    error = np.abs(np.degrees(table.yaw_tc - scenario.yaw))[table.tc_reliable]
    prior_error = np.abs(np.degrees(prior.yaw_tc - scenario.yaw))[prior.tc_reliable]
    assert np.median(error) < 0.5 * np.median(prior_error)
