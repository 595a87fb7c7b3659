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
windows, guards against optimistic a-priori σ. Each statistic is divided by the ratio of that
variance to its noise-only value.

Real noise (variance components fitted from the data, :func:`receiver_noise`): real Doppler
errors are correlated in time — multipath, the atmosphere, orbit errors, tracking loops, and the
vertical velocity of a road that is not level, which the model leaves out — so over a window of
a few seconds part of each satellite's error is a constant, κ·σ_i on its rows (d_j). Over tens
of rows that constant does not average down as white noise would, and a test that assumed so
would name clean satellites biased (on the comma2k19 minute it flagged three windows in four).
It adds κ²·Σ_k (c_jᵀW(I − H)d_k)² to the variance of c_jᵀWr and κ²·Σ_k (w_i[(I − H)d_k]_i)² to
that of w_i r_i. σ₀ and κ are pooled over every window of the recording (one receiver), so that
a reflection cannot hide by raising its own window's scale.

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

from dataclasses import dataclass, replace

import numpy as np
from scipy.special import chdtri, gammaincinv

from vo_doppler.heading.profile import (
    minimum_cost,
    project_out,
    projected_normal_matrix,
    weighted_gram,
    z_of,
)
from vo_doppler.robust import nmad

MIN_SCALE_DOF = 10
"""Windows with fewer degrees of freedom do not estimate the scale of the a-priori σ."""
CORRELATED_QUANTILE = 0.25
"""κ matches this quantile of the satellite statistics to χ²(1)'s: it stays put while up to
three quarters of the (window, satellite) statistics are raised by a bias (a reflection biases
its own satellite and, through the fit, smears into every other satellite of its windows)."""
MAX_PAIR_SATELLITES = 12
"""Two-satellite hypotheses are formed among this many satellites of largest statistic."""


def chi2_isf_1(q):
    """χ²(1)'s inverse survival function (``scipy.stats.chi2.isf(q, 1)`` for 0 < q < 1, the
    same special function) without importing scipy.stats (about 0.4 s per process)."""
    return chdtri(1, q)


@dataclass
class SnoopingResult:
    """Per window: the rows to reject (K, R), whether a bias was detected, whether its
    satellite (or row) was identified, and the smallest redundancy number of the satellites
    present (1 if none)."""

    reject: np.ndarray
    detected: np.ndarray
    identified: np.ndarray
    row_fault: np.ndarray
    """The largest statistic of a detected fault is a row's (a blunder), not a satellite's."""
    theta: np.ndarray
    """θ₀ of the least-squares fit that was tested."""
    min_redundancy: np.ndarray
    bias_variance: np.ndarray
    """Largest increase of var θ₀ (rad²) if one tested satellite had its own unknown bias."""
    suspect_theta: np.ndarray
    """θ₀ (K, n_groups) under the bias hypothesis of each satellite that is a suspect: its
    statistic is significant, or the identification odds cannot rule it out against the
    largest (NaN for the others)."""
    noise: ReceiverNoise


def _group_sums(values, flat, shape):
    """Σ per (window, group) of ``values`` (K, R) or (K, R, C), flattened index ``flat``."""
    size = shape[0] * shape[1]
    if values.ndim == 2:
        return np.bincount(flat, values.ravel(), size).reshape(shape)
    columns = [np.bincount(flat, values[..., c].ravel(), size) for c in range(values.shape[-1])]
    return np.stack(columns, -1).reshape(*shape, values.shape[-1])


def _cost_with_biases(normal, S_X, S_T, S_w, grid_size, iterations):
    """θ₀ and the minimum profiled cost when each window (leading axis) also fits one constant
    bias per selected satellite: sums (K, H, n, ·) of the n disjoint satellites of H
    hypotheses."""
    XtWX, XtWT, TtWT = (m[:, None] for m in normal)
    lead = S_w.shape[:2]
    XtWT_h = np.concatenate(
        [np.broadcast_to(XtWT, (*lead, 3, 2)), np.swapaxes(S_X, -1, -2)], axis=-1
    )
    top = np.concatenate([np.broadcast_to(TtWT, (*lead, 2, 2)), np.swapaxes(S_T, -1, -2)], -1)
    bottom = np.concatenate([S_T, S_w[..., None] * np.eye(S_w.shape[-1])], axis=-1)
    Q = project_out(XtWX, XtWT_h, np.concatenate([top, bottom], axis=-2))[0]
    return minimum_cost(Q, grid_size, iterations)


