"""Data snooping for the tightly coupled heading: which satellite's Doppler is biased (NLOS)?

A reflected (non-line-of-sight) signal adds to its range rate the rate of the extra path,
−2·(v·m)·|u_n| for a facade with unit normal u_n, m the unit vector towards it: a bias that
stays nearly constant over a window of a few seconds on a straight road, ramps in a turn, and
starts or stops where the reflecting facade does. Three families of fault hypotheses cover it:

* satellite H_j: "satellite j is biased by an unknown constant ∇ over the window" (the model
  gets ∇·c_j, c_j the indicator of the window's rows of satellite j);
* row H_i: "row i alone is biased" (a blunder, or the part of a reflection that is not
  constant over the window);
* pair H_jk: two satellites biased at once, which one satellite test can mask (a second bias
  drags the fit so that a clean satellite looks worst).

Satellite statistic (generalised likelihood ratio; Baarda's w-test squared when the model is
linear): the drop of the weighted residual sum of squares when ∇ joins the linear parameters,

    λ_j = min_θ₀ zᵀQ₀z − min_θ₀ zᵀQ_jz,       λ_j ~ χ²(1) when no satellite is biased,

with Q the profiled cost of :mod:`vo_doppler.heading.profile` (Q_j has c_j as a further column
of T). θ₀ is re-estimated under each hypothesis over the whole circle, so a biased satellite
that pulled the fit into a wrong minimum is still found. Every quantity is a per-satellite
partial sum of the window's normal equations, so all hypotheses of all windows are solved at
once; pairs (λ_jk ~ χ²(2)) only where a bias was detected. Row statistic: the w-test
(w_i r_i)² / var(w_i r_i) of the least-squares fit linearised at its θ₀ (design
J = ∂model/∂(θ₀, ρ₀, α), N = JᵀWJ, var = w_i − w_i² J_i N⁻¹ J_iᵀ).

Redundancy number: the share of a bias on satellite j that shows in the residuals,
r_j = (Σ_j w − A_j N⁻¹ A_jᵀ)/Σ_j w with A_j = Σ_j w·J (rows alike). Near zero (as many
independent constraints as unknowns; one satellite, whose bias is a clock drift; two
satellites on a straight road) a bias cannot be detected: such satellites and rows are not
tested, and a window using one is *unverifiable*.

Errors the noise model leaves out — a speed-scale error ε and a gyro-bias error δb of the
calibration — move every row coherently (model error m_ε = a·cos θ₀ + b·sin θ₀ per unit ε,
m_b = −τ·J_θ per unit δb) and look like satellite biases: they add (c_jᵀ W Q_r W m)²·σ² to the
variance of c_jᵀWr (Q_r the residuals' cofactor matrix), whose noise part is
σ₀²·(Σ_j w − A_j N⁻¹ A_jᵀ); σ₀ ≥ 1, a robust scale of the normalised residuals over all
windows (:func:`receiver_noise_scale`), guards against optimistic a-priori σ. Each
statistic is divided by the ratio of that variance to its noise-only value.

Decision: the false-alarm probability α of a window is split between the satellite and the row
family and Bonferroni-shared among their tests. The largest statistic names a satellite only
when that hypothesis is at least ``identification_odds`` times likelier than every hypothesis
on another satellite, i.e. λ − λ_other ≥ 2 ln(odds) (likelihood ratio exp(Δλ/2)); hypotheses
that explain the residuals equally well (redundancy one at satellite level, e.g. three
satellites on a straight road, give equal λ) leave the window inconsistent rather than
repaired. A named satellite loses all its rows (satellite hypothesis) or all its rows whose
own test is significant (row hypothesis); the best pair replaces the best single satellite when
its second bias is significant (λ_jk − λ_j beyond the χ²(1) critical value).

Heading variance after a repair: a window that had to reject a reflected satellite may hold
another whose bias stayed below detection. Giving satellite j its own bias parameter adds
g_j²·var(∇̂_j) to var θ₀ (Schur complement; g_j = (N⁻¹A_jᵀ)_θ, var(∇̂_j) the variance of
c_jᵀWr over (Σ_j w − A_j N⁻¹ A_jᵀ)²); the largest such term over the tested satellites is
``bias_variance``.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from vo_doppler.heading.profile import (
    minimum_cost,
    project_out,
    projected_normal_matrix,
    weighted_gram,
    z_of,
)

MIN_SCALE_DOF = 10
"""Windows with fewer degrees of freedom do not estimate the scale of the a-priori σ."""
MAX_PAIR_SATELLITES = 12
"""Two-satellite hypotheses are formed among this many satellites of largest statistic."""


@dataclass
class SnoopingResult:
    """Per window: the rows to reject (K, R), whether a bias was detected, whether its
    satellite (or row) was identified, and the smallest redundancy number of the satellites
    present (1 if none)."""

    reject: np.ndarray
    detected: np.ndarray
    identified: np.ndarray
    min_redundancy: np.ndarray
    bias_variance: np.ndarray
    """Largest increase of var θ₀ (rad²) if one tested satellite had its own unknown bias."""
    noise_scale: float


def _group_sums(values, flat, shape):
    """Σ per (window, group) of ``values`` (K, R) or (K, R, C), flattened index ``flat``."""
    size = shape[0] * shape[1]
    if values.ndim == 2:
        return np.bincount(flat, values.ravel(), size).reshape(shape)
    columns = [np.bincount(flat, values[..., c].ravel(), size) for c in range(values.shape[-1])]
    return np.stack(columns, -1).reshape(*shape, values.shape[-1])


def _cost_with_biases(normal, S_X, S_T, S_w, grid_size, iterations):
    """Minimum profiled cost when each window (leading axis) also fits one constant bias per
    selected satellite: sums (K, H, n, ·) of the n disjoint satellites of H hypotheses."""
    XtWX, XtWT, TtWT = (m[:, None] for m in normal)
    lead = S_w.shape[:2]
    XtWT_h = np.concatenate(
        [np.broadcast_to(XtWT, (*lead, 3, 2)), np.swapaxes(S_X, -1, -2)], axis=-1
    )
    top = np.concatenate([np.broadcast_to(TtWT, (*lead, 2, 2)), np.swapaxes(S_T, -1, -2)], -1)
    bottom = np.concatenate([S_T, S_w[..., None] * np.eye(S_w.shape[-1])], axis=-1)
    Q = project_out(XtWX, XtWT_h, np.concatenate([top, bottom], axis=-2))[0]
    return minimum_cost(Q, grid_size, iterations)[1]


@dataclass
class _Linearised:
    """The least-squares fit linearised at its θ₀ (module docstring): per row the weighted
    residual w·r, the noise-only variance of w·r with unit σ₀ (w − w²·J N⁻¹ Jᵀ) and w·(I − H)·m
    of each calibration error m scaled by its σ; per window the MAD scale of the normalised
    residuals and the degrees of freedom."""

    weighted_residual: np.ndarray
    row_seen: np.ndarray
    model_rows: list[np.ndarray]
    mad: np.ndarray
    dof: np.ndarray
    J: np.ndarray
    N_inv: np.ndarray


def _linearise(a, b, tau, w, X, T, theta, TtWT_pinv, XtWT, calibration_sigma):
    cos_t, sin_t = np.cos(theta)[:, None], np.sin(theta)[:, None]
    j_theta = -a * sin_t + b * cos_t
    J = np.stack([j_theta, np.ones_like(tau), -tau], axis=-1)
    z = z_of(theta)
    params = (TtWT_pinv @ (XtWT.transpose(0, 2, 1) @ z[:, :, None]))[:, :, 0]
    residual = (X @ z[:, :, None])[:, :, 0] - np.einsum("krj,kj->kr", T, params)
    normalised = np.where(w > 0, np.abs(residual) * np.sqrt(w), np.nan)
    with warnings.catch_warnings():  # windows without rows give NaN: no scale-up
        warnings.simplefilter("ignore", RuntimeWarning)
        mad = 1.4826 * np.nan_to_num(np.nanmedian(normalised, axis=1))
    N_inv = np.linalg.pinv(weighted_gram(J, w, J), hermitian=True)
    leverage = np.sum((J @ N_inv) * J, axis=-1) * w
    model_rows = []
    for m, sigma in zip((a * cos_t + b * sin_t, -tau * j_theta), calibration_sigma, strict=True):
        fitted = (J @ (N_inv @ weighted_gram(J, w * m, np.ones_like(m)[..., None])))[..., 0]
        model_rows.append(w * (m - fitted) * sigma[:, None])
    return _Linearised(
        weighted_residual=w * residual,
        row_seen=np.clip(w * (1.0 - leverage), 0.0, None),
        model_rows=model_rows,
        mad=mad,
        dof=np.count_nonzero(w > 0, axis=1) - np.linalg.matrix_rank(weighted_gram(J, w, J)),
        J=J,
        N_inv=N_inv,
    )


def snoop_satellites(
    a: np.ndarray,
    b: np.ndarray,
    y: np.ndarray,
    tau: np.ndarray,
    w: np.ndarray,
    group: np.ndarray,
    n_groups: int,
    calibration_sigma: tuple[np.ndarray, np.ndarray],
    grid_size: int,
    iterations: int,
    alpha: float,
    identification_odds: float,
    min_redundancy: float,
    noise_scale: float | None = None,
) -> SnoopingResult:
    """Bias tests of every satellite and every row of every window (module docstring).

    Arrays (K, R) as in :func:`vo_doppler.heading.tight_heading.solve_windows`: coefficients
    ``a``, ``b``, reduced observations ``y``, row times ``tau``, a-priori weights ``w`` of the
    rows in the fit (0 elsewhere) and ``group`` the satellite index in [0, n_groups).
    ``calibration_sigma``: relative speed-scale and gyro-bias (rad/s) standard deviations (K,).
    ``alpha`` is the false-alarm probability per window, half for the satellite tests and
    half for the row tests, each half shared among the n tests (Bonferroni: α/(2n)).
    Satellites and rows whose redundancy number is below ``min_redundancy`` are not tested:
    so little of a bias would show that the statistic would measure the model's small
    unmodelled errors rather than the observation. ``noise_scale`` σ₀ multiplies the a-priori
    σ (default: :func:`receiver_noise_scale` of these windows).
    """
    a, b = np.nan_to_num(a), np.nan_to_num(b)
    K = len(w)
    shape = (K, n_groups)
    X, T, XtWX, XtWT, TtWT_pinv, theta, cost0 = _least_squares(
        a, b, y, tau, w, grid_size, iterations
    )
    flat = (np.arange(K)[:, None] * n_groups + group).ravel()
    S_w = _group_sums(w, flat, shape)
    S_X = _group_sums(w[..., None] * X, flat, shape)
    S_T = _group_sums(w[..., None] * T, flat, shape)
    normal = (XtWX, XtWT, weighted_gram(T, w, T))
    single = _cost_with_biases(
        normal, S_X[:, :, None], S_T[:, :, None], S_w[:, :, None], grid_size, iterations
    )
    lin = _linearise(a, b, tau, w, X, T, theta, TtWT_pinv, XtWT, calibration_sigma)

    A = _group_sums(w[..., None] * lin.J, flat, shape)
    seen = np.clip(S_w - np.sum((A @ lin.N_inv) * A, axis=-1), 0.0, None)
    if noise_scale is None:
        noise_scale = receiver_noise_scale(lin.mad, lin.dof)
    variance = noise_scale**2 * seen
    row_variance = noise_scale**2 * lin.row_seen
    for model in lin.model_rows:
        variance += _group_sums(model, flat, shape) ** 2
        row_variance += model**2
    present = S_w > 0
    redundancy = np.where(present, seen / np.where(present, S_w, 1.0), 1.0)
    sat_ok = present & (redundancy >= min_redundancy)
    row_ok = (w > 0) & (lin.row_seen >= min_redundancy * w)
    drop = np.clip(cost0[:, None] - single, 0.0, None)
    sat_stat = np.where(sat_ok, drop * seen / np.where(sat_ok, variance, 1.0), 0.0)
    row_stat = np.where(row_ok, lin.weighted_residual**2 / np.where(row_ok, row_variance, 1.0), 0.0)
    n_sat, n_row = np.count_nonzero(sat_ok, axis=1), np.count_nonzero(row_ok, axis=1)
    best_sat, best_row = np.argmax(sat_stat, axis=1), np.argmax(row_stat, axis=1)
    k = np.arange(K)
    sat_max, row_max = sat_stat[k, best_sat], row_stat[k, best_row]
    row_critical = chi2.isf(alpha / (2 * np.maximum(n_row, 1)), 1)
    detected = (sat_max > chi2.isf(alpha / (2 * np.maximum(n_sat, 1)), 1)) | (
        row_max > row_critical
    )
    by_row = row_max > sat_max
    suspect = np.where(by_row, group[k, best_row], best_sat)
    own = group == suspect[:, None]
    largest = np.maximum(sat_max, row_max)
    other_sat = np.where(sat_ok & (np.arange(n_groups) != suspect[:, None]), sat_stat, 0.0)
    other_row = np.where(row_ok & ~own, row_stat, 0.0)
    runner_up = np.maximum(np.max(other_sat, axis=1), np.max(other_row, axis=1, initial=0.0))
    margin = 2.0 * np.log(identification_odds)
    identified = largest - runner_up >= margin
    significant_rows = own & (row_stat > row_critical[:, None])
    significant_rows[k, best_row] = True
    reject = np.where(by_row[:, None], significant_rows, own)
    two = np.flatnonzero(detected & ~by_row & (n_sat >= 2))
    if two.size:
        pair, pair_identified, pair_wins = _pairs(
            two,
            (S_X, S_T, S_w, seen / np.where(sat_ok, variance, 1.0), sat_stat, sat_ok),
            normal,
            single[two, best_sat[two]],
            (grid_size, iterations),
            alpha,
            margin,
        )
        windows = two[pair_wins]
        chosen = pair[pair_wins]
        reject[windows] = (group[windows] == chosen[:, :1]) | (group[windows] == chosen[:, 1:])
        identified[windows] = pair_identified[pair_wins]
    return SnoopingResult(
        reject=reject & (w > 0) & (detected & identified)[:, None],
        detected=detected,
        identified=identified,
        bias_variance=np.max(
            np.where(sat_ok, (A @ lin.N_inv)[..., 0] ** 2 * variance, 0.0)
            / np.where(sat_ok, seen, 1.0) ** 2,
            axis=1,
            initial=0.0,
        ),
        min_redundancy=np.min(redundancy, axis=1, initial=1.0),
        noise_scale=noise_scale,
    )


def _least_squares(a, b, y, tau, w, grid_size, iterations):
    """The windows' fit without bias parameters: X, T, XᵀWX, XᵀWT, (TᵀWT)⁺, θ₀ and its cost."""
    X = np.stack([-a, -b, y], axis=-1)
    T = np.stack([np.ones_like(tau), -tau], axis=-1)
    Q0, XtWX, XtWT, TtWT_pinv, _ = projected_normal_matrix(X, T, w)
    theta, cost0 = minimum_cost(Q0, grid_size, iterations)
    return X, T, XtWX, XtWT, TtWT_pinv, theta, cost0


