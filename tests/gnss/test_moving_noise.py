"""The Doppler noise at rest and in motion (gnss/moving_noise.py): exact synthetic fits."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from vo_doppler.gnss.moving_noise import CN0_REFERENCE_DBHZ, MovingNoiseModel, fit_moving_noise


def _rows(k_ref, slope, n=4000, seed=0):
    """Gaussian residuals whose σ follows the model exactly, at C/N0 20–45 and 3–15 m/s."""
    rng = np.random.default_rng(seed)
    cn0 = rng.uniform(20.0, 45.0, n)
    speed = rng.uniform(3.0, 15.0, n)
    prior = np.full(n, 0.1)
    truth = MovingNoiseModel(k_ref=k_ref, k_slope=slope)
    residual = truth.sigma(prior, cn0, speed) * rng.standard_normal(n)
    return residual, prior, cn0, speed


def test_the_fit_recovers_the_speed_coefficient_and_its_cn0_slope():
    model = fit_moving_noise(*_rows(0.03, -1.0))
    assert abs(model.k_slope - -1.0) < 0.1
    assert abs(np.log10(model.k_ref / 0.03)) < 0.05
    assert model.n_bins == 5


def test_standstill_rows_and_noise_at_the_prior_give_no_speed_term():
    residual, prior, cn0, speed = _rows(0.03, -1.0)
    at_rest = fit_moving_noise(residual, prior, cn0, np.zeros_like(speed))
    assert at_rest.k_ref == 0.0 and at_rest.n_rest_rows == len(prior)
    quiet = 0.1 * np.random.default_rng(1).standard_normal(len(prior))
    assert fit_moving_noise(quiet, prior, cn0, speed).k_ref < 0.005


def test_sigma_adds_the_speed_term_in_quadrature():
    model = MovingNoiseModel(k_ref=0.1, k_slope=-1.0)
    sigma = model.sigma(np.array([0.3]), np.array([CN0_REFERENCE_DBHZ - 10.0]), np.array([4.0]))
    np.testing.assert_allclose(sigma, np.hypot(0.3, 1.0 * 4.0), rtol=1e-12)
    assert model.sigma(np.array([0.3]), np.array([30.0]), np.array([np.nan]))[0] == 0.3


@given(st.floats(0.0, 0.5), st.floats(-2.0, 0.0), st.floats(0.0, 60.0), st.floats(0.0, 40.0))
def test_sigma_never_below_the_prior_and_grows_with_speed(k_ref, slope, cn0, speed):
    model = MovingNoiseModel(k_ref=k_ref, k_slope=slope)
    prior = np.array([0.2])
    low = model.sigma(prior, np.array([cn0]), np.array([speed]))[0]
    high = model.sigma(prior, np.array([cn0]), np.array([speed + 1.0]))[0]
    assert 0.2 <= low <= high


def test_the_rest_factor_is_the_spread_at_rest_over_the_prior():
    rng = np.random.default_rng(2)
    prior = rng.uniform(0.1, 1.0, 5000)
    residual = 0.25 * prior * rng.standard_normal(prior.size)
    model = fit_moving_noise(residual, prior, np.full(prior.size, 30.0), np.zeros(prior.size))
    assert abs(model.rest_factor - 0.25) < 0.01
    np.testing.assert_allclose(model.sigma(prior, 30.0, 0.0), model.rest_factor * prior)
