"""The tightly coupled heading's profiled cost ([TK18] sec. 3.5) and its minimisation, per window.

With the model y = a·cos θ₀ + b·sin θ₀ + T·p (p the parameters that enter linearly: clock drift
and its rate, the road grade, and any bias being tested), the observation matrix
X = [−a, −b, y] and z = [cos θ₀, sin θ₀, 1], the weighted residual sum of squares minimised over
p is zᵀQz with Q = XᵀWX − XᵀWT (TᵀWT)⁺ TᵀWX (variable projection; a Gaussian prior on p enters
as weighted pseudo-observations in the three sums): a trigonometric polynomial of degree 2 in
θ₀ with at most two minima, found on a grid and refined by Gauss–Newton. Arrays carry any
number of leading axes (windows, hypotheses); the last ones are rows and vector components.
"""

from __future__ import annotations

import numpy as np

from vo_doppler.geo import wrap_angle


def project_out(XtWX, XtWT, TtWT):
    """Q = XᵀWX − XᵀWT (TᵀWT)⁺ TᵀWX, with (TᵀWT)⁺ and rank(TᵀWT)."""
    TtWT_pinv = np.linalg.pinv(TtWT, hermitian=True)
    Q = XtWX - XtWT @ TtWT_pinv @ np.swapaxes(XtWT, -1, -2)
    return Q, TtWT_pinv, np.linalg.matrix_rank(TtWT, hermitian=True)


def weighted_gram(U, w, V):
    """UᵀWV per window for rows U (K, R, m), V (K, R, n) and weights w (K, R)."""
    return np.swapaxes(U * w[..., None], -1, -2) @ V


def projected_normal_matrix(X, T, w, prior=None):
    """Q per window from rows (K, R, ·) with weights (K, R), plus XᵀWX, XᵀWT, (TᵀWT)⁺ and
    rank(TᵀWT), the normal matrices including ``prior``.

    ``prior``: pseudo-observations (X_p, T_p, w_p) of shapes (K, P, 3), (K, P, p), (K, P) — a
    Gaussian prior on the linear parameters, e.g. X_p = [0, 0, μ], T_p = e_j, w_p = 1/σ² for
    p_j ~ N(μ, σ²) — added to the normal matrices; they take no robust weight (default:
    none)."""
    XtW = np.swapaxes(X * w[..., None], -1, -2)
    XtWX, XtWT = XtW @ X, XtW @ T
    TtWT = weighted_gram(T, w, T)
    if prior is not None:
        Xp, Tp, wp = prior
        XtWX = XtWX + weighted_gram(Xp, wp, Xp)
        XtWT = XtWT + weighted_gram(Xp, wp, Tp)
        TtWT = TtWT + weighted_gram(Tp, wp, Tp)
    Q, TtWT_pinv, rank = project_out(XtWX, XtWT, TtWT)
    return Q, XtWX, XtWT, TtWT_pinv, rank


def quadratic(Q, u, v):
    """uᵀQv for matrices Q (..., 3, 3) and vectors u, v (..., 3)."""
    return np.einsum("...i,...ij,...j->...", u, Q, v)


def z_of(theta):
    return np.stack([np.cos(theta), np.sin(theta), np.ones_like(theta)], axis=-1)


def dz_of(theta):
    return np.stack([-np.sin(theta), np.cos(theta), np.zeros_like(theta)], axis=-1)


def gauss_newton(Q, theta, iterations):
    """Refine θ₀ towards a minimum of zᵀQz."""
    for _ in range(iterations):
        dz = dz_of(theta)
        hessian = quadratic(Q, dz, dz)
        ok = hessian > 0
        theta = theta - np.where(ok, quadratic(Q, dz, z_of(theta)) / np.where(ok, hessian, 1), 0)
    return wrap_angle(theta)


def grid_minima(Q, grid_size):
    """Best and second-best local minima of zᵀQz on a circular grid (second NaN if none)."""
    grid = np.linspace(-np.pi, np.pi, grid_size, endpoint=False)
    Z = z_of(grid)
    cost = np.einsum("gi,...ij,gj->...g", Z, Q, Z)
    is_min = (cost <= np.roll(cost, 1, axis=-1)) & (cost < np.roll(cost, -1, axis=-1))
    candidate = np.where(is_min, cost, np.inf)
    first = np.argmin(np.where(is_min.any(axis=-1, keepdims=True), candidate, cost), axis=-1)
    np.put_along_axis(candidate, first[..., None], np.inf, axis=-1)
    second = np.argmin(candidate, axis=-1)
    has_second = np.isfinite(np.take_along_axis(candidate, second[..., None], axis=-1)[..., 0])
    return grid[first], np.where(has_second, grid[second], np.nan)


def minimum_cost(Q, grid_size, iterations):
    """θ₀ at the lowest minimum of zᵀQz and the cost there."""
    theta = gauss_newton(Q, grid_minima(Q, grid_size)[0], iterations)
    z = z_of(theta)
    return theta, quadratic(Q, z, z)
