"""vo_doppler.robust: exact answers of the scale (R1), the weights (R2)–(R4), Huber's ψ (R2′)
and inflated variance (R2″), the Huber covariance (R5) and the IRLS loop, and properties over
generated data."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.robust import (
    MAD_TO_SIGMA,
    cauchy_weight,
    huber_inflated_variance,
    huber_psi,
    huber_variance,
    huber_weight,
    irls,
    mad,
    median_of_finite,
    nmad,
    student_weight,
)


def test_the_constant_makes_nmad_the_gaussian_sigma():
    from scipy.special import ndtri

    assert abs(MAD_TO_SIGMA - 1.0 / ndtri(0.75)) < 1e-4
    sample = np.random.default_rng(1).normal(3.0, 2.0, 200_001)
    assert nmad(sample) == pytest.approx(2.0, rel=5e-3)


def test_nmad_of_known_samples():
    assert mad([1.0, 2.0, 3.0, 4.0, 100.0]) == 1.0
    assert nmad([1.0, 2.0, 3.0, 4.0, 100.0]) == MAD_TO_SIGMA
    assert nmad([1.0, 2.0, 3.0, 4.0]) == MAD_TO_SIGMA  # |x − 2.5| = 1.5, 0.5, 0.5, 1.5
    assert nmad([-3.0, 1.0, 2.0], centre=False) == 2.0 * MAD_TO_SIGMA
    assert nmad([-3.0, 1.0, 2.0, 10.0]) == 2.5 * MAD_TO_SIGMA  # |x − 1.5| = 4.5, .5, .5, 8.5
    assert isinstance(nmad(np.arange(5.0)), float)


def test_nmad_along_an_axis_and_skipping_nan():
    values = np.array([[1.0, np.nan, 3.0], [2.0, 4.0, 10.0]])
    np.testing.assert_array_equal(
        nmad(values, axis=1, skip_nan=True), [MAD_TO_SIGMA, 2.0 * MAD_TO_SIGMA]
    )
    np.testing.assert_array_equal(
        nmad(values, axis=1, centre=False, skip_nan=True), [2.0, 4.0] * np.array(MAD_TO_SIGMA)
    )
    np.testing.assert_array_equal(
        nmad(values, axis=0, skip_nan=True)[[0, 2]], [0.5, 3.5] * np.array(MAD_TO_SIGMA)
    )
    assert np.isnan(nmad(values, axis=1)[0])  # NaN propagates unless skipped
    all_nan = nmad(np.full((2, 3), np.nan), axis=1, skip_nan=True)  # silently NaN
    assert np.isnan(all_nan).all()
    assert np.isnan(nmad([1.0, np.nan, 2.0]))


def test_median_of_finite_values_is_numpys_median_to_the_bit():
    assert median_of_finite(np.array([3.0, -1.0, 2.0])) == 2.0
    assert median_of_finite(np.array([4.0, 1.0, 2.0, 3.0])) == 2.5
    assert median_of_finite(np.array([7.0])) == 7.0
    rng = np.random.default_rng(5)
    for n in (2, 3, 30, 31, 760, 761):
        for _ in range(50):
            values = rng.standard_normal(n) * 10.0 ** rng.uniform(-8, 8) + rng.normal(0, 1e3)
            assert median_of_finite(values) == float(np.median(values))
            assert mad(values) == float(np.median(np.abs(values - np.median(values))))


def test_weights_of_known_residuals():
    with np.errstate(divide="ignore"):  # no floor: a zero residual divides by zero, weight 1
        np.testing.assert_array_equal(
            huber_weight([0.0, -1.0, 2.69, -5.38], 1.345), [1, 1, 0.5, 0.25]
        )
    assert huber_weight(4.0, 1.0, scale=2.0) == 0.5
    assert huber_weight(0.0, 1.0, floor=1e-300) == 1.0
    np.testing.assert_array_equal(
        huber_weight([0.0, 4.0], 1.0, floor=1e-300, prior=[3.0, 3.0]), [3.0, 0.75]
    )
    c = 2.385
    np.testing.assert_allclose(
        cauchy_weight(np.array([0.0, c, -2 * c]), c), [1.0, 0.5, 0.2], rtol=1e-15
    )
    assert cauchy_weight(c, c, prior=4.0) == 2.0
    np.testing.assert_array_equal(
        student_weight(np.array([0.0, 1.0, -np.sqrt(6.0)]), 4.0), [1.25, 1.0, 0.5]
    )
    assert student_weight(1.0, 4.0, prior=2.0) == 2.0


def test_huber_psi_of_known_residuals():
    np.testing.assert_array_equal(
        huber_psi(np.array([0.0, 1.0, -1.5, 2.69, -5.38]), 1.345),
        [0.0, 1.0, -1.345, 1.345, -1.345],
    )
    u = np.array([-1e300, -2.5, 0.0, 7.0, 1e300])
    np.testing.assert_array_equal(huber_psi(u, np.inf), u)  # k = ∞: least squares
    assert huber_psi(-0.5, 0.5) == -0.5  # the bound itself is inside
    assert np.isnan(huber_psi(np.nan, 1.0))


def test_huber_inflated_variance_of_known_residuals():
    np.testing.assert_array_equal(
        huber_inflated_variance(2.0, np.array([0.0, 3.0, -6.0, -1.5, 7.5]), 3.0),
        [2.0, 2.0, 4.0, 2.0, 5.0],
    )
    np.testing.assert_array_equal(  # variances and residuals side by side
        huber_inflated_variance(np.array([1.0, 4.0, 0.5]), np.array([8.0, -2.0, -16.0]), 2.0),
        [4.0, 4.0, 4.0],
    )
    np.testing.assert_array_equal(
        huber_inflated_variance(np.array([1.0, 2.0]), np.array([1e300, -1e300]), np.inf),
        [1.0, 2.0],
    )
    assert huber_inflated_variance(3.0, np.nan, 1.0) == 3.0  # a NaN residual keeps it


def test_the_inflated_variance_bounds_a_kalman_update_by_k_standard_deviations():
    """Gain P⁻/(S/w) with u = ν/√S: a gross innovation moves the state by k·P⁻/√S exactly as
    far as an innovation of k standard deviations, and by no more."""
    P_pred, r, k = 0.75, 0.25, 3.0
    S = P_pred + r
    nu = np.array([0.5, 3.0, 30.0, -300.0])
    moved = P_pred / huber_inflated_variance(S, nu / np.sqrt(S), k) * nu
    np.testing.assert_allclose(moved, [0.375, 2.25, 2.25, -2.25], rtol=1e-15)


def test_huber_variance_is_least_squares_with_infinite_k_and_counts_the_clipped():
    residual = np.array([1.0, -1.0, 2.0, -2.0])
    assert huber_variance(residual, 1.0, np.inf, 1) == 10.0 / 3.0
    # k = 1.5: ψ = 1, −1, 1.5, −1.5 (Σψ² = 6.5), m = 1/2, K = 1 + 1·0.5/(4·0.5) = 1.25
    assert huber_variance(residual, 1.0, 1.5, 1) == pytest.approx(
        1.25**2 * 6.5 / 3 / 0.25, rel=1e-15
    )
    assert np.isnan(huber_variance(residual, 1.0, 0.5, 1))


def _line_problem(x, y):
    X = np.column_stack([np.ones_like(x), x])

    def solve(w):
        sw = np.sqrt(w)
        return np.linalg.lstsq(X * sw[:, None], y * sw, rcond=None)[0]

    return solve, lambda w: y - X @ solve(w)


def _huber(residual, _pass, k=1.345):
    scale = nmad(residual)
    return None if scale <= 0 else huber_weight(residual, k, scale, floor=1e-300)


def test_huber_irls_recovers_a_line_through_one_gross_outlier():
    x = np.arange(11.0)
    y = 2.0 + 0.5 * x
    y[7] += 100.0
    solve, fit = _line_problem(x, y)
    assert abs(solve(np.ones_like(x))[1] - 0.5) > 0.5  # least squares is pulled away
    weights = irls(fit, _huber, np.ones_like(x), 50, tolerance=1e-12)
    np.testing.assert_allclose(solve(weights), [2.0, 0.5], rtol=0, atol=1e-9)
    assert weights[7] < 1e-12


def test_cauchy_irls_from_a_huber_start_recovers_the_line():
    x = np.arange(20.0)
    y = -1.0 + 0.25 * x + 1e-3 * np.cos(x)  # small, smooth noise
    y[[3, 15]] += [40.0, -25.0]
    solve, fit = _line_problem(x, y)

    def weigh(residual, n):
        if n < 2:
            return _huber(residual, n)
        return cauchy_weight(residual / nmad(residual), 2.385)

    weights = irls(fit, weigh, np.ones_like(x), 30)
    assert np.abs(solve(np.ones_like(x)) - [-1.0, 0.25]).max() > 0.5
    np.testing.assert_allclose(solve(weights), [-1.0, 0.25], atol=1e-3)
    assert weights[[3, 15]].max() < 1e-5 * np.delete(weights, [3, 15]).min()


def test_irls_runs_the_passes_in_order_and_stops_when_told_or_settled():
    seen = []

    def fit(w):
        seen.append(("fit", w))
        return np.float64(w)

    def weigh(residual, n):
        seen.append(("weigh", n))
        return residual + 1.0

    assert irls(fit, weigh, 0.0, 3) == 3.0
    assert seen == [
        ("fit", 0.0),
        ("weigh", 0),
        ("fit", 1.0),
        ("weigh", 1),
        ("fit", 2.0),
        ("weigh", 2),
    ]
    assert irls(fit, lambda r, n: None, 5.0, 3) == 5.0  # no scale: the weights stay
    assert irls(lambda w: None, weigh, 5.0, 3) == 5.0  # nothing to fit
    calls = []
    settled = irls(lambda w: calls.append(w) or w, lambda r, n: r / 2.0, np.array([1.0]), 50, 0.1)
    np.testing.assert_array_equal(settled, [0.0625])  # 1 → ½ → ¼ → ⅛ → 1/16, the last step < 0.1
    assert len(calls) == 4


finite = st.floats(-1e6, 1e6, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(
    st.lists(finite, min_size=1, max_size=40),
    st.floats(1e-3, 1e3),
    st.booleans(),
    finite,
)
def test_nmad_is_shift_invariant_and_scale_equivariant(values, factor, negative, shift):
    values = np.asarray(values)
    a = -factor if negative else factor
    expected = abs(a) * nmad(values)
    tolerance = 1e-9 * (abs(a) * np.max(np.abs(values)) + abs(shift)) + 1e-300
    assert nmad(a * values + shift) == pytest.approx(expected, abs=tolerance * 10)
    assert nmad(a * values, centre=False) == pytest.approx(
        abs(a) * nmad(values, centre=False), rel=1e-12
    )


@settings(max_examples=200, deadline=None)
@given(
    st.lists(finite, min_size=1, max_size=20),
    st.floats(1e-3, 1e3),
    st.floats(1e-6, 1e6),
)
def test_huber_psi_and_inflated_variance_are_the_weight(u, k, variance):
    """ψ(u) = u·w(u) (R2′), |ψ| ≤ k, and S/(S/w(u)) = w(u) (R2″), to rounding."""
    u = np.asarray(u)
    weight = huber_weight(u, k, floor=1e-300)
    psi = huber_psi(u, k)
    np.testing.assert_allclose(psi, u * weight, rtol=1e-15, atol=0)
    assert np.all(np.abs(psi) <= k)
    np.testing.assert_allclose(
        variance / huber_inflated_variance(variance, u, k), weight, rtol=1e-15, atol=0
    )


@settings(max_examples=100, deadline=None)
@given(
    st.lists(st.floats(-10.0, 10.0), min_size=4, max_size=30, unique=True),
    st.floats(-100.0, 100.0),
    st.floats(-10.0, 10.0),
    st.integers(0, 2**32 - 1),
)
def test_irls_on_clean_data_is_least_squares(x, intercept, slope, seed):
    """Clean: no residual of the least-squares fit beyond k scales, so every weight stays 1 and
    IRLS stops after one pass at least squares, to the bit."""
    x = np.asarray(x)
    y = intercept + slope * x + np.random.default_rng(seed).normal(0.0, 0.1, x.size)
    solve, fit = _line_problem(x, y)
    least = solve(np.ones_like(x))
    residual = fit(np.ones_like(x))
    scale = nmad(residual)
    k = 1.01 * np.max(np.abs(residual)) / scale if scale > 0 else 1.0
    calls = []

    def counted(w):
        calls.append(1)
        return fit(w)

    weights = irls(counted, lambda r, n: _huber(r, n, k), np.ones_like(x), 50, tolerance=0.0)
    np.testing.assert_array_equal(weights, 1.0)
    np.testing.assert_array_equal(solve(weights), least)
    assert len(calls) == 1
