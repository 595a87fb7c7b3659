"""The profiled cost of the tight heading ([TK18] sec. 3.5) and its minimisation: exact cases."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.geo import wrap_angle
from vo_doppler.heading.profile import (
    grid_minima,
    minimum_cost,
    projected_normal_matrix,
    quadratic,
    z_of,
)


def _window(theta0: float, clock: tuple[float, float], n: int = 12, seed: int = 0):
    """Rows y = a·cos θ₀ + b·sin θ₀ + T·p of one window, noise-free, and their weights."""
    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=n), rng.normal(size=n)
    T = np.column_stack([np.ones(n), np.linspace(-1.0, 1.0, n)])
    y = a * np.cos(theta0) + b * np.sin(theta0) + T @ np.asarray(clock)
    X = np.column_stack([-a, -b, y])
    return X[None], T[None], rng.uniform(0.5, 2.0, n)[None]


@settings(max_examples=40, deadline=None)
@given(st.floats(-np.pi, np.pi), st.floats(-5.0, 5.0), st.floats(-1.0, 1.0))
def test_noise_free_rows_give_theta0_at_zero_cost(theta0, rho0, alpha):
    X, T, w = _window(theta0, (rho0, alpha))
    Q, *_ = projected_normal_matrix(X, T, w)
    theta, cost = minimum_cost(Q, 72, 8)
    assert abs(wrap_angle(theta[0] - theta0)) < 1e-9
    assert cost[0] == pytest.approx(0.0, abs=1e-9)


def test_the_projected_cost_is_the_residual_minimised_over_the_linear_parameters():
    X, T, w = _window(0.7, (2.0, -0.3), seed=5)
    X = X.copy()
    X[0, :, 2] += np.random.default_rng(2).normal(0.0, 0.1, X.shape[1])
    Q, *_ = projected_normal_matrix(X, T, w)
    for theta in (-2.0, 0.1, 1.3):
        r_theta = X[0] @ z_of(np.array(theta))
        W = np.diag(w[0])
        p = np.linalg.solve(T[0].T @ W @ T[0], T[0].T @ W @ r_theta)
        direct = (r_theta - T[0] @ p) @ W @ (r_theta - T[0] @ p)
        assert quadratic(Q, z_of(np.array(theta)), z_of(np.array(theta)))[0] == pytest.approx(
            direct, rel=1e-10
        )


def test_a_mirror_ambiguous_cost_has_two_grid_minima():
    # Two satellites with no clock rows: y = cos θ₀ along one axis only, minima at ±θ₀.
    Q = np.zeros((1, 3, 3))
    Q[0, 0, 0], Q[0, 0, 2], Q[0, 2, 0], Q[0, 2, 2] = 1.0, -np.cos(0.6), -np.cos(0.6), 0.69
    best, second = grid_minima(Q, 360)
    found = sorted(wrap_angle(np.array([best[0], second[0]])))
    np.testing.assert_allclose(found, [-0.6, 0.6], atol=np.radians(1.0))


def test_prior_is_a_weighted_pseudo_observation():
    """A Gaussian prior p₁ ~ N(μ, σ²) on the linear parameters gives the cost of the rows plus
    (p₁ − μ)²/σ², minimised over p: the same Q as one more row [0, 0, μ] with T-row e₁ and
    weight 1/σ²."""
    X, T, w = _window(0.7, (2.0, -0.3), seed=6)
    X = X.copy()
    X[0, :, 2] += np.random.default_rng(3).normal(0.0, 0.1, X.shape[1])
    mu, sigma = 0.2, 0.05
    prior = (np.array([[[0.0, 0.0, mu]]]), np.array([[[0.0, 1.0]]]), np.array([[sigma**-2]]))
    Q, *_ = projected_normal_matrix(X, T, w, prior)
    appended = [np.concatenate(pair, axis=1) for pair in zip((X, T, w), prior, strict=True)]
    Q_rows, *_ = projected_normal_matrix(*appended)
    np.testing.assert_allclose(Q, Q_rows, rtol=1e-12, atol=1e-12)
    theta = np.array(0.4)
    r_theta = X[0] @ z_of(theta)
    W = np.diag(w[0])
    normal = T[0].T @ W @ T[0] + np.diag([0.0, sigma**-2])
    p = np.linalg.solve(normal, T[0].T @ W @ r_theta + np.array([0.0, mu * sigma**-2]))
    direct = (r_theta - T[0] @ p) @ W @ (r_theta - T[0] @ p) + ((p[1] - mu) / sigma) ** 2
    assert quadratic(Q, z_of(theta), z_of(theta))[0] == pytest.approx(direct, rel=1e-10)
