"""Weighted least squares with chi-square fault detection and exclusion (iterated).

Global test: the weighted sum of squared residuals Ω = rᵀWr of a correct model with n rows and
u unknowns follows χ²(n − u); when Ω exceeds the (1 − α) quantile, the row with the largest
normalised residual |r_i| / √(Q_vv,ii), Q_vv = W⁻¹ − H (HᵀWH)⁻¹ Hᵀ (Baarda's w-test), is
excluded and the solution repeated, while enough distinct satellites remain. Rows whose |w|
equal the largest within ``TIE_TOLERANCE`` cannot be told apart (with one degree of freedom
every row's |w| is the same: the residuals span one direction), and the first of them in row
order is excluded: the choice is the data's order, not the rounding of the numbers (issue 30:
on the sample, which of five satellites was dropped changed when every time was shifted by
10⁹ s, and the four left gave velocities 10–56 m/s apart). Leaving such an epoch failed
instead, or excluding the tied row of largest σ, was tried and not kept: the sample's wheel
scale moved off and its dead reckoning with the tight heading drifted about three times as
much (docs/benchmarks.md, "The GNSS velocity's settings").

What the test cannot see (external reliability, :func:`minimal_detectable_shift`): the shift of
the solution that the smallest bias on one satellite the test still detects with probability
``DETECTION_POWER`` would cause.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.special import chdtri, chndtrinc

DEFAULT_ALPHA = 1e-3
TIE_TOLERANCE = 1e-6
"""Relative difference below which two normalised residuals are the same statistic (rounding
leaves ~1e-12)."""
DETECTION_POWER = 0.8
"""β₀ of the minimal detectable bias: the test detects a bias of that size four times in five."""


@dataclass(frozen=True)
class LsqResult:
    """Solution of one weighted least-squares problem after fault exclusion.

    ``residuals`` = y − H x for every row (excluded rows included); ``used`` marks the rows kept.
    ``chi_square`` = Ω of the kept rows, ``dof`` = kept rows − unknowns. ``passed``: the global
    test accepts the kept rows (dof ≥ 1); False both when it rejects them after the allowed
    exclusions and when there is no redundancy to test (dof 0).
    """

    x: np.ndarray
    covariance: np.ndarray
    residuals: np.ndarray
    used: np.ndarray
    chi_square: float
    dof: int
    valid: bool
    passed: bool = False


def weighted_lsq(H: np.ndarray, y: np.ndarray, sigma: np.ndarray):
    """x, covariance (HᵀWH)⁻¹ and residuals of min Σ ((y − Hx)_i / σ_i)²."""
    w = 1.0 / sigma
    Hw = H * w[:, None]
    normal = Hw.T @ Hw
    covariance = np.linalg.inv(normal)
    x = covariance @ (Hw.T @ (y * w))
    return x, covariance, y - H @ x


def lsq_with_exclusion(
    H: np.ndarray,
    y: np.ndarray,
    sigma: np.ndarray,
    groups: np.ndarray,
    min_groups: int,
    alpha: float = DEFAULT_ALPHA,
    max_excluded_fraction: float = 0.34,
) -> LsqResult:
    """Weighted LS with iterated chi-square FDE; ``groups`` labels rows by satellite.

    The solution is invalid (never guessed) when fewer than ``min_groups`` distinct groups or
    fewer rows than unknowns are available, or the geometry is singular.
    """
    n, u = H.shape
    used = np.ones(n, dtype=bool)
    unavailable = LsqResult(
        np.full(u, np.nan), np.full((u, u), np.nan), np.full(n, np.nan), ~used, np.nan, 0, False
    )
    max_excluded = int(max_excluded_fraction * n)
    while True:
        if np.unique(groups[used]).size < min_groups or used.sum() < u:
            return unavailable
        Hu, yu, su = H[used], y[used], sigma[used]
        if np.linalg.matrix_rank(Hu) < u:
            return unavailable
        x, covariance, _ = weighted_lsq(Hu, yu, su)
        residuals = y - H @ x
        dof = int(used.sum()) - u
        omega = float(np.sum((residuals[used] / su) ** 2))
        passed = dof >= 1 and omega <= chdtri(dof, alpha)
        if dof < 1 or passed or (~used).sum() >= max_excluded:
            return LsqResult(x, covariance, residuals, used.copy(), omega, dof, True, passed)
        q_vv = su**2 - np.einsum("ij,jk,ik->i", Hu, covariance, Hu)
        normalised = np.abs(residuals[used]) / np.sqrt(np.maximum(q_vv, 1e-30))
        tied = np.flatnonzero(normalised >= normalised.max() * (1.0 - TIE_TOLERANCE))
        worst = np.flatnonzero(used)[tied[0]]
        used[worst] = False


@functools.lru_cache(maxsize=256)
def detectable_noncentrality(dof: int, alpha: float, power: float) -> float:
    """λ₀: the non-centrality of χ²(dof) that the test at ``alpha`` detects with ``power``."""
    return float(chndtrinc(chdtri(dof, alpha), dof, 1.0 - power))


def minimal_detectable_shift(
    H: np.ndarray,
    sigma: np.ndarray,
    groups: np.ndarray,
    covariance: np.ndarray,
    dof: int,
    alpha: float = DEFAULT_ALPHA,
    power: float = DETECTION_POWER,
) -> np.ndarray:
    """Baarda's external reliability of the solution of the rows ``H`` (kept rows only, their
    ``sigma`` and ``groups``, ``covariance`` = (HᵀWH)⁻¹): for each group g (a satellite, in
    the order of ``np.unique(groups)``) the shift of the solution by the minimal detectable
    bias ∇_g, one bias on every row of g that the global test of ``dof`` degrees of freedom at
    ``alpha`` detects with probability ``power``::

        ∇_g = √(λ₀ / (c_gᵀ W Q_vv W c_g)),    Δx_g = (HᵀWH)⁻¹ Hᵀ W c_g · ∇_g

    with W = diag(σ⁻²), Q_vv = W⁻¹ − H (HᵀWH)⁻¹ Hᵀ, c_g the indicator of g's rows and λ₀ the
    non-centrality of χ²(dof) at which the test's power is ``power`` (W. Baarda, "A testing
    procedure for use in geodetic networks", 1968; P. J. G. Teunissen, "Testing theory", 2000,
    ch. 4). A smaller bias goes undetected more often. Rows of infinities where a bias on g
    cannot show in the residuals (no redundancy, or g controlled by no other row)."""
    names, group = np.unique(groups, return_inverse=True)
    indicator = np.zeros((len(groups), len(names)))
    indicator[np.arange(len(groups)), group.reshape(-1)] = 1.0
    if dof < 1:
        return np.full((len(names), H.shape[1]), np.inf)
    weight = sigma**-2.0
    weighted = indicator * weight[:, None]
    q_vv = np.diag(sigma**2) - H @ covariance @ H.T
    controlled = np.einsum("ig,ij,jg->g", weighted, q_vv, weighted)
    own = np.einsum("ig,ig->g", indicator, weighted)
    noncentrality = detectable_noncentrality(dof, alpha, power)
    with np.errstate(divide="ignore"):
        bias = np.sqrt(noncentrality / np.where(controlled > 1e-12 * own, controlled, 0.0))
    with np.errstate(invalid="ignore"):  # 0 · inf where a bias cannot show: replaced below
        shift = (covariance @ H.T @ weighted).T * bias[:, None]
    return np.where(np.isfinite(bias)[:, None], shift, np.inf)