@dataclass(frozen=True)
class SnoopWindows:
    """The padded windows (K, R) tested, as in
    :func:`vo_doppler.heading.tight_heading.solve_windows`: coefficients ``a``, ``b``, reduced
    observations ``y``, row times ``tau``, a-priori weights ``w`` of the rows in the fit (0
    elsewhere), ``group`` the satellite index in [0, n_groups); ``calibration_sigma`` the
    relative speed-scale and gyro-bias (rad/s) standard deviations (K,) each."""

    a: np.ndarray
    b: np.ndarray
    y: np.ndarray
    tau: np.ndarray
    w: np.ndarray
    group: np.ndarray
    n_groups: int
    calibration_sigma: tuple[np.ndarray, np.ndarray]

    def finite(self) -> SnoopWindows:
        """The same windows with NaN coefficients (padding) as zeros."""
        return replace(self, a=np.nan_to_num(self.a), b=np.nan_to_num(self.b))

    @property
    def shape(self) -> tuple[int, int]:
        """(windows, satellite groups)."""
        return len(self.w), self.n_groups

    @property
    def flat(self) -> np.ndarray:
        """Each row's (window, group) as one flat index (:func:`_group_sums`)."""
        return (np.arange(len(self.w))[:, None] * self.n_groups + self.group).ravel()

    def group_sums(self, values) -> np.ndarray:
        """Σ per (window, group) of ``values`` (K, R) or (K, R, C)."""
        return _group_sums(values, self.flat, self.shape)


@dataclass(frozen=True)
class SnoopSettings:
    """The tests' settings (:class:`vo_doppler.heading.tight_heading.TightHeadingConfig`):
    the θ₀ grid and Gauss–Newton iterations, the false-alarm probability ``alpha`` per window,
    the ``identification_odds`` and the smallest redundancy number tested."""

    grid_size: int
    iterations: int
    alpha: float
    identification_odds: float
    min_redundancy: float


@dataclass(frozen=True)
class _LeastSquares:
    """The windows' fit without bias parameters: X, T, XᵀWX, XᵀWT, (TᵀWT)⁺, θ₀ and its cost."""

    X: np.ndarray
    T: np.ndarray
    XtWX: np.ndarray
    XtWT: np.ndarray
    TtWT_pinv: np.ndarray
    theta: np.ndarray
    cost: np.ndarray


def _least_squares(windows: SnoopWindows, settings: SnoopSettings) -> _LeastSquares:
    """:class:`_LeastSquares` of ``windows`` (finite coefficients)."""
    X = np.stack([-windows.a, -windows.b, windows.y], axis=-1)
    T = np.stack([np.ones_like(windows.tau), -windows.tau], axis=-1)
    Q0, XtWX, XtWT, TtWT_pinv, _ = projected_normal_matrix(X, T, windows.w)
    theta, cost0 = minimum_cost(Q0, settings.grid_size, settings.iterations)
    return _LeastSquares(X, T, XtWX, XtWT, TtWT_pinv, theta, cost0)


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