def noise_statistics(a, b, y, tau, w, grid_size: int, iterations: int):
    """Per window, what :func:`receiver_noise_scale` pools: the MAD scale of the normalised
    residuals of the least-squares fit and its degrees of freedom (arrays as in
    :func:`snoop_satellites`; the same numbers it computes on its first pass). Windows solved
    in several chunks share one σ₀ by pooling these over every chunk."""
    a, b = np.nan_to_num(a), np.nan_to_num(b)
    X, T, _, XtWT, TtWT_pinv, theta, _ = _least_squares(a, b, y, tau, w, grid_size, iterations)
    none = np.zeros(len(w))
    lin = _linearise(a, b, tau, w, X, T, theta, TtWT_pinv, XtWT, (none, none))
    return lin.mad, lin.dof


def receiver_noise_scale(mad: np.ndarray, dof: np.ndarray) -> float:
    """σ₀ ≥ 1 of the a-priori σ: the median over windows of the MAD scale of their normalised
    residuals, from windows with at least ``MIN_SCALE_DOF`` degrees of freedom (1 if none).

    One value for the receiver's noise model, not one per window: in a window with little
    redundancy a biased row smears into every residual and its own MAD would hide the bias.
    """
    usable = mad[dof >= MIN_SCALE_DOF]
    return max(1.0, float(np.median(usable))) if usable.size else 1.0


