"""Static bias ε0 over a standstill and the Allan-deviation τ ([KZ] Eq. 5–6): exact cases."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.lowcost.static_bias import (
    allan_deviation,
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