def _linearise(windows: SnoopWindows, fit: _LeastSquares) -> _Linearised:
    """:class:`_Linearised` of the least-squares ``fit`` of ``windows``."""
    a, b, tau, w, theta = windows.a, windows.b, windows.tau, windows.w, fit.theta
    cos_t, sin_t = np.cos(theta)[:, None], np.sin(theta)[:, None]
    j_theta = -a * sin_t + b * cos_t
    J = np.stack([j_theta, np.ones_like(tau), -tau], axis=-1)
    z = z_of(theta)
    params = (fit.TtWT_pinv @ (fit.XtWT.transpose(0, 2, 1) @ z[:, :, None]))[:, :, 0]
    residual = (fit.X @ z[:, :, None])[:, :, 0] - np.einsum("krj,kj->kr", fit.T, params)
    normalised = np.where(w > 0, np.abs(residual) * np.sqrt(w), np.nan)
    # windows without rows give NaN: no scale-up
    mad = np.nan_to_num(nmad(normalised, axis=1, centre=False, skip_nan=True))
    N_inv = np.linalg.pinv(weighted_gram(J, w, J), hermitian=True)
    leverage = np.sum((J @ N_inv) * J, axis=-1) * w
    model_rows = []
    errors = (a * cos_t + b * sin_t, -tau * j_theta)
    for m, sigma in zip(errors, windows.calibration_sigma, strict=True):
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


@dataclass(frozen=True)
class _Statistics:
    """The test statistics of every satellite (K, n_groups) and row (K, R), which of them are
    tested, the variance of each satellite's c_jᵀWr and the bias-free θ₀ (and cost) under
    each satellite's hypothesis."""

    satellite: np.ndarray
    row: np.ndarray
    satellite_ok: np.ndarray
    row_ok: np.ndarray
    variance: np.ndarray
    seen: np.ndarray
    single_theta: np.ndarray
    single_cost: np.ndarray
    sums: tuple
    """:func:`_satellite_sums` of the windows."""


def _statistics(windows, settings, fit, lin, terms, noise) -> _Statistics:
    """Satellite statistics λ_j (the cost's drop when satellite j gets a bias, over its
    variance ratio) and row w-tests (module docstring); the noise model ``noise``."""
    w = windows.w
    sums = _satellite_sums(windows, fit)
    single_theta, single = _cost_with_biases(
        sums[3],
        sums[0][:, :, None],
        sums[1][:, :, None],
        sums[2][:, :, None],
        settings.grid_size,
        settings.iterations,
    )
    sat_ok = (sums[2] > 0) & (terms.redundancy >= settings.min_redundancy)
    variance = noise.variance(terms)
    row_variance = (
        noise.scale**2 * lin.row_seen
        + noise.correlated**2 * terms.row_correlated
        + sum(m**2 for m in lin.model_rows)
    )
    row_ok = (w > 0) & (lin.row_seen >= settings.min_redundancy * w)
    drop = np.clip(fit.cost[:, None] - single, 0.0, None)
    seen = terms.seen
    sat_stat = np.where(sat_ok, drop * seen / np.where(sat_ok, variance, 1.0), 0.0)
    row_stat = np.where(row_ok, lin.weighted_residual**2 / np.where(row_ok, row_variance, 1.0), 0.0)
    return _Statistics(
        sat_stat, row_stat, sat_ok, row_ok, variance, seen, single_theta, single, sums
    )


def _satellite_sums(windows: SnoopWindows, fit: _LeastSquares):
    """Per (window, satellite) Σ w·X, Σ w·T and Σ w, and the windows' normal matrices
    (XᵀWX, XᵀWT, TᵀWT): what each bias hypothesis adds to the fit."""
    w = windows.w
    S_w = windows.group_sums(w)
    S_X = windows.group_sums(w[..., None] * fit.X)
    S_T = windows.group_sums(w[..., None] * fit.T)
    return S_X, S_T, S_w, (fit.XtWX, fit.XtWT, weighted_gram(fit.T, w, fit.T))


def snoop_satellites(
    windows: SnoopWindows, settings: SnoopSettings, noise: ReceiverNoise | None = None
) -> SnoopingResult:
    """Bias tests of every satellite and every row of every window (module docstring).

    ``settings.alpha`` is the false-alarm probability per window, half for the satellite tests
    and half for the row tests, each half shared among the n tests (Bonferroni: α/(2n)).
    Satellites and rows whose redundancy number is below ``settings.min_redundancy`` are not
    tested: so little of a bias would show that the statistic would measure the model's small
    unmodelled errors rather than the observation. ``noise``: σ₀ and κ of the receiver's
    noise (default: :func:`receiver_noise` of these windows).
    """
    windows = windows.finite()
    fit = _least_squares(windows, settings)
    lin = _linearise(windows, fit)
    terms = _satellite_terms(lin, windows.w, windows.group, windows.flat, windows.shape)
    if noise is None:
        tested = (windows.group_sums(windows.w) > 0) & (terms.redundancy >= settings.min_redundancy)
        noise = receiver_noise([_sample(lin, terms, tested)])
    stats = _statistics(windows, settings, fit, lin, terms, noise)
    return _decide(windows, settings, fit, stats, noise, (lin, terms))


