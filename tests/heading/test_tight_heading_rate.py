"""Rules of the tight heading in seconds: the same drive at 1, 5, 10 and 20 Hz gets the same
windows, the same clock model decision and the same reliability stretch."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.heading.tight_heading import (
    TightHeadingConfig,
    _reliability,
    clock_per_epoch,
    window_lengths,
)

ROBUST = TightHeadingConfig.robust()


@pytest.mark.parametrize("rate_hz", [1, 5, 10, 20])
def test_window_length_is_the_same_at_every_rate(rate_hz):
    t = np.arange(0.0, 30.0, 1.0 / rate_hz)
    # the same rows at every epoch (each row as precise at 20 Hz as at 1 Hz): rows closer
    # than the 1-s correlation time count for Δt/1 s of theirs
    information = np.full(t.size, 0.25 * ROBUST.window_target_sigma_rad**-2.0)
    length = window_lengths(t, information, ROBUST)
    # four seconds of rows hold the target information at every rate
    assert np.allclose(length[t > 10.0], 4.0, atol=1.0 / rate_hz + 1e-9)


def test_window_grows_as_far_as_the_gyro_and_the_road_allow():
    t = np.arange(0.0, 30.0, 1.0)
    sparse = np.full(t.size, 1.0)  # far below the target: grows to the maximum (whole epochs)
    longest = window_lengths(t, sparse, ROBUST)[10:]
    assert np.all((longest <= ROBUST.max_window_s) & (longest > ROBUST.max_window_s - 1.0))
    # an uncalibrated gyro (0.5 °/s) allows 2 × 0.15° / 0.5 °/s = 0.6 s: the minimum
    bias = np.radians(0.5)
    assert np.all(window_lengths(t, sparse, ROBUST, gyro_bias_sigma=bias) == ROBUST.window_s)
    # a calibrated one (0.05 °/s) allows 6 s
    calibrated = window_lengths(t, sparse, ROBUST, gyro_bias_sigma=np.radians(0.05))[10:]
    assert np.all((calibrated <= 6.0) & (calibrated > 5.0))
    fast = window_lengths(t, sparse, ROBUST, speed=20.0)
    assert np.all(fast[10:] <= ROBUST.max_window_m / 20.0)
    assert np.all(fast[10:] >= ROBUST.max_window_m / 20.0 - 1.0)


def test_one_clock_drift_per_epoch_from_half_a_second_between_epochs():
    assert clock_per_epoch(np.arange(0.0, 10.0, 1.0), ROBUST)
    assert not clock_per_epoch(np.arange(0.0, 10.0, 0.1), ROBUST)
    assert not clock_per_epoch(np.arange(0.0, 10.0, 1.0), TightHeadingConfig())


@pytest.mark.parametrize("rate_hz", [1, 5, 10, 20])
def test_reliability_in_seconds_judges_the_same_stretch_at_every_rate(rate_hz):
    t = np.arange(0.0, 20.0, 1.0 / rate_hz)
    yaw = np.zeros(t.size)
    yaw[(t >= 10.0) & (t < 10.0 + 1.0)] = np.radians(20.0)  # one second of a wrong heading
    available = np.ones(t.size, bool)
    sigma = np.full(t.size, np.radians(0.5))
    reliable = _reliability(yaw, sigma, available, np.zeros(t.size), t, ROBUST)
    assert not reliable[t < ROBUST.reliability_min_span_s].any()  # nothing earlier yet
    assert reliable[(t >= 3.0) & (t < 10.0)].all()
    assert not reliable[(t >= 10.0) & (t < 11.0)].any()  # the majority disagrees
    # once the wrong second is less than a quarter of the last 5 s, consensus returns
    assert reliable[t >= 10.0 + 1.0 + 5.0].all()


@pytest.mark.parametrize("rate_hz", [1, 5, 10, 20])
def test_window_holds_enough_equations_beyond_its_clock_unknowns(rate_hz):
    t = np.arange(0.0, 30.0, 1.0 / rate_hz)
    rich = np.full(t.size, 1e12)  # plenty of information: the minimum would do
    one_each = (np.ones(t.size), 0)  # two satellites, one clock drift per epoch
    length = window_lengths(t, rich, ROBUST, speed=20.0, equations=one_each)
    # four equations need four epochs: 3.5 s at 1 Hz, the 2-s minimum from 2 Hz on
    expected = max(ROBUST.window_s, (ROBUST.min_window_equations - 0.5) / rate_hz)
    np.testing.assert_allclose(length[t > 10.0], expected)
