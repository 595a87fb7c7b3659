"""Static bias ε0 over a standstill and the Allan-deviation τ ([KZ] Eq. 5–6): exact cases; τ never
longer than the window and never the Allan minimum of a moving record."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.errors import InputError
from vo_doppler.io.comma2k19 import read_lowcost_inputs
from vo_doppler.lowcost.drift import VARIANTS
from vo_doppler.lowcost.evaluation import heading_run
from vo_doppler.lowcost.pipeline import Reference, run_deadreckon
from vo_doppler.lowcost.static_bias import (
    AllanDeviation,
    allan_deviation,
    choose_tau,
    detect_standstill,
    remove_bias,
    static_bias,
)


def test_static_bias_is_the_interval_mean():
    t = np.arange(0.0, 10.0, 0.5)
    rate = t * 2.0
    bias = static_bias(t, rate, 2.0, 4.0)
    assert bias.eps0 == pytest.approx(6.0) and bias.n == 5
    np.testing.assert_allclose(remove_bias(rate, bias.eps0), rate - 6.0)
    with pytest.raises(InputError, match="no rate samples"):
        static_bias(t, rate, 20.0, 30.0)


def test_allan_deviation_white_noise_slope_and_minimum():
    rng = np.random.default_rng(1)
    fs, n_white, k_walk = 100.0, 0.002, 2e-5
    white = rng.normal(0, n_white * np.sqrt(fs), 60_000)
    adev = allan_deviation(white, fs)
    small = adev.taus < 5
    # White rate noise: ADEV(τ) = N / √τ.
    np.testing.assert_allclose(adev.adev[small] * np.sqrt(adev.taus[small]), n_white, rtol=0.1)
    walk = np.cumsum(rng.normal(0, k_walk / np.sqrt(fs), 60_000))
    tau_min = allan_deviation(white + walk, fs).tau_at_minimum
    expected = np.sqrt(3.0) * n_white / k_walk
    assert expected / 2.5 < tau_min < expected * 2.5


def test_detect_standstill_intervals():
    t = np.arange(0.0, 30.0, 1.0)
    speed = np.where((t < 10) | ((t >= 20) & (t < 23)), 0.0, 5.0)
    assert detect_standstill(t, speed, 0.2, 5.0) == [(0.0, 9.0)]
    assert detect_standstill(t, speed, 0.2, 2.0) == [(0.0, 9.0), (20.0, 22.0)]


ALLAN = AllanDeviation(np.array([0.1, 0.4, 2.0, 8.0]), np.array([3.0, 1.0, 2.0, 4.0]))


def test_auto_over_a_standstill_takes_the_allan_minimum():
    choice = choose_tau(None, ALLAN, 10.0, window_is_standstill=True)
    assert choice.tau == 0.4
    assert "Allan deviation minimum" in choice.reason and "standstill" in choice.reason


def test_auto_over_a_straight_stretch_takes_the_whole_stretch():
    choice = choose_tau(None, ALLAN, 5.0, window_is_standstill=False)
    assert choice.tau == 5.0
    assert "whole straight stretch" in choice.reason and "standstill" not in choice.reason


@pytest.mark.parametrize(
    ("standstill", "word"), [(True, "standstill"), (False, "straight stretch")]
)
def test_tau_never_exceeds_the_window(standstill, word):
    choice = choose_tau(30.0, ALLAN, 6.0, window_is_standstill=standstill)
    assert choice.tau == 6.0
    assert f"longer than the {word}" in choice.reason
    short = AllanDeviation(np.array([1.0, 12.0]), np.array([2.0, 1.0]))
    assert choose_tau(None, short, 6.0, window_is_standstill=True).tau == 6.0


def test_non_positive_tau_is_an_input_error():
    with pytest.raises(InputError, match="τ must be positive"):
        choose_tau(0.0, ALLAN, 6.0, window_is_standstill=True)


@pytest.mark.shared_data
def test_auto_tau_on_the_moving_comma_minute_matches_the_window():
    """Before the rule, τ auto took 0.41 s from the moving window and the ε0-removed heading
    drifted −17.3 °/min; with it τ is the 5-s window (−1.57 °/min, like ``--tau 5``)."""
    require_shared("comma2k19_example1/global_pose/frame_times")
    data = read_lowcost_inputs(require_shared("comma2k19_example1"))
    run = heading_run(*data, window_s=5.0, k=None)
    auto = dataclasses.replace(run.config, tau_s=None)
    truth, fixes, gyro, can = data
    rerun = run_deadreckon(
        gyro, can, fixes.as_tuple(), auto, reference=Reference(truth.t, truth.yaw, "course")
    )
    assert rerun.model.tau == pytest.approx(5.0)
    i = VARIANTS.index("combined + ε0 removed")
    assert rerun.rows[i].drift_deg_per_min == pytest.approx(run.rows[i].drift_deg_per_min)
    assert abs(rerun.rows[i].drift_deg_per_min) < 2.1