def _decide(windows, settings, fit, stats: _Statistics, noise, linearised) -> SnoopingResult:
    """The decision on the statistics ``stats`` (module docstring): detection against the
    Bonferroni-shared critical values, identification by the likelihood-ratio margin, the
    rows to reject, and the pair hypotheses where a satellite's bias was detected."""
    lin, terms = linearised
    w, group, n_groups = windows.w, windows.group, windows.n_groups
    sat_stat, row_stat = stats.satellite, stats.row
    sat_ok, row_ok = stats.satellite_ok, stats.row_ok
    K = len(w)
    n_sat, n_row = np.count_nonzero(sat_ok, axis=1), np.count_nonzero(row_ok, axis=1)
    best_sat, best_row = np.argmax(sat_stat, axis=1), np.argmax(row_stat, axis=1)
    k = np.arange(K)
    sat_max, row_max = sat_stat[k, best_sat], row_stat[k, best_row]
    row_critical = chi2_isf_1(settings.alpha / (2 * np.maximum(n_row, 1)))
    sat_critical = chi2_isf_1(settings.alpha / (2 * np.maximum(n_sat, 1)))
    detected = (sat_max > sat_critical) | (row_max > row_critical)
    by_row = row_max > sat_max
    suspect = np.where(by_row, group[k, best_row], best_sat)
    own = group == suspect[:, None]
    largest = np.maximum(sat_max, row_max)
    other_sat = np.where(sat_ok & (np.arange(n_groups) != suspect[:, None]), sat_stat, 0.0)
    other_row = np.where(row_ok & ~own, row_stat, 0.0)
    runner_up = np.maximum(np.max(other_sat, axis=1), np.max(other_row, axis=1, initial=0.0))
    margin = 2.0 * np.log(settings.identification_odds)
    identified = largest - runner_up >= margin
    significant_rows = own & (row_stat > row_critical[:, None])
    significant_rows[k, best_row] = True
    reject = np.where(by_row[:, None], significant_rows, own)
    two = np.flatnonzero(detected & ~by_row & (n_sat >= 2))
    if two.size:
        S_X, S_T, S_w, normal = stats.sums
        pair, pair_identified, pair_wins = _pairs(
            two,
            (S_X, S_T, S_w, stats.seen / np.where(sat_ok, stats.variance, 1.0), sat_stat, sat_ok),
            normal,
            stats.single_cost[two, best_sat[two]],
            (settings.grid_size, settings.iterations),
            settings.alpha,
            margin,
        )
        windows_won = two[pair_wins]
        chosen = pair[pair_wins]
        reject[windows_won] = (group[windows_won] == chosen[:, :1]) | (
            group[windows_won] == chosen[:, 1:]
        )
        identified[windows_won] = pair_identified[pair_wins]
    suspects = sat_ok & (
        (sat_stat > largest[:, None] - margin) | (sat_stat > sat_critical[:, None])
    )
    return SnoopingResult(
        reject=reject & (w > 0) & (detected & identified)[:, None],
        detected=detected,
        identified=identified,
        row_fault=detected & (sat_max <= sat_critical),
        theta=fit.theta,
        bias_variance=np.max(
            np.where(sat_ok, (terms.A @ lin.N_inv)[..., 0] ** 2 * stats.variance, 0.0)
            / np.where(sat_ok, stats.seen, 1.0) ** 2,
            axis=1,
            initial=0.0,
        ),
        min_redundancy=np.min(terms.redundancy, axis=1, initial=1.0),
        suspect_theta=np.where(suspects, stats.single_theta, np.nan),
        noise=noise,
    )


