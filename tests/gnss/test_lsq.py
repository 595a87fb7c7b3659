"""Weighted least squares with chi-square fault detection and exclusion: exact cases."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.special import chdtri, chndtr, chndtrinc
from scipy.stats import chi2

from vo_doppler.gnss.lsq import lsq_with_exclusion, minimal_detectable_shift, weighted_lsq

X_TRUE = np.array([1.5, -2.0, 0.25, 3.0])


def _geometry(n: int, seed: int = 0) -> np.ndarray:
    """Rows [−e, 1] of n unit lines of sight spread over the sky (a Doppler design matrix)."""
    rng = np.random.default_rng(seed)
    e = rng.normal(size=(n, 3))
    e[:, 2] = np.abs(e[:, 2]) + 0.2
    e /= np.linalg.norm(e, axis=1)[:, None]
    return np.hstack([-e, np.ones((n, 1))])


def test_consistent_rows_give_the_exact_solution_and_its_covariance():
    H = _geometry(8)
    sigma = np.linspace(0.05, 0.2, 8)
    x, covariance, residuals = weighted_lsq(H, H @ X_TRUE, sigma)
    np.testing.assert_allclose(x, X_TRUE, atol=1e-12)
    np.testing.assert_allclose(residuals, 0.0, atol=1e-12)
    W = np.diag(sigma**-2.0)
    np.testing.assert_allclose(covariance, np.linalg.inv(H.T @ W @ H), rtol=1e-10)


def test_a_gross_fault_is_excluded_and_the_rest_solve_exactly():
    H = _geometry(9)
    y = H @ X_TRUE
    y[4] += 3.0
    groups = np.array([f"G{i:02d}" for i in range(9)])
    result = lsq_with_exclusion(H, y, np.full(9, 0.05), groups, min_groups=4)
    assert result.valid
    assert result.used.tolist() == [i != 4 for i in range(9)]
    np.testing.assert_allclose(result.x, X_TRUE, atol=1e-9)
    assert result.dof == 8 - 4 and result.chi_square == pytest.approx(0.0, abs=1e-12)
    assert result.residuals[4] == pytest.approx(3.0, abs=1e-9)


def test_noise_within_its_sigma_passes_the_global_test_untouched():
    H = _geometry(10, seed=3)
    sigma = np.full(10, 0.1)
    noise = 0.1 * np.random.default_rng(1).standard_normal(10)
    groups = np.arange(10)
    result = lsq_with_exclusion(H, H @ X_TRUE + noise, sigma, groups, min_groups=4)
    assert result.valid and result.used.all()
    omega = np.sum((result.residuals / sigma) ** 2)
    assert result.chi_square == pytest.approx(omega)
    assert omega <= chi2.ppf(1 - 1e-3, 6)


def test_too_few_satellites_or_a_singular_geometry_is_unavailable():
    H = _geometry(6)
    y = H @ X_TRUE
    three_satellites = np.array([0, 0, 1, 1, 2, 2])
    short = lsq_with_exclusion(H, y, np.full(6, 0.1), three_satellites, min_groups=4)
    assert not short.valid and np.isnan(short.x).all()
    flat = H.copy()
    flat[:, 2] = 0.0  # no vertical component: the up velocity is unobservable
    singular = lsq_with_exclusion(flat, y, np.full(6, 0.1), np.arange(6), min_groups=4)
    assert not singular.valid and np.isnan(singular.covariance).all()


@pytest.mark.parametrize("rows_per_satellite", [1, 2])
def test_the_minimal_detectable_bias_is_detected_at_the_stated_power_and_moves_x_as_stated(
    rows_per_satellite,
):
    H = _geometry(7 * rows_per_satellite, seed=5)
    sigma = np.linspace(0.03, 0.12, len(H))
    groups = np.repeat(np.arange(7), rows_per_satellite)
    _, covariance, _ = weighted_lsq(H, H @ X_TRUE, sigma)
    dof = len(H) - 4
    shift = minimal_detectable_shift(H, sigma, groups, covariance, dof)
    assert shift.shape == (7, 4)
    noncentrality = chndtrinc(chdtri(dof, 1e-3), dof, 0.2)
    assert 1.0 - chndtr(chdtri(dof, 1e-3), dof, noncentrality) == pytest.approx(0.8, abs=1e-9)
    for g in range(7):
        rows = groups == g
        # the bias that gives this shift: solve Δx = C Hᵀ W c ∇ for ∇ along the shift
        unit = covariance @ H.T @ (rows / sigma**2)
        bias = float(shift[g] @ unit / (unit @ unit))
        y = H @ X_TRUE + bias * rows
        x, _, residuals = weighted_lsq(H, y, sigma)
        np.testing.assert_allclose(x - X_TRUE, shift[g], rtol=1e-9, atol=1e-12)
        # noise-free rows: Ω is the non-centrality the test needs for power 0.8
        assert np.sum((residuals / sigma) ** 2) == pytest.approx(noncentrality, rel=1e-9)


def test_without_redundancy_no_bias_is_detectable():
    H = _geometry(4)
    sigma = np.full(4, 0.1)
    _, covariance, _ = weighted_lsq(H, H @ X_TRUE, sigma)
    assert np.isinf(minimal_detectable_shift(H, sigma, np.arange(4), covariance, 0)).all()
    flat = _geometry(5, seed=2)
    flat[:4, 2] = 0.0  # only the fifth satellite sees the vertical: nothing can check it
    sigma5 = np.full(5, 0.1)
    _, covariance5, _ = weighted_lsq(flat, flat @ X_TRUE, sigma5)
    shift = minimal_detectable_shift(flat, sigma5, np.arange(5), covariance5, 1)
    assert np.isinf(shift[4]).all() and np.isfinite(shift[:4]).all()


@pytest.mark.parametrize("faulty", range(5))
def test_equal_statistics_exclude_the_first_row_whatever_the_rounding(faulty):
    """Five rows, four unknowns: every row's normalised residual is the same, so the fault
    cannot be located. The first row is excluded (the data's order), whichever row holds the
    fault and however rounding perturbs the values, where the largest of equal statistics was
    excluded before: a choice by rounding, which moved with the time origin (issue 30)."""
    H = _geometry(5, seed=2)
    groups = np.array([f"G{i:02d}" for i in range(5)])
    rng = np.random.default_rng(faulty)
    for _ in range(20):
        y = H @ X_TRUE + 1e-12 * rng.standard_normal(5)
        y[faulty] += 30.0
        result = lsq_with_exclusion(H, y, np.full(5, 0.05), groups, min_groups=4)
        assert result.valid and not result.passed and result.dof == 0
        assert result.used.tolist() == [False, True, True, True, True]
