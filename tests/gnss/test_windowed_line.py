"""The robust windowed line test (design (I1)) shared by the GNSS continuity test and the
heading stage's test against the car's sensors."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.geo import wrap_angle
from vo_doppler.gnss.windowed_line import (
    ConsistencyConfig,
    LineFit,
    consistency_test,
    windowed_line_residuals,
)


def test_line_residuals_are_exact_on_a_line_with_one_outlier():
    t = np.arange(0.0, 10.0, 0.1)
    values = 0.3 + 0.02 * t
    values[50] += 0.5
    sigma = np.full(t.size, 0.01)
    usable = np.ones(t.size, bool)
    residual, variance = windowed_line_residuals(t, values, sigma, usable, LineFit(2.0, 5))
    assert residual[50] == pytest.approx(0.5, abs=1e-12)
    # 40 neighbours at ±0.1–2 s: var(c₀) = σ²·Σdt²/(n·Σdt² − (Σdt)²) = σ²/40 (symmetric)
    assert variance[50] == pytest.approx(0.01**2 / 40, rel=1e-9)
    others = np.delete(np.arange(t.size), 50)
    # the outlier's Huber weight k·σ/0.5 leaves at most 1 % of it in a neighbour's line
    assert np.max(np.abs(residual[others])) < 5e-3
    # a slope prior of zero makes the line a constant: the drift shows in the residuals
    flat, _ = windowed_line_residuals(
        t, values, sigma, usable, LineFit(2.0, 5), slope_sigma=np.zeros(100)
    )
    assert flat[20] == pytest.approx(0.0, abs=1e-9)  # symmetric window: the drift cancels
    assert flat[5] < -0.005  # the window is cut at the start: the later epochs pull it up
    # without enough neighbours: untested
    lonely = np.zeros(t.size, bool)
    lonely[[10, 40, 90]] = True
    residual, _ = windowed_line_residuals(t, values, sigma, lonely, LineFit(2.0, 1))
    assert np.isnan(residual).all()


def test_angular_residuals_wrap_across_pi():
    t = np.arange(0.0, 5.0, 0.1)
    values = wrap_angle(np.pi - 0.01 + 0.004 * t / 0.1)  # crosses ±π
    usable = np.ones(t.size, bool)
    residual, _ = windowed_line_residuals(
        t, values, np.ones(t.size), usable, LineFit(1.0, 5, angular=True)
    )
    np.testing.assert_allclose(residual, 0.0, atol=1e-9)


def test_consistency_test_threshold_and_sigma_factor():
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 200.0, 0.1)
    sigma = np.full(t.size, 0.1)
    values = rng.normal(0.0, 0.2, t.size)  # twice the stated σ
    values[1000] += 3.0
    test = consistency_test(t, values, sigma, np.ones(t.size, bool), ConsistencyConfig())
    assert test.sigma_factor == pytest.approx(2.0, rel=0.1)
    assert test.failed[1000]
    assert test.failed.mean() < 0.005
    assert ConsistencyConfig().threshold == pytest.approx(3.2905, abs=1e-4)
    honest = consistency_test(t, values, 2 * sigma, np.ones(t.size, bool), ConsistencyConfig())
    assert honest.sigma_factor == pytest.approx(1.0, abs=0.1)


def test_threshold_is_the_normal_two_sided_quantile():
    from scipy.stats import norm

    for false_alarm in (0.001, 0.01, 0.05):
        config = ConsistencyConfig(false_alarm=false_alarm)
        assert config.threshold == norm.isf(false_alarm / 2.0)