@dataclass
class _SatelliteTerms:
    """Per (window, satellite) sums of the linearised fit (module docstring): A_j = Σ_j w·J,
    the noise-only variance ``seen`` of c_jᵀWr (unit σ₀), its part ``correlated`` from a
    window-constant error of unit κ on every satellite, the calibration errors' part
    ``model``, c_jᵀWr itself and the redundancy number."""

    A: np.ndarray
    seen: np.ndarray
    correlated: np.ndarray
    model: np.ndarray
    weighted_residual: np.ndarray
    redundancy: np.ndarray
    row_correlated: np.ndarray
    """Per row (K, R): the part of var(w·r) from the window-constant errors of unit κ."""
    n_rows: np.ndarray


def _satellite_terms(lin: _Linearised, w, group, flat, shape) -> _SatelliteTerms:
    """c_jᵀW(I − H)d_k = δ_jk·Σ_j √w − A_j N⁻¹ B_kᵀ, B_k = Σ_k √w·J, is how much of satellite
    k's window-constant error (σ_i·κ on its rows) shows in satellite j's sum; squared and summed
    over k: Σ_j √w² − 2·Σ_j √w·A_j N⁻¹ B_jᵀ + A_j N⁻¹ (Σ_k B_kᵀB_k) N⁻¹ A_jᵀ."""
    S_w = _group_sums(w, flat, shape)
    root = np.sqrt(w)
    S_root = _group_sums(root, flat, shape)
    A = _group_sums(w[..., None] * lin.J, flat, shape)
    B = _group_sums(root[..., None] * lin.J, flat, shape)
    AN = A @ lin.N_inv
    seen = np.clip(S_w - np.sum(AN * A, axis=-1), 0.0, None)
    spread = lin.N_inv @ (np.swapaxes(B, -1, -2) @ B) @ lin.N_inv
    correlated = np.clip(
        S_root**2 - 2.0 * S_root * np.sum(AN * B, axis=-1) + np.sum((A @ spread) * A, axis=-1),
        0.0,
        None,
    )
    present = S_w > 0
    own = np.take_along_axis(B, group[..., None], axis=1)
    row_correlated = np.clip(
        w
        - 2.0 * w * root * np.einsum("krj,kjl,krl->kr", lin.J, lin.N_inv, own)
        + w**2 * np.einsum("krj,kjl,krl->kr", lin.J, spread, lin.J),
        0.0,
        None,
    )
    return _SatelliteTerms(
        row_correlated=row_correlated,
        n_rows=_group_sums((w > 0).astype(float), flat, shape),
        A=A,
        seen=seen,
        correlated=correlated,
        model=sum(_group_sums(m, flat, shape) ** 2 for m in lin.model_rows),
        weighted_residual=_group_sums(lin.weighted_residual, flat, shape),
        redundancy=np.where(present, seen / np.where(present, S_w, 1.0), 1.0),
    )


@dataclass(frozen=True)
class ReceiverNoise:
    """The receiver's Doppler noise relative to the a-priori σ_i of each row: white noise of
    σ₀·σ_i per row plus an error of κ·σ_i constant over the window on each satellite."""

    scale: float
    """σ₀ ≥ 1, the scale of the a-priori σ (:func:`receiver_noise`)."""
    correlated: float
    """κ ≥ 0, the window-constant share of each satellite's noise."""

    def variance(self, terms: _SatelliteTerms) -> np.ndarray:
        """Variance of c_jᵀWr per (window, satellite): σ₀²·seen + κ²·correlated + model."""
        return self.scale**2 * terms.seen + self.correlated**2 * terms.correlated + terms.model


@dataclass
class NoiseSample:
    """What :func:`receiver_noise` pools from a set of windows: per window the MAD scale of
    the normalised residuals and the degrees of freedom; per tested (window, satellite) the
    squared sum (c_jᵀWr)² and the parts of its variance (:class:`_SatelliteTerms`)."""

    mad: np.ndarray
    dof: np.ndarray
    squared_sum: np.ndarray
    seen: np.ndarray
    correlated: np.ndarray
    model: np.ndarray