def _pairs(windows, sums, normal, cost_bound, solver, alpha, margin):
    """Two-satellite hypotheses in ``windows`` (module docstring): the best pair, whether it is
    identified, and whether its second bias is significant — the pair then replaces the best
    single hypothesis, which a second biased satellite can mask. ``cost_bound`` is the
    cost under the best single-satellite hypothesis."""
    S_X, S_T, S_w, scale, statistic, testable = (x[windows] for x in sums)
    normal = tuple(m[windows] for m in normal)
    n_tests = np.count_nonzero(testable, axis=1)
    order = np.argsort(np.where(testable, -statistic, np.inf), axis=1, kind="stable")
    ids = order[:, : min(int(n_tests.max()), MAX_PAIR_SATELLITES)]
    u, v = np.triu_indices(ids.shape[1], 1)
    g1, g2 = ids[:, u], ids[:, v]
    k = np.arange(len(windows))[:, None]
    cost = _cost_with_biases(
        normal,
        np.stack([S_X[k, g1], S_X[k, g2]], axis=-2),
        np.stack([S_T[k, g1], S_T[k, g2]], axis=-2),
        np.stack([S_w[k, g1], S_w[k, g2]], axis=-1),
        *solver,
    )
    gain = np.clip(cost_bound[:, None] - cost, 0.0, None) * np.minimum(scale[k, g1], scale[k, g2])
    valid = v[None, :] < n_tests[:, None]
    gain = np.where(valid, gain, -np.inf)
    best = np.argmax(gain, axis=1)
    rows = np.arange(len(windows))
    largest = gain[rows, best]
    gain[rows, best] = -np.inf
    identified = largest - np.max(gain, axis=1) >= margin
    wins = largest > chi2.isf(alpha / np.maximum(n_tests - 1, 1), 1)
    return np.stack([g1[rows, best], g2[rows, best]], axis=1), identified, wins