def _sample(lin: _Linearised, terms: _SatelliteTerms, tested: np.ndarray) -> NoiseSample:
    """The numbers of :class:`NoiseSample`; κ only from satellites with several rows in windows
    with at least ``MIN_SCALE_DOF`` degrees of freedom (a satellite's one row cannot tell a
    window-constant error from white noise, nor a window with few rows a bias from noise)."""
    tested = tested & (terms.n_rows >= 2) & (lin.dof >= MIN_SCALE_DOF)[:, None]
    return NoiseSample(
        mad=lin.mad,
        dof=lin.dof,
        squared_sum=terms.weighted_residual[tested] ** 2,
        seen=terms.seen[tested],
        correlated=terms.correlated[tested],
        model=terms.model[tested],
    )


def noise_statistics(windows: SnoopWindows, settings: SnoopSettings) -> NoiseSample:
    """What :func:`receiver_noise` pools from these windows (the same numbers
    :func:`snoop_satellites` computes on its first pass). Windows solved in several chunks
    share one noise model by pooling these over every chunk."""
    windows = windows.finite()
    lin = _linearise(windows, _least_squares(windows, settings))
    terms = _satellite_terms(lin, windows.w, windows.group, windows.flat, windows.shape)
    tested = (windows.group_sums(windows.w) > 0) & (terms.redundancy >= settings.min_redundancy)
    return _sample(lin, terms, tested)


def receiver_noise(samples: list[NoiseSample]) -> ReceiverNoise:
    """σ₀ and κ of the receiver's noise (:class:`ReceiverNoise`), robust estimates pooled over
    every window of the samples (variance components fitted by medians).

    σ₀ ≥ 1: the median over windows of the MAD scale of their normalised residuals, from
    windows with at least ``MIN_SCALE_DOF`` degrees of freedom (1 if none). κ ≥ 0: the value
    for which the median of the satellite statistics (c_jᵀWr)²/(σ₀²·seen + κ²·correlated +
    model) over every tested (window, satellite) is the median of χ²(1), their distribution
    with no biased satellite; 0 when it already is at most that. Real Doppler errors are
    correlated in time (tracking loops, multipath, the vertical velocity and the atmosphere
    the model leaves out), so a satellite's rows of one window do not average down as white
    noise would, and a test that assumed so would flag clean satellites.

    One value for the receiver, not one per window: in a window with little redundancy a biased
    row smears into every residual and its own scale would hide the bias; the medians stay
    put while fewer than half of the satellites are biased.
    """
    mad, dof = (np.concatenate([getattr(s, f) for s in samples]) for f in ("mad", "dof"))
    usable = mad[dof >= MIN_SCALE_DOF]
    scale = max(1.0, float(np.median(usable))) if usable.size else 1.0
    parts = {
        f: np.concatenate([getattr(s, f) for s in samples])
        for f in ("squared_sum", "seen", "correlated", "model")
    }
    white = scale**2 * parts["seen"] + parts["model"]
    target = 2.0 * gammaincinv(0.5, CORRELATED_QUANTILE)

    def excess(kappa2: float) -> float:
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = parts["squared_sum"] / (white + kappa2 * parts["correlated"])
        ratio = np.nan_to_num(ratio, nan=0.0, posinf=0.0)
        return float(np.quantile(ratio, CORRELATED_QUANTILE)) - target

    if not parts["seen"].size or excess(0.0) <= 0.0:
        return ReceiverNoise(scale, 0.0)
    # scipy.optimize (about 22 MiB resident) loads here, in the heading stage, not with the
    # module: the processes that import it and never fit the noise stay without it.
    from scipy.optimize import brentq

    upper = 1.0
    while excess(upper) > 0.0 and upper < 1e12:
        upper *= 10.0
    return ReceiverNoise(scale, float(np.sqrt(brentq(excess, 0.0, upper, xtol=1e-6, rtol=1e-6))))


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
    _, cost = _cost_with_biases(
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
    wins = largest > chi2_isf_1(alpha / np.maximum(n_tests - 1, 1))
    return np.stack([g1[rows, best], g2[rows, best]], axis=1), identified, wins
