"""Tightly coupled time-series heading from Doppler, gyro and wheel speed ([TK18] sec. 3.5).

For the window of epochs t ∈ (t_k − W, t_k] ending at epoch k, every Doppler row (see
:mod:`vo_doppler.model.doppler`) gives one equation in three unknowns:

    y = −G·v_t + ρ_t,    v_t = s_t · [cos θ_t, sin θ_t, g],
    θ_t = θ₀ + Φ_t − Φ_k,    ρ_t = ρ₀ − α · (t − t_k)

with s_t the calibrated (horizontal) speed, Φ the integrated calibrated yaw rate
(counter-clockwise positive, so Φ_t − Φ_k = −∫_t^{t_k} ω dτ: "θ₀ minus the integrated yaw rate
since t"), θ the yaw counter-clockwise from east, ρ the receiver clock drift (m/s), α its rate
and g = tan γ the road grade (rise over run) over the window. [TK18] takes the vertical
velocity as zero; on a road that climbs, g·s_t (0.19 m/s median on the comma2k19 minute, 1 %)
shows in every row as −g_up·g·s_t, which a level model puts into θ₀ (0.1–1° with two to four
satellites). The grade has a Gaussian prior g ~ N(μ, σ_g²) (σ_g = ``grade_sigma``, μ = 0
unless given): with three or more satellites the data outweigh it, with two on a straight road
(where θ₀ and g trade off) it keeps the window observable. θ₀ is the heading at the newest
epoch. An antenna at (r_x, r_y) off the vehicle origin moves at
v_t = R(θ_t)·[s_t − ω_t·r_y, ω_t·r_x] (v + ω × r, ω_t the calibrated yaw rate), which is still
a·cos θ₀ + b·sin θ₀ (``lever_velocity``).

Given θ₀ the model is linear in (ρ₀, α, g), so they are projected out (variable projection),
the grade's prior entering as a weighted pseudo-observation 0·θ₀ + g = μ: with
z = [cos θ₀, sin θ₀, 1] the weighted residual sum of squares (prior term included) is zᵀQz for
a 3×3 matrix Q per window — a trigonometric polynomial of degree 2 in θ₀ with at most two
minima. A grid finds
both, Gauss–Newton refines them, and iteratively re-weighted passes apply Huber weights. Two
minima that fit equally well (e.g. two satellites on a straight road) make the window
*ambiguous*: the one nearer the previous heading propagated by the gyro is kept, or the epoch
is unavailable. Whenever two separated minima and a recent heading exist, that propagated
heading weighs in as a pseudo-observation (variance σ_prev² + σ²): the root of least fit +
prior cost is kept, so that one noisy window cannot switch a two-satellite solution to its
mirror root. The θ₀ variance is s²/(J_θᵀ P J_θ) (the marginal of the full covariance, the
grade's included), s² the a-posteriori variance factor — with the grade prior's share
restored to its own σ_g where s² < 1, since s² measures the Doppler rows, not the road — or
more where the profiled cost is not a parabola (a flat
side, a near second minimum: the Δcost = n²·s² intervals, n = 1 … 3, are read off the cost),
plus the errors that white Doppler noise does not cover:
the uncertainty of the speed scale and gyro bias calibration and the random walk of the clock
drift about its linear model, propagated through the least-squares gain. Those are
correlated over the window (one scale, one bias, one clock path), so the residuals cannot
reveal them, and with one or two satellites they dominate. Every window is solved at once
with numpy.

Reflected (NLOS) Doppler: before the robust fit, data snooping on the least-squares fit
(:mod:`vo_doppler.heading.snooping`) tests every satellite of the window for a bias, every row
for a blunder and, where a bias is found, every pair of satellites; it rejects what it can
name and tests again. What it detects but cannot name makes the window *inconsistent*: its
heading is then the robust (Huber) fit's, with the θ₀ variance widened to cover every heading
that the hypotheses it could not tell apart would give (fallback); a window where a bias on
some satellite would not show is flagged *unverifiable*; after a rejected reflection the θ₀
variance allows for one more, undetected, biased satellite. The tests' noise model (σ₀ and the
window-constant share κ of each satellite's noise) is estimated from the data, pooled over every
window (:func:`vo_doppler.heading.snooping.receiver_noise`).

Reliability ([TK18] sec. 3.5): the heading at epoch k is compared with the headings of the previous
epochs of the last ``reliability_epochs`` propagated by the gyro; it is reliable when enough of
them exist and all agree within the gate, and when it also agrees with the heading of a window
that shares no row with its own (:func:`_independent_agreement`): overlapping windows agree
with each other whatever a fault that outlasts them, such as reflected satellites that
snooping took for the consistent majority.
"""

from __future__ import annotations

import warnings
from bisect import bisect_right
from dataclasses import dataclass, replace

import numpy as np

from vo_doppler.geo import wrap_angle, yaw_to_course
from vo_doppler.heading.profile import (
    dz_of,
    gauss_newton,
    grid_minima,
    projected_normal_matrix,
    quadratic,
    weighted_gram,
    z_of,
)
from vo_doppler.heading.snooping import (
    ReceiverNoise,
    SnoopSettings,
    SnoopWindows,
    noise_statistics,
    receiver_noise,
    snoop_satellites,
)
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.robust import huber_weight, irls, nmad, student_weight

ROW_FLOATS = 52
"""float64 values held per window and padded row at the peak of :func:`solve_windows`."""
HYPOTHESIS_FLOATS = 2
"""… per window, satellite and grid point (the cost of every single-satellite hypothesis)."""
PROFILE_FLOATS = 8
"""… per window and step of the profiled-cost σ (:func:`_profile_sigma`)."""


@dataclass(frozen=True)
class TightHeadingConfig:
    """Solver settings; angles in radians."""

    window_s: float = 2.0
    """The shortest window (s); longer where the rows need it (:func:`window_lengths`)."""
    max_window_s: float = 2.0
    """The longest window (s): the gyro's bias error and the straight-road model's grade grow
    with it."""
    min_window_equations: int = 4
    """… but holds at least this many rows beyond its clock unknowns (:func:`window_lengths`)."""
    max_window_m: float = 40.0
    """… nor longer than this stretch of road (m) at the epoch's speed (one grade per window)."""
    window_target_sigma_rad: float = np.radians(0.15)
    """A window grows until its rows hold the information of this heading σ."""
    noise_correlation_s: float = 1.0
    """Rows of one satellite closer in time than this count as one (:func:`window_lengths`)."""
    min_obs: int = 3
    min_speed_mps: float = 0.2
    grid_size: int = 72
    gauss_newton_iterations: int = 10
    robust_passes: int = 3
    huber_k: float = 1.345
    redescending_passes: int = 0
    """Passes with Student-t weights w·(ν + 1)/(ν + r²) after the Huber ones (r the residual over
    its σ, scaled by the window's robust spread where that is larger): a redescending
    M-estimator, whose weight falls to zero for a reflected satellite far off the fit, where
    Huber's only levels off."""
    student_dof: float = 4.0
    sigma_floor_mps: float = 0.01
    observability_ratio: float = 1e-6
    ambiguity_chi2: float = 9.0
    """Two minima more than ``ambiguity_min_separation_rad`` apart whose costs differ by less
    than this many variance factors (:func:`_ambiguity_variance`) make the window ambiguous."""
    noise_model_dof: float = 10.0
    """Degrees of freedom credited to the a-priori noise model when the ambiguity test pools
    it with a window's own variance factor (:func:`_ambiguity_variance`)."""
    ambiguity_min_separation_rad: float = np.radians(5.0)
    max_sigma_rad: float = np.radians(20.0)
    prior_max_age_s: float = 10.0
    reliability_epochs: int | None = 10
    """The earlier headings of the last this many epochs check the current one ([TK18] sec.
    3.5; at least ``reliability_min_epochs`` of them, all agreeing); None: the rule in
    seconds below (:func:`_reliability`), which means the same at every rate."""
    reliability_min_epochs: int = 5
    reliability_span_s: float = 5.0
    """The earlier headings of the last this many seconds check the current one …"""
    reliability_min_span_s: float = 2.0
    """… and must reach back at least this far …"""
    reliability_agreement: float = 0.75
    """… and this share of them must agree with it."""
    reliability_gate_rad: float = np.radians(3.0)
    reliability_n_sigma: float = 3.0
    reference_max_sigma_rad: float = np.radians(10.0)
    """An earlier window's heading confirms a later one only when its σ, with the gyro
    bias's drift since, is at most this. The independent check is for gross faults that
    outlast a window (a mirror root, a reflected satellite the heading absorbs), tens of
    degrees: a reference within 10° (gate ≈ 30°) reveals them, a vaguer one agrees with almost
    any heading (a one-satellite window at σ 16° "confirmed" a two-satellite heading 88° off,
    one satellite reflected; three satellites 0.5 s into a drive, one reflected, gave a heading
    64° off at σ 0.2° that nothing could check). A heading without an informative reference
    before it needs one after it, or a verifiable window (:func:`_independent_agreement`)."""
    epoch_match_s: float = 1e-3
    chunk_bytes: int = 16 * 2**20
    """Memory (bytes) for the windows solved at once: the windows are solved in chunks of as
    many as fit (:func:`windows_per_chunk`); the headings do not depend on it."""
    profile_step_rad: float = np.radians(0.25)
    profile_max_rad: float = np.radians(30.0)
    clock_epoch_interval_s: float = np.inf
    """From this epoch interval (median, s) on each epoch has its own clock drift
    (:func:`clock_per_epoch`)."""
    clock_drift_walk_mps_per_sqrt_s: float = 0.01
    """Random walk of the receiver clock drift (m/s per √s) that the linear model leaves out."""
    grade_sigma: float = 0.05
    """Standard deviation of the zero-mean Gaussian prior on the road grade g = tan γ (rise over
    run) of a window (0: level road, no grade unknown). Road design keeps grades within ±6 %
    on main roads and ±10–12 % on streets; σ 5 % covers both at 2σ while pulling a window whose
    geometry cannot see the vertical (two low satellites) towards level."""
    outlier_passes: int = 4
    """Rejection rounds of data snooping per window, each removing one satellite, a pair, or a
    satellite's significant rows (0: no NLOS rejection)."""
    outlier_alpha: float = 0.001
    """False-alarm probability of the bias tests per window (Baarda's α₀ = 0.001 of data
    snooping, shared among the window's satellites)."""
    identification_odds: float = 100.0
    """The satellite with the largest test statistic is named biased only when that hypothesis
    is this many times likelier than any on another satellite (generalised likelihood ratio)."""
    testable_redundancy: float = 0.05
    """Satellites whose redundancy number (the share of a bias that shows in the residuals) is
    below this are not tested; a window using such a satellite is not verifiable."""

    @classmethod
    def robust(cls) -> TightHeadingConfig:
        """The settings for receivers at any rate in deep street canyons (``--heading-method
        robust``): no data snooping (the Huber fit weighs reflections down instead of
        naming them), windows that grow with the information they need (up to 8 s,
        :func:`window_lengths`), one clock drift per epoch from 0.5 s between epochs, and
        reliability as a consensus of the last 5 s (at least 2 s of earlier headings, three
        quarters agreeing). Measured on the Hong Kong canyon drive at 1 Hz
        (``benchmarks/real_heading.py``); not yet the default because the simulated 20-Hz
        canyon of the sample loses availability with it (docs/design.md)."""
        return cls(
            outlier_passes=0,
            max_window_s=8.0,
            clock_epoch_interval_s=0.5,
            reliability_epochs=None,
        )


@dataclass
class TightHeadingResult:
    """Per-epoch heading (yaw, counter-clockwise from east); NaN where unavailable."""

    t: np.ndarray
    yaw: np.ndarray
    sigma: np.ndarray
    n_obs: np.ndarray
    n_sat_epoch: np.ndarray
    available: np.ndarray
    reliable: np.ndarray
    ambiguous: np.ndarray
    clock_drift: np.ndarray
    clock_drift_rate: np.ndarray
    n_rejected: np.ndarray
    """Rows of the window rejected as biased by data snooping (reflections, blunders)."""
    window_s: np.ndarray
    """Length (s) of the window ending at each epoch (:func:`window_lengths`)."""
    verifiable: np.ndarray
    """Every satellite used could have been tested: a bias on any would show in the residuals
    (redundancy number ≥ ``testable_redundancy``); False where it could hide, e.g. as many
    independent rows as unknowns. Unavailable epochs, and all without NLOS rejection
    (``outlier_passes`` 0), are False."""
    inconsistent: np.ndarray
    """Data snooping found a bias it could not attribute (or too many, or a repair that left
    the window unverifiable): no heading, unless the fault is a blunder (``fallback``)."""
    fallback: np.ndarray
    """The heading is the robust (Huber) fit's of an inconsistent window whose largest test
    statistic is a row's (blunders the Huber weights damp, e.g. Doppler spikes on several
    satellites), with σ widened (:func:`_fallback_variance`); not verifiable."""

    @property
    def course(self) -> np.ndarray:
        """Heading as course, clockwise from north, radians in [0, 2π); NaN where unavailable."""
        return np.where(self.available, yaw_to_course(self.yaw), np.nan)


@dataclass
class _WindowSolution:
    theta: np.ndarray
    theta_second: np.ndarray
    cost: np.ndarray
    cost_second: np.ndarray
    info: np.ndarray
    info_raw: np.ndarray
    variance_factor: np.ndarray
    variance_dof: np.ndarray
    """Degrees of freedom of ``variance_factor`` (redundant rows of the window's fit)."""
    rho0: np.ndarray
    alpha: np.ndarray
    grade: np.ndarray
    n_obs: np.ndarray
    n_rejected: np.ndarray
    inconsistent: np.ndarray
    fallback: np.ndarray
    min_redundancy: np.ndarray
    repair_variance: np.ndarray
    profile_sigma: np.ndarray
    scale_gain: np.ndarray
    bias_gain: np.ndarray
    clock_walk_gain: np.ndarray
    prior_variance: np.ndarray


def snoop_settings(config: TightHeadingConfig) -> SnoopSettings:
    """The data-snooping settings of ``config``
    (:func:`vo_doppler.heading.snooping.snoop_satellites`)."""
    return SnoopSettings(
        config.grid_size,
        config.gauss_newton_iterations,
        config.outlier_alpha,
        config.identification_odds,
        config.testable_redundancy,
    )


def _fit(X, T, prior, w, config):
    """Huber-weighted fit of padded windows (observation matrix ``X``, design ``T`` of the
    linear parameters and the precision ``prior`` of their prior, a-priori weights ``w``): the
    robust weights, both minima of the final profiled cost and the linear parameters at the
    best one."""

    def normalised(weights):
        Q, _, XtWT, TtWT_pinv, _ = projected_normal_matrix(X, T, weights, prior)
        theta = gauss_newton(Q, grid_minima(Q, config.grid_size)[0], config.gauss_newton_iterations)
        return np.abs(_residual(X, T, XtWT, TtWT_pinv, theta)) * np.sqrt(w)

    def weigh(normalised, n):
        scale = _robust_scale(normalised, w, config)
        if n < config.robust_passes:
            return huber_weight(normalised / scale[:, None], config.huber_k, floor=1e-300, prior=w)
        ratio = normalised / np.maximum(scale, 1.0)[:, None]
        return student_weight(ratio, config.student_dof, prior=w)

    passes = config.robust_passes + config.redescending_passes
    weights = irls(normalised, weigh, np.array(w), passes)
    Q, XtWX, XtWT, TtWT_pinv, rank_t = projected_normal_matrix(X, T, weights, prior)
    first, second = grid_minima(Q, config.grid_size)
    theta = gauss_newton(Q, first, config.gauss_newton_iterations)
    has_second = np.isfinite(second)
    theta2 = gauss_newton(Q, np.where(has_second, second, theta), config.gauss_newton_iterations)
    cost = quadratic(Q, z_of(theta), z_of(theta))
    cost2 = np.where(has_second, quadratic(Q, z_of(theta2), z_of(theta2)), np.inf)
    swap = cost2 < cost
    return {
        "weights": weights,
        "Q": Q,
        "XtWX": XtWX,
        "XtWT": XtWT,
        "TtWT_pinv": TtWT_pinv,
        "rank_t": rank_t,
        "theta": np.where(swap, theta2, theta),
        "theta2": np.where(swap, theta, theta2),
        "cost": np.where(swap, cost2, cost),
        "cost2": np.where(swap, cost, cost2),
    }


def linear_design(tau, grade_coefficient, grade_prior, clock_epoch=None):
    """Design T (K, R, p) of the linear parameters and their prior as pseudo-observations
    (:func:`vo_doppler.heading.profile.projected_normal_matrix`): T = [1, −τ, c] for (ρ₀, α, g)
    with g ~ N(μ, σ²) per window (``grade_prior`` = (μ, σ), each (K,)), the clock drift and its
    rate free; or T = [1, −τ] and no prior for a level road (no ``grade_coefficient`` c).

    ``clock_epoch`` (K, R): each row's epoch counted back from the window's newest (0): one
    free clock drift per epoch instead of ρ₀ − α·τ, T = [e₀ … e_E, c] (indicator columns; the
    first is the newest epoch's drift, so that the first parameter is ρ₀ in both models)."""
    if clock_epoch is None:
        columns = [np.ones_like(tau), -tau]
    else:
        n_epochs = int(np.max(clock_epoch, initial=0)) + 1
        indicator = clock_epoch[..., None] == np.arange(n_epochs)
        columns = list(np.moveaxis(indicator.astype(float), -1, 0))
    if grade_coefficient is None:
        return np.stack(columns, axis=-1), None
    mean, sigma = (np.broadcast_to(np.asarray(v, dtype=float), tau.shape[:1]) for v in grade_prior)
    linear = np.zeros((len(mean), len(columns) + 1))
    linear[:, -1] = 1.0
    prior = (
        np.stack([np.zeros_like(mean), np.zeros_like(mean), mean], axis=-1)[:, None, :],
        linear[:, None, :],
        sigma[:, None] ** -2.0,
    )
    return np.stack([*columns, grade_coefficient], axis=-1), prior


def _residual(X, T, XtWT, TtWT_pinv, theta):
    """Observation − model per row at θ₀, with (ρ₀, α, g) at their conditional optimum."""
    z = z_of(theta)
    params = (TtWT_pinv @ (XtWT.transpose(0, 2, 1) @ z[:, :, None]))[:, :, 0]
    return (X @ z[:, :, None])[:, :, 0] - np.einsum("krj,kj->kr", T, params)


@dataclass(frozen=True)
class PaddedWindows:
    """Windows padded to one width, arrays (K, R): reduced observations ``y``, coefficients
    ``a``, ``b`` (model a·cos θ₀ + b·sin θ₀ + ρ₀ − α·τ + c·g), row times ``tau`` relative to
    the window end, weights ``w`` (0 on padding), the satellite ``group`` of each row, the
    grade coefficient c = −g_up·s_t (how the window's road grade g moves each row: the
    vertical velocity g·s_t seen along the line of sight) and each row's epoch counted back
    from the window's newest, ``clock_epoch`` (:func:`linear_design`; None: one clock line)."""

    y: np.ndarray
    a: np.ndarray
    b: np.ndarray
    tau: np.ndarray
    w: np.ndarray
    group: np.ndarray | None = None
    grade_coefficient: np.ndarray | None = None
    clock_epoch: np.ndarray | None = None


@dataclass
class _Snooped:
    """What data snooping left of the windows (:func:`_snoop_windows`): the rows accepted,
    which windows are inconsistent and whose largest statistic was a row's (a blunder), the
    smallest redundancy number and whether the window was verifiable before any repair, the
    room for one more biased satellite, which windows rejected a reflection (more than one row
    at once), the θ₀ of the suspects and of the least-squares fit (:func:`_fallback_variance`)
    and the noise model used."""

    accepted: np.ndarray
    inconsistent: np.ndarray
    blunder: np.ndarray
    min_redundancy: np.ndarray
    verifiable_before: np.ndarray
    bias_variance: np.ndarray
    reflection: np.ndarray
    suspects: np.ndarray
    noise: ReceiverNoise | None


def _snoop_windows(windows: PaddedWindows, config, calibration_sigma, noise) -> _Snooped:
    """Data snooping on the least-squares fit of every window (:func:`solve_windows`): reject
    what is identified and test again, up to ``config.outlier_passes`` times."""
    a, b, y, tau, w, group = windows.a, windows.b, windows.y, windows.tau, windows.w, windows.group
    K, R = w.shape
    if group is None:
        group = np.broadcast_to(np.arange(R), (K, R))
    n_groups = int(np.max(group, initial=0)) + 1
    scale_sigma, bias_sigma = calibration_sigma
    out = _Snooped(
        accepted=w > 0,
        inconsistent=np.zeros(K, dtype=bool),
        blunder=np.zeros(K, dtype=bool),
        min_redundancy=np.zeros(K),  # untested windows are not verifiable
        verifiable_before=np.zeros(K, dtype=bool),
        bias_variance=np.zeros(K),
        reflection=np.zeros(K, dtype=bool),
        suspects=np.full((K, n_groups + 1), np.nan),
        noise=noise,
    )
    todo = np.arange(K)
    for rejection in range(config.outlier_passes + 1):
        if not (todo.size and config.outlier_passes):
            break
        window_rows = SnoopWindows(
            a[todo],
            b[todo],
            y[todo],
            tau[todo],
            w[todo] * out.accepted[todo],
            group[todo],
            n_groups,
            (scale_sigma[todo], bias_sigma[todo]),
        )
        tests = snoop_satellites(window_rows, snoop_settings(config), out.noise)
        out.noise = tests.noise
        if rejection == 0:
            out.verifiable_before = tests.min_redundancy >= config.testable_redundancy
        out.min_redundancy[todo] = tests.min_redundancy
        out.bias_variance[todo] = tests.bias_variance
        detected = tests.detected
        failed = detected if rejection == config.outlier_passes else detected & ~tests.identified
        out.inconsistent[todo[failed]] = True
        out.suspects[todo[failed]] = np.column_stack(
            [tests.suspect_theta[failed], tests.theta[failed]]
        )
        out.blunder[todo[failed]] = tests.row_fault[failed]
        if rejection == config.outlier_passes:
            break
        repair = detected & tests.identified
        todo = todo[repair]
        out.accepted[todo] &= ~tests.reject[repair]
        out.reflection[todo] |= np.count_nonzero(tests.reject[repair], axis=1) > 1
    return out


def solve_windows(
    windows: PaddedWindows,
    config: TightHeadingConfig = TightHeadingConfig(),
    calibration_sigma=(0.0, 0.0),
    noise: ReceiverNoise | None = None,
    grade_prior=(0.0, None),
) -> _WindowSolution:
    """Solve padded ``windows`` at once (a :class:`_WindowSolution`). The road grade g is a
    linear unknown with the Gaussian prior ``grade_prior`` = (μ, σ) per window or scalars
    (σ None: ``config.grade_sigma``; :func:`linear_design`). No ``grade_coefficient``, or
    ``config.grade_sigma`` 0: a level road.

    The windows' ``group`` (default: every row its own) is the unit of NLOS rejection: data
    snooping on the least-squares fit (:mod:`vo_doppler.heading.snooping`, :func:`_snoop_windows`)
    rejects the biased satellite (or rows, or pair of satellites) it identifies and tests again,
    up to ``config.outlier_passes`` times per window; the robust fit then uses the rows left. A
    significant test that cannot name its satellite, one that still fails after the last pass,
    or a repair that leaves a verifiable window unverifiable (a satellite whose bias could no
    longer show), makes the window inconsistent: its θ₀ variance then covers the headings of
    every satellite hypothesis the tests could not rule out, and at least one more biased
    satellite (:func:`_fallback_variance`). After rejecting more than one row at once (a
    reflection lasts; a lone row is a blunder) the θ₀ variance allows for one more biased
    satellite (``bias_variance`` of :mod:`vo_doppler.heading.snooping`).
    ``calibration_sigma`` = (speed scale σ, gyro bias σ), per window or scalars, are the
    calibration uncertainties the tests allow for. ``noise``: σ₀ and κ of the tests (default:
    pooled over these windows, :func:`vo_doppler.heading.snooping.receiver_noise`).
    """
    a, b, y, tau, w = windows.a, windows.b, windows.y, windows.tau, windows.w
    clock_epoch = windows.clock_epoch
    K = len(w)
    X = np.stack([-a, -b, y], axis=-1)
    grade_coefficient = None if config.grade_sigma <= 0 else windows.grade_coefficient
    grade_mean, grade_sigma = grade_prior
    grade_sigma = config.grade_sigma if grade_sigma is None else grade_sigma
    T, prior = linear_design(tau, grade_coefficient, (grade_mean, grade_sigma), clock_epoch)
    calibration_sigma = tuple(
        np.broadcast_to(np.asarray(v, dtype=float), (K,)) for v in calibration_sigma
    )
    snooped = _snoop_windows(windows, config, calibration_sigma, noise)
    accepted = snooped.accepted
    fit = _fit(X, T, prior, w * accepted, config)
    theta, cost = fit["theta"], fit["cost"]
    z, dz = z_of(theta), dz_of(theta)
    params = (fit["TtWT_pinv"] @ (fit["XtWT"].transpose(0, 2, 1) @ z[:, :, None]))[:, :, 0]
    n_obs = np.count_nonzero(w > 0, axis=1)
    n_used = np.count_nonzero(accepted, axis=1)
    # A repair must not leave a window unverifiable that was verifiable: what remains has to be
    # able to reveal a bias (exclusion, then detection).
    lost = snooped.verifiable_before & (snooped.min_redundancy < config.testable_redundancy)
    lost &= n_used < n_obs
    inconsistent = snooped.inconsistent | lost
    fallback = inconsistent & snooped.blunder & ~lost
    variance = _variance_factor((X, T, prior), np.where(accepted, w, 0.0), fit, fallback, config)
    Q = fit["Q"]
    return _WindowSolution(
        theta=theta,
        theta_second=np.where(np.isfinite(fit["cost2"]), fit["theta2"], np.nan),
        cost=cost,
        cost_second=fit["cost2"],
        info=quadratic(Q, dz, dz),
        info_raw=quadratic(fit["XtWX"], dz, dz),
        **variance,
        profile_sigma=_profile_sigma(Q, theta, cost, variance["variance_factor"], config),
        rho0=params[:, 0],
        alpha=params[:, 1] if clock_epoch is None else np.full(K, np.nan),
        grade=params[:, -1] if prior is not None else np.zeros(K),
        n_obs=n_obs,
        n_rejected=n_obs - n_used,
        inconsistent=inconsistent,
        fallback=fallback,
        min_redundancy=snooped.min_redundancy,
        repair_variance=np.where(
            fallback,
            _fallback_variance(snooped.suspects, theta, snooped.bias_variance),
            np.where(snooped.reflection, snooped.bias_variance, 0.0),
        ),
        **_error_gains(a, b, tau, T, prior, fit["weights"], theta, clock_epoch is None),
    )


def _variance_factor(model, used_w, fit, fallback, config) -> dict[str, np.ndarray]:
    """The a-posteriori variance factor s² of each window's robust fit (``model`` = X, T and
    the grade prior; ``used_w`` the a-priori weights of the rows used), at least the floor
    ``sigma_floor_mps``², and its degrees of freedom, as the :class:`_WindowSolution` fields
    ``variance_factor`` and ``variance_dof``. Fallback windows: the Huber weights hide the
    fault that could not be named, so the scatter is judged with the a-priori weights (the
    least-squares variance factor at the robust θ₀) where that is larger."""
    X, T, prior = model
    cost, z = fit["cost"], z_of(fit["theta"])
    n_used = np.count_nonzero(used_w > 0, axis=1)
    # the prior is one pseudo-observation of the parameter it adds
    dof = n_used + (prior is not None) - (1 + fit["rank_t"])
    mean_w = np.sum(used_w, axis=1) / np.maximum(n_used, 1)
    floor = config.sigma_floor_mps**2 * mean_w
    posterior = np.where(dof > 0, np.maximum(cost, 0) / np.maximum(dof, 1), 1.0)
    robust = np.flatnonzero(fallback & (dof > 0))
    Q_prior = projected_normal_matrix(
        X[robust], T[robust], used_w[robust], None if prior is None else [v[robust] for v in prior]
    )[0]
    unweighted = quadratic(Q_prior, z[robust], z[robust]) / dof[robust]
    posterior[robust] = np.maximum(posterior[robust], unweighted)
    return {
        "variance_factor": np.maximum(posterior, floor),
        "variance_dof": np.maximum(dof, 0).astype(float),
    }


def _ambiguity_variance(sol: _WindowSolution, config: TightHeadingConfig) -> np.ndarray:
    """The variance factor that judges whether a window's two minima fit alike: its own s²
    (ν degrees of freedom) pooled with the a-priori noise model (s² = 1) counted as
    ν₀ = ``noise_model_dof``, (ν·s² + ν₀) / (ν + ν₀), the posterior mean of a scaled
    inverse-χ² prior on the variance factor (docs/design.md, "Ambiguity"). A window with a
    handful of redundant rows can fit far below the noise by chance (s² 0.04–0.15 with three
    degrees of freedom on the comma2k19 minute at 1 Hz): dividing the two roots' cost gap by
    that s² made a gap of about one noise variance look like 14–27 χ², and the wrong root a
    confident heading. With many redundant rows s² speaks for itself."""
    nu, nu0 = sol.variance_dof, config.noise_model_dof
    return (nu * sol.variance_factor + nu0) / (nu + nu0)


def _fallback_variance(suspects, theta, bias_variance):
    """Variance added to the robust θ₀ of a window whose fault could not be named: the sum of
    its squared distances to the θ₀ of the least-squares fit and of each suspect satellite's
    bias hypothesis (``suspects``: those θ₀, NaN for the satellites not suspected; as if every
    suspect were biased, the shifts independent), at least the room for one undetected
    bias."""
    shift = np.where(np.isfinite(suspects), wrap_angle(suspects - theta[:, None]) ** 2, 0.0)
    return np.maximum(np.sum(shift, axis=1), bias_variance)


def _profile_sigma(Q, theta, cost, variance_factor, config):
    """Standard deviation of θ₀ read off the profiled cost: max over n of w_n / n, with w_n the
    largest distance from θ₀ at which the cost is still within n² variance factors of its
    minimum (n = 1 … 3).

    The cost is a trigonometric polynomial of θ₀, not a parabola: with one or two satellites
    it can be flat on one side of the minimum, or have a second minimum nearby that fits
    almost as well, so the curvature at the minimum overstates the precision and an error of
    "five sigmas" is not rare. For a quadratic cost every w_n / n equals the curvature's σ; a
    flat side or a near second minimum makes one of them larger. The distances are found on a
    grid of ``profile_step_rad`` both sides, up to ``profile_max_rad``.
    """
    offsets = np.arange(0, round(config.profile_max_rad / config.profile_step_rad) + 1)
    offsets = offsets * config.profile_step_rad
    rows = np.arange(len(Q))
    width = np.zeros(len(Q))
    for side in (-1.0, 1.0):
        Z = z_of(np.nan_to_num(theta)[:, None] + side * offsets[None, :])
        rise = (np.einsum("kgi,kij,kgj->kg", Z, Q, Z) - cost[:, None]) / variance_factor[:, None]
        rise[:, 0] = 0.0
        for n in (1.0, 2.0, 3.0):
            inside = rise < n**2
            last = len(offsets) - 1 - np.argmax(inside[:, ::-1], axis=1)
            after = np.minimum(last + 1, len(offsets) - 1)
            step = np.maximum(rise[rows, after] - rise[rows, last], 1e-300)
            fraction = np.clip((n**2 - rise[rows, last]) / step, 0.0, 1.0)
            reach = offsets[last] + fraction * (offsets[after] - offsets[last])
            width = np.maximum(width, reach / n)
    return width


def _error_gains(a, b, tau, T, prior, weights, theta, clock_walks=True):
    """How errors the noise model leaves out move θ₀, per window (linearised at θ₀).

    The weighted least-squares gain g = e₀ᵀ(JᵀWJ + P)⁺JᵀW of θ₀ (J = ∂model/∂(θ₀, ρ₀, α[, g]),
    i.e. [J_θ, T], P the prior's precision on the linear parameters) maps a model error δm to
    δθ₀ = g·δm. A relative speed-scale error ε gives δm = ε·(a cos θ₀ +
    b sin θ₀); a yaw-rate bias error δb rotates row t by −δb·τ, δm = −δb·τ·J_θ; a clock drift
    that random-walks with unit intensity adds ∫ (Σ_{t_i ≥ s} g_i)² ds to var θ₀ (Brownian
    covariance min(s, t) − t_start, with the constant and linear parts absorbed by ρ₀ and α).
    The prior's pseudo-observations (T_p, w_p) carry their own gain: an error of the prior mean
    of σ = 1/√w_p moves θ₀ by (N⁻¹T_pᵀ)_θ·√w_p, so ``prior_variance`` = Σ_p (N⁻¹T_pᵀ)_θ²·w_p
    is the part of var θ₀ that the prior's σ, not the Doppler noise, sets. With one clock drift
    per epoch (``clock_walks`` False) the walk is absorbed and its gain is zero.
    """
    # Windows without a solution (no rows, or no yaw at their end) are unavailable anyway.
    theta, a, b, weights = (np.nan_to_num(x) for x in (theta, a, b, weights))
    cos_t, sin_t = np.cos(theta)[:, None], np.sin(theta)[:, None]
    j_theta = -a * sin_t + b * cos_t
    J = np.concatenate([j_theta[..., None], T], axis=-1)
    normal_inv, prior_variance = _normal_inverse(J, weights, prior)
    g = np.einsum("kj,krj,kr->kr", normal_inv[:, 0, :], J, weights)
    tail = np.cumsum(g[:, ::-1], axis=1)[:, ::-1]
    step = np.diff(tau, axis=1, prepend=tau[:, :1])
    return {
        "scale_gain": np.sum(g * (a * cos_t + b * sin_t), axis=1),
        "bias_gain": -np.sum(g * tau * j_theta, axis=1),
        "clock_walk_gain": np.sum(np.maximum(step, 0.0) * tail**2, axis=1) * clock_walks,
        "prior_variance": prior_variance,
    }


def _normal_inverse(J, weights, prior):
    """(JᵀWJ + P)⁺ per window for the Jacobian J = [∂model/∂x, T] of one parameter x and the
    linear parameters T, P the precision of ``prior`` (X_p, T_p, w_p) on the latter, and the
    part of var x that the prior's σ sets: Σ_p (N⁻¹T_pᵀ)_x²·w_p (an error of the prior mean of
    σ = 1/√w_p moves x by (N⁻¹T_pᵀ)_x·√w_p; zero without a prior)."""
    normal = weighted_gram(J, weights, J)
    if prior is None:
        return np.linalg.pinv(normal, hermitian=True), np.zeros(len(J))
    _, Tp, wp = prior
    normal[:, 1:, 1:] += weighted_gram(Tp, wp, Tp)
    normal_inv = np.linalg.pinv(normal, hermitian=True)
    prior_gain = np.einsum("kj,kpj->kp", normal_inv[:, 0, 1:], Tp)
    return normal_inv, np.sum(prior_gain**2 * wp, axis=1)


def _robust_scale(normalised, w, config):
    """NMAD (R1) of the normalised residuals (≥ 0, not centred) per window, floored: the scale
    of the Huber weights."""
    mad = nmad(np.where(w > 0, normalised, np.nan), axis=1, centre=False, skip_nan=True)
    with warnings.catch_warnings():  # windows without rows give NaN, replaced below
        warnings.simplefilter("ignore", RuntimeWarning)
        mean_w = np.nanmean(np.where(w > 0, w, np.nan), axis=1)
    floor = config.sigma_floor_mps * np.sqrt(np.nan_to_num(mean_w, nan=1.0))
    return np.maximum(np.nan_to_num(mad, nan=1.0), np.maximum(floor, 1e-300))


def _match_epochs(row_t, t_epoch, tolerance):
    """Index of the epoch of each row (−1 when no epoch lies within ``tolerance``)."""
    position = np.clip(np.searchsorted(t_epoch, row_t), 1, max(len(t_epoch) - 1, 1))
    left = np.maximum(position - 1, 0)
    right = np.minimum(position, len(t_epoch) - 1)
    nearest = np.where(np.abs(t_epoch[left] - row_t) <= np.abs(t_epoch[right] - row_t), left, right)
    return np.where(np.abs(t_epoch[nearest] - row_t) <= tolerance, nearest, -1)


def tight_heading_series(
    rows: DopplerRows,
    t_epoch: np.ndarray,
    speed: np.ndarray,
    yaw_angle: np.ndarray,
    config: TightHeadingConfig = TightHeadingConfig(),
    speed_scale_sigma: np.ndarray | float = 0.0,
    gyro_bias_sigma: np.ndarray | float = 0.0,
    lever_velocity: np.ndarray | float = 0.0,
    grade_prior: tuple = (0.0, None),
    calibration: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> TightHeadingResult:
    """Heading at every epoch from the window of Doppler rows ending there ([TK18] sec. 3.5).

    ``speed`` (m/s) and ``yaw_angle`` Φ (rad, integral of the calibrated counter-clockwise yaw
    rate) are given per epoch; rows are matched to epochs by time. ``speed_scale_sigma``
    (relative) and ``gyro_bias_sigma`` (rad/s), per epoch or scalars, are the uncertainties of
    the calibration behind them; they enter the heading's standard deviation together with
    the Doppler noise and the clock-drift random walk
    (``config.clock_drift_walk_mps_per_sqrt_s``).

    ``lever_velocity`` (m, 2) or a scalar: the antenna's velocity relative to the vehicle
    origin in the vehicle frame (along, across) = ω × r = (−ω·r_y, ω·r_x) for an antenna at
    (r_x, r_y) turning at ω (:func:`antenna_offset_velocity`); the Doppler rows then see
    v_t = R(θ_t)·[s_t + along_t, across_t] instead of s_t·[cos θ_t, sin θ_t].

    ``grade_prior`` = (μ, σ), per epoch or scalars: the Gaussian prior of the road grade of the
    window ending at each epoch (σ None: ``config.grade_sigma``; a level road when that is 0).

    ``calibration`` = (k, b, B) per epoch: the wheel scale and gyro bias current at each epoch
    and B(t) = ∫ b̂ dt, the bias integral already taken out of ``yaw_angle`` (a causal
    calibration changes as data arrive). Each window then uses the calibration of its newest
    epoch for all its rows, s_t·k_k/k_t and Φ_t − Φ_k + B_t − B_k − b_k·(t − t_k), which is what
    ``speed_scale_sigma`` and ``gyro_bias_sigma`` of that epoch describe: without it, the rows of
    a window at the start of a drive carry the prior's scale and bias while its σ is already
    the first estimate's, a heading far off at a small σ (docs/benchmarks.md, "A street canyon
    from the start").

    Many parameters because it is the heading stage's solver entry point: after the rows and
    the per-epoch sensors, each argument is an independent optional input, passed by keyword
    (``heading/pipeline.py`` shares them with :func:`speed_scale_ratio` as one dict); gathering
    them into an input dataclass is issue 32's open work together with that caller.
    """
    t_epoch = np.asarray(t_epoch, dtype=float)
    speed = np.asarray(speed, dtype=float)
    yaw_angle = np.asarray(yaw_angle, dtype=float)
    m = len(t_epoch)
    scale_sigma = np.broadcast_to(np.asarray(speed_scale_sigma, dtype=float), (m,))
    bias_sigma = np.broadcast_to(np.asarray(gyro_bias_sigma, dtype=float), (m,))
    if np.any(np.diff(t_epoch) <= 0):
        raise ValueError("epoch times must be strictly increasing")
    if m == 0:
        return _unavailable(t_epoch)
    sensors = _EpochSensors(t_epoch, speed, yaw_angle, lever_velocity, grade_prior, calibration)
    windows = _WindowRows.build(rows, sensors, config, bias_sigma)
    if windows.empty:
        return _unavailable(t_epoch, windows.n_sat_epoch)
    solution = _solve_in_chunks(windows, config, (scale_sigma, bias_sigma))
    model_variance = _model_variance(solution, (scale_sigma, bias_sigma), config)
    gyro = (yaw_angle, bias_sigma)
    n_sat_epoch = windows.n_sat_epoch
    return _decide(solution, model_variance, t_epoch, speed, gyro, n_sat_epoch, windows, config)


def _solve_in_chunks(windows: _WindowRows, config, calibration_sigma) -> _WindowSolution:
    """Every window solved (:func:`solve_windows`) in chunks of as many as fit in
    ``config.chunk_bytes`` (:func:`windows_per_chunk`), with one receiver noise model pooled
    over every chunk (:func:`vo_doppler.heading.snooping.noise_statistics`) when there are
    several; ``calibration_sigma`` = (speed scale σ, gyro bias σ) per epoch."""
    scale_sigma, bias_sigma = calibration_sigma
    m = len(windows.length)
    size = windows_per_chunk(windows.width, windows.n_groups, config)
    chunks = [np.arange(start, min(start + size, m)) for start in range(0, m, size)]
    noise = None
    if len(chunks) > 1 and config.outlier_passes:
        samples = []
        for k in chunks:
            padded = windows.padded(k)
            window_rows = SnoopWindows(
                padded.a,
                padded.b,
                padded.y,
                padded.tau,
                padded.w,
                padded.group,
                windows.n_groups,
                (scale_sigma[k], bias_sigma[k]),
            )
            samples.append(noise_statistics(window_rows, snoop_settings(config)))
        noise = receiver_noise(samples)
    solutions = [
        solve_windows(
            windows.padded(k), config, (scale_sigma[k], bias_sigma[k]), noise, windows.grade_at(k)
        )
        for k in chunks
    ]
    return _concatenate(solutions)


def _model_variance(solution: _WindowSolution, calibration_sigma, config) -> np.ndarray:
    """The part of var θ₀ the Doppler noise does not cover: the speed scale's and gyro bias's
    calibration σ (``calibration_sigma``, per epoch) and the clock drift's random walk through
    their gains, a repair's allowance, and the grade prior's share where s² < 1."""
    scale_sigma, bias_sigma = calibration_sigma
    return (
        (solution.scale_gain * scale_sigma) ** 2
        + (solution.bias_gain * bias_sigma) ** 2
        + solution.clock_walk_gain * config.clock_drift_walk_mps_per_sqrt_s**2
        + solution.repair_variance
        # s²/info scales the whole var θ₀ by the Doppler rows' variance factor s², but the
        # grade prior's part is set by its own σ: where s² < 1 it is restored to full size
        + np.clip(1.0 - solution.variance_factor, 0.0, None) * solution.prior_variance
    )


MIN_SCALE_WINDOWS = 10
"""Fewer disjoint windows with a known heading give no speed scale (:func:`speed_scale_ratio`)."""


def clock_per_epoch(t_epoch: np.ndarray, config: TightHeadingConfig) -> bool:
    """One clock drift per epoch (:func:`linear_design`) where the epochs are at least
    ``config.clock_epoch_interval_s`` apart (median): over a second a receiver clock's drift
    wanders further than a line in time follows (the Hong Kong M8T's jumps 0.17 m/s from one
    1-Hz epoch to the next), while at 10–20 Hz the line holds and an unknown per epoch would
    cost the rows' information on θ₀."""
    if len(t_epoch) < 2:
        return False
    return bool(np.median(np.diff(t_epoch)) >= config.clock_epoch_interval_s)


def speed_scale_ratio(
    rows: DopplerRows,
    t_epoch: np.ndarray,
    speed: np.ndarray,
    yaw_angle: np.ndarray,
    yaw: np.ndarray,
    informative: np.ndarray,
    config: TightHeadingConfig = TightHeadingConfig(),
    lever_velocity: np.ndarray | float = 0.0,
    grade_prior: tuple = (0.0, None),
    calibration: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
) -> tuple[float, float] | None:
    """Ratio r of the true horizontal speed to ``speed``, and its σ, from the Doppler rows of
    windows whose heading ``yaw`` is known (None with fewer than :data:`MIN_SCALE_WINDOWS`).

    This project's addition, for drives whose wheel speed nothing else calibrates (a street
    canyon from the start). With θ₀ given, the rows of :func:`tight_heading_series`'s window
    with the speed scaled by r read y = r·(a·cos θ₀ + b·sin θ₀) + ρ₀ − α·τ + c·g, linear in r:
    the clock terms and the grade (with its prior) are projected out as for θ₀, and
    r_j = −Q₀₁/Q₀₀ per window, var r_j = s_j²/Q₀₀. A constant speed is not separable from the
    clock drift, so the information comes from accelerating, braking and turning. Windows are
    taken among ``informative`` ending at least ``config.window_s`` apart (no shared rows).
    r is their weighted median (weights 1/var r_j). Its σ has a part that pooling reduces,
    1.2533·s/√Σ(1/var r_j) with s the robust spread of the normalised (r_j − r)/σ_j (at least 1),
    and one it does not: the grade prior's mean error is shared by every window (an
    accelerometer's bias), and a prior σ_g moves r_j by |(N⁻¹)_{r,g}|/σ_g (N the window's
    normal matrix with the prior), whose weighted mean is added in quadrature. With the two
    highest satellites, whose lines of sight are mostly vertical, that part dominates: the grade
    and the speed scale trade off.

    Many parameters because it takes :func:`tight_heading_series`'s inputs by the same keywords
    (see there) plus the headings.
    """
    t_epoch = np.asarray(t_epoch, dtype=float)
    speed, yaw_angle = np.asarray(speed, dtype=float), np.asarray(yaw_angle, dtype=float)
    sensors = _EpochSensors(t_epoch, speed, yaw_angle, lever_velocity, grade_prior, calibration)
    windows = _WindowRows.build(rows, sensors, config)
    candidates = np.flatnonzero(np.asarray(informative, dtype=bool) & np.isfinite(yaw))
    chosen, last = [], -np.inf
    for k in candidates:
        if t_epoch[k] - last >= config.window_s:
            chosen.append(k)
            last = t_epoch[k]
    if windows.empty or len(chosen) < MIN_SCALE_WINDOWS:
        return None
    chosen = np.asarray(chosen)
    padded = windows.padded(chosen)
    y, a, b, tau, w = padded.y, padded.a, padded.b, padded.tau, padded.w
    theta = yaw[chosen][:, None]
    X = np.stack([-(a * np.cos(theta) + b * np.sin(theta)), y], axis=-1)
    use_grade = config.grade_sigma > 0
    T, prior = linear_design(
        tau,
        padded.grade_coefficient if use_grade else None,
        windows.grade_at(chosen),
        padded.clock_epoch,
    )
    if prior is not None:
        prior = (prior[0][..., 1:], prior[1], prior[2])
    Q, _, _, _, rank = projected_normal_matrix(X, T, w, prior)
    info = Q[:, 0, 0]
    dof = np.sum(w > 0, axis=1) - 1 - rank
    jacobian = np.concatenate([-X[..., :1], T], axis=-1)
    prior_sigma = np.sqrt(_normal_inverse(jacobian, w, prior)[1])
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = -Q[:, 0, 1] / info
        variance = (Q[:, 1, 1] - Q[:, 0, 1] ** 2 / info) / dof / info
    ok = (info > 0) & (dof > 0) & np.isfinite(ratio) & np.isfinite(variance) & (variance > 0)
    if ok.sum() < MIN_SCALE_WINDOWS:
        return None
    ratio, weight, prior_sigma = ratio[ok], 1.0 / variance[ok], prior_sigma[ok]
    order = np.argsort(ratio)
    cumulative = np.cumsum(weight[order])
    median = float(ratio[order][np.searchsorted(cumulative, 0.5 * cumulative[-1])])
    spread = max(nmad(np.abs(ratio - median) * np.sqrt(weight), centre=False), 1.0)
    white = 1.2533 * spread / float(np.sqrt(np.sum(weight)))
    shared = float(np.sum(weight * prior_sigma) / np.sum(weight))
    return median, float(np.hypot(white, shared))


@dataclass(frozen=True)
class _EpochSensors:
    """Per epoch (as :func:`tight_heading_series`'s arguments): times (s), speed (m/s), the
    integrated calibrated yaw rate Φ (rad), the antenna's lever velocity, the grade prior
    (μ, σ) and the causal calibration (k, b, B) or None."""

    t_epoch: np.ndarray
    speed: np.ndarray
    yaw_angle: np.ndarray
    lever_velocity: np.ndarray | float
    grade_prior: tuple
    calibration: tuple[np.ndarray, np.ndarray, np.ndarray] | None


@dataclass(frozen=True)
class _WindowRows:
    """The Doppler rows matched to epochs, each window's rows on demand (:meth:`padded`) and
    the grade prior per epoch (:meth:`grade_at`); arguments as :func:`tight_heading_series`'s."""

    rows: DopplerRows
    per_row: tuple[np.ndarray, np.ndarray]
    index: np.ndarray
    row_epoch: np.ndarray
    bounds: tuple[np.ndarray, np.ndarray]
    per_epoch: tuple
    grade: tuple[np.ndarray, np.ndarray]
    n_sat_epoch: np.ndarray
    length: np.ndarray
    """Each window's length (s, :func:`window_lengths`)."""
    per_epoch_clock: bool
    """One clock drift per epoch (:func:`clock_per_epoch`)."""
    width: int
    n_groups: int

    @classmethod
    def build(cls, rows, sensors: _EpochSensors, config, gyro_bias_sigma=0.0) -> _WindowRows:
        """The ``rows`` matched to the epochs of ``sensors``, each window's length
        (:func:`window_lengths`, with the gyro bias σ per epoch) and the rows it holds."""
        t_epoch, speed, yaw_angle = sensors.t_epoch, sensors.speed, sensors.yaw_angle
        lever_velocity, grade_prior = sensors.lever_velocity, sensors.grade_prior
        calibration = sensors.calibration
        m = len(t_epoch)
        lever = np.broadcast_to(np.asarray(lever_velocity, dtype=float), (m, 2))
        grade_sigma = config.grade_sigma if grade_prior[1] is None else grade_prior[1]
        grade = tuple(
            np.broadcast_to(np.asarray(v, dtype=float), (m,)) for v in (grade_prior[0], grade_sigma)
        )
        epoch_of_row = _match_epochs(rows.t, t_epoch, config.epoch_match_s)
        y_all = rows.reduced()
        usable = (
            (epoch_of_row >= 0)
            & np.isfinite(y_all)
            & np.all(np.isfinite(rows.los), axis=1)
            & (rows.weight > 0)
        )
        n_sat_epoch = np.bincount(epoch_of_row[usable], minlength=m)[:m]
        epoch_safe = np.maximum(epoch_of_row, 0)
        usable &= np.isfinite(speed[epoch_safe]) & np.isfinite(yaw_angle[epoch_safe])
        index = np.flatnonzero(usable)
        row_group = np.unique(rows.sat_id, return_inverse=True)[1].reshape(-1)
        row_epoch = epoch_of_row[index]
        per_epoch_clock = clock_per_epoch(t_epoch, config)
        information, equations = epoch_information(
            rows.weight[index], rows.los[index], speed, row_epoch, m, per_epoch_clock
        )
        length = window_lengths(
            t_epoch,
            information,
            config,
            gyro_bias_sigma,
            speed,
            (equations, 0 if per_epoch_clock else 2),
        )
        lo = np.searchsorted(t_epoch[row_epoch], t_epoch - length, side="right")
        hi = np.searchsorted(t_epoch[row_epoch], t_epoch, side="right")
        if calibration is None:
            calibration = (np.ones(m), np.zeros(m), np.zeros(m))
        per_epoch = (t_epoch, speed, yaw_angle, lever, *(np.asarray(c, float) for c in calibration))
        return cls(
            rows,
            (y_all, row_group),
            index,
            row_epoch,
            (lo, hi),
            per_epoch,
            grade,
            n_sat_epoch,
            length,
            per_epoch_clock,
            max(int(np.max(hi - lo, initial=0)), 1),
            int(np.max(row_group, initial=0)) + 1,
        )

    @property
    def empty(self) -> bool:
        return len(self.index) == 0

    def grade_at(self, k: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(μ, σ) of the grade prior of windows ``k``."""
        return self.grade[0][k], self.grade[1][k]

    def padded(self, k: np.ndarray) -> PaddedWindows:
        """:func:`_padded_rows` of windows ``k``; their rows' epochs (``clock_epoch``) only
        with one clock drift per epoch."""
        padded = _padded_rows(
            self.rows,
            self.per_row,
            self.index,
            self.row_epoch,
            k,
            self.bounds,
            self.per_epoch,
            self.width,
        )
        return padded if self.per_epoch_clock else replace(padded, clock_epoch=None)


def window_lengths(
    t_epoch: np.ndarray,
    information: np.ndarray,
    config: TightHeadingConfig,
    gyro_bias_sigma: np.ndarray | float = 0.0,
    speed: np.ndarray | float = 0.0,
    equations: tuple[np.ndarray, int] | None = None,
) -> np.ndarray:
    """Length (s) of the window ending at each epoch: ``config.window_s``, or longer until the
    rows inside hold the information of a heading σ of ``config.window_target_sigma_rad``, but
    no longer than the gyro allows, ``config.max_window_s`` and ``config.max_window_m`` of
    road; and at least as long as it takes to hold ``config.min_window_equations`` rows beyond
    the clock unknowns.

    ``information`` per epoch is Σ (s·|g_h|/σ_i)² over its rows (s the speed, g_h the line of
    sight's horizontal part, σ_i the row's σ; with one clock drift per epoch, times (n − 1)/n
    for its n rows, :func:`epoch_information`): the Fisher information on θ₀ of rows whose
    lines of sight surround the receiver, an upper bound otherwise. Rows closer in time than
    ``config.noise_correlation_s`` are not independent (a reflection's Doppler error lasts
    about that long), so an epoch counts for min(1, Δt / correlation time) of its rows: the
    same drive at 1, 10 or 20 Hz gets the same windows. At 10–20 Hz under open sky the
    minimum holds; at 1 Hz in a street canyon (weak signals, σ of metres per second) the
    window grows to several seconds.

    The gyro: a bias error of σ_b (``gyro_bias_sigma`` per epoch, rad/s) turns the rows of a
    window of length W by up to σ_b·W, which moves θ₀ by about σ_b·W/2, so W stays within
    2·target/σ_b: before the bias is calibrated that is the minimum (longer windows with the
    prior's bias settled on the mirror root, and trading the bias against noise instead
    calibrated a wrong bias: docs/benchmarks.md, "The heading stage's settings"). The road: the
    model holds one grade per window, and a road's grade changes over a few tens of metres
    (longer windows went to the mirror root with the bias calibrated, same section).

    ``equations``: per epoch the rows left by its own clock drift, and how many unknowns the
    window's clock has besides. Whatever the limits above, up to ``config.max_window_s``, a
    window holds ``config.min_window_equations`` of them: two satellites of a 1-Hz receiver
    with one clock drift per epoch give one equation per epoch, and a 2-s window of them cannot
    tell θ₀ from its mirror (a 1-Hz two-satellite canyon from the start had no heading at all
    without this rule, same section)."""
    t_epoch = np.asarray(t_epoch, dtype=float)
    m = len(t_epoch)
    if m == 0:
        return np.zeros(0)
    interval = np.diff(t_epoch, prepend=t_epoch[0] - (np.median(np.diff(t_epoch)) if m > 1 else 1))
    counted = np.asarray(information, dtype=float) * np.minimum(
        1.0, interval / config.noise_correlation_s
    )
    longest_s = max(config.max_window_s, config.window_s)
    with np.errstate(divide="ignore"):
        gyro_limit = 2.0 * config.window_target_sigma_rad / np.asarray(gyro_bias_sigma, float)
        road_limit = config.max_window_m / np.abs(np.asarray(speed, dtype=float))
    longest = np.minimum(np.minimum(longest_s, gyro_limit), np.nan_to_num(road_limit, nan=np.inf))
    needed = _span_holding(t_epoch, interval, counted, config.window_target_sigma_rad**-2.0)
    length = np.maximum(np.minimum(needed, longest), config.window_s)
    if equations is None:
        return length
    per_epoch, clock_unknowns = equations
    observable = _span_holding(
        t_epoch, interval, per_epoch, config.min_window_equations + clock_unknowns
    )
    return np.maximum(length, np.minimum(observable, longest_s))


def _span_holding(t_epoch, interval, amount, target) -> np.ndarray:
    """Per epoch k the shortest window (t_k − W, t_k] whose epochs' ``amount`` sums to
    ``target`` (inf where all the epochs so far hold less): back to the latest epoch s with
    Σ_{s..k} ≥ target, half an epoch interval beyond it."""
    total = np.concatenate([[0.0], np.cumsum(amount)])
    first = np.searchsorted(total, total[1:] - target, side="right") - 1
    s = np.maximum(first, 0)
    return np.where(first >= 0, t_epoch - t_epoch[s] + 0.5 * interval[s], np.inf)


def epoch_information(
    weight: np.ndarray,
    los: np.ndarray,
    speed: np.ndarray,
    epoch: np.ndarray,
    m: int,
    per_epoch_clock: bool,
) -> tuple[np.ndarray, np.ndarray]:
    """Σ (s·|g_h|/σ_i)² of the rows of each of ``m`` epochs (:func:`window_lengths`) and their
    count n; with one clock drift per epoch, times (n − 1)/n and n − 1 (what that unknown
    leaves of them)."""
    information = np.bincount(
        epoch, weight * speed[epoch] ** 2 * np.sum(los[:, :2] ** 2, axis=1), minlength=m
    )[:m]
    n = np.bincount(epoch, minlength=m)[:m].astype(float)
    if not per_epoch_clock:
        return information, n
    left = np.maximum(n - 1.0, 0.0)
    return information * left / np.maximum(n, 1.0), left


def windows_per_chunk(width: int, n_groups: int, config: TightHeadingConfig) -> int:
    """How many windows of ``width`` padded rows and ``n_groups`` satellites fit in
    ``config.chunk_bytes`` (at least one): the peak of :func:`solve_windows` per window is at
    most ROW_FLOATS·width + HYPOTHESIS_FLOATS·n_groups·grid + PROFILE_FLOATS·profile steps
    float64 values (measured with tracemalloc; the benchmark and test check the bound)."""
    steps = round(config.profile_max_rad / config.profile_step_rad) + 1
    floats = ROW_FLOATS * width + HYPOTHESIS_FLOATS * n_groups * config.grid_size
    return max(1, config.chunk_bytes // (8 * (floats + PROFILE_FLOATS * steps)))


def _padded_rows(rows, per_row, index, row_epoch, k, bounds, per_epoch, width):
    """The rows of windows ``k`` padded to ``width`` (the widest window of the series, so that
    a window's arrays, and so its solution, do not depend on the chunk it is solved in):
    :class:`PaddedWindows`."""
    (y_all, row_group), (lo, hi) = per_row, bounds
    t_epoch, speed, yaw_angle, lever, scale, bias, bias_integral = per_epoch
    slot = lo[k][:, None] + np.arange(width)[None, :]
    # a window whose end has no yaw angle has no θ₀ to solve for: no rows
    inside = (slot < hi[k][:, None]) & np.isfinite(yaw_angle[k])[:, None]
    slot = np.where(inside, slot, 0)
    row = index[slot]
    epoch = row_epoch[slot]
    tau = t_epoch[epoch] - t_epoch[k][:, None]
    delta = yaw_angle[epoch] - yaw_angle[k][:, None]
    delta += bias_integral[epoch] - bias_integral[k][:, None] - bias[k][:, None] * tau
    window_speed = speed[epoch] * scale[k][:, None] / scale[epoch]
    along, across = window_speed + lever[epoch, 0], lever[epoch, 1]
    ge, gn = rows.los[row, 0], rows.los[row, 1]
    cos_d, sin_d = np.cos(delta), np.sin(delta)
    # The LOS turned by −δ, so that −G·R(θ₀ + δ)·[along, across] = a·cos θ₀ + b·sin θ₀.
    forward, left = ge * cos_d + gn * sin_d, gn * cos_d - ge * sin_d
    a = -along * forward - across * left
    b = -along * left + across * forward
    w = np.where(inside, rows.weight[row], 0.0)
    y = np.where(w > 0, y_all[row], 0.0)
    a, b, tau = np.where(w > 0, a, 0.0), np.where(w > 0, b, 0.0), np.where(w > 0, tau, 0.0)
    group = np.where(w > 0, row_group[row], 0)
    grade_coefficient = np.where(w > 0, -rows.los[row, 2] * window_speed, 0.0)
    clock_epoch = np.where(w > 0, k[:, None] - epoch, 0)
    return PaddedWindows(y, a, b, tau, w, group, grade_coefficient, clock_epoch)


def antenna_offset_velocity(yaw_rate: np.ndarray, lever_arm_m) -> np.ndarray:
    """Velocity (N, 2) of an antenna at ``lever_arm_m`` = (r_x forward, r_y left, …) relative
    to the vehicle origin, in the vehicle frame: ω × r = (−ω·r_y, ω·r_x) for yaw rates ω
    (rad/s, counter-clockwise; the vehicle stays level, so r_z does not move the antenna)."""
    rx, ry = (float(v) for v in tuple(lever_arm_m)[:2])
    omega = np.asarray(yaw_rate, dtype=float)
    return np.stack([-omega * ry, omega * rx], axis=-1)


def _unavailable(t_epoch, n_sat_epoch=None) -> TightHeadingResult:
    """Every epoch unavailable (no epochs, or no Doppler row with sensor data at all), with the
    satellites observed at each epoch when known."""
    m = len(t_epoch)
    nan, flags, counts = np.full(m, np.nan), np.zeros(m, dtype=bool), np.zeros(m, dtype=int)
    observed = counts if n_sat_epoch is None else np.asarray(n_sat_epoch, dtype=int)
    return TightHeadingResult(
        t_epoch,
        nan,
        nan,
        counts,
        observed,
        flags,
        flags,
        flags,
        nan,
        nan,
        counts,
        np.zeros(m),
        flags,
        flags,
        flags,
    )


def _concatenate(solutions):
    fields = _WindowSolution.__dataclass_fields__
    return _WindowSolution(
        **{f: np.concatenate([getattr(s, f) for s in solutions]) for f in fields}
    )


def _decide(
    sol, model_variance, t_epoch, speed, gyro, n_sat_epoch, windows, config
) -> TightHeadingResult:
    """Availability, ambiguity resolution and reliability; σ from the noise (s²/info) plus
    ``model_variance``, the calibration and clock errors the model leaves out. ``gyro``: the
    integrated calibrated yaw rate Φ and the gyro-bias σ (rad/s) per epoch; ``windows`` the
    :class:`_WindowRows` (their lengths)."""
    yaw_angle, bias_sigma = gyro
    m = len(t_epoch)
    with np.errstate(divide="ignore", invalid="ignore"):
        noise_variance = np.maximum(sol.variance_factor / sol.info, sol.profile_sigma**2)
        sigma = np.sqrt(noise_variance + model_variance)
        observable = (sol.info > 0) & (sol.info >= config.observability_ratio * sol.info_raw)
        chi2_gap = (sol.cost_second - sol.cost) / _ambiguity_variance(sol, config)
    separated = (
        np.abs(wrap_angle(sol.theta_second - sol.theta)) > config.ambiguity_min_separation_rad
    )
    ambiguous = separated & (chi2_gap < config.ambiguity_chi2)
    candidate = (
        (sol.n_obs >= config.min_obs)
        & (speed >= config.min_speed_mps)
        & observable
        & np.isfinite(sol.theta)
        & (sigma <= config.max_sigma_rad)
        & (sol.fallback | ~sol.inconsistent)
    )
    yaw = np.where(candidate & ~ambiguous, sol.theta, np.nan)
    available = candidate & ~ambiguous
    last = -1
    for k in range(m):
        recent = last >= 0 and t_epoch[k] - t_epoch[last] <= config.prior_max_age_s
        if candidate[k] and separated[k] and recent:
            # the gyro-propagated previous heading is a pseudo-observation of θ₀ with the
            # variance σ_last² + σ_k²: the root of least data + prior cost (χ² units) is kept
            prior = yaw[last] + yaw_angle[k] - yaw_angle[last]
            options = np.array([sol.theta[k], sol.theta_second[k]])
            prior_cost = wrap_angle(options - prior) ** 2 / (sigma[last] ** 2 + sigma[k] ** 2)
            yaw[k] = options[np.argmin(np.array([0.0, chi2_gap[k]]) + prior_cost)]
            available[k] = True
        if available[k]:
            last = k
    verifiable = available & (sol.min_redundancy >= config.testable_redundancy) & ~sol.inconsistent
    reliable = _independent_agreement(
        _reliability(yaw, sigma, available, yaw_angle, t_epoch, config),
        verifiable,
        HeadingSeries(yaw, sigma, available, t_epoch),
        (yaw_angle, bias_sigma),
        windows.length,
        config,
    )
    return TightHeadingResult(
        t=t_epoch,
        yaw=np.where(available, wrap_angle(yaw), np.nan),
        sigma=np.where(available, sigma, np.nan),
        n_obs=sol.n_obs.astype(int),
        n_sat_epoch=n_sat_epoch.astype(int),
        available=available,
        reliable=reliable,
        ambiguous=ambiguous & candidate,
        clock_drift=np.where(available, sol.rho0, np.nan),
        clock_drift_rate=np.where(available, sol.alpha, np.nan),
        n_rejected=sol.n_rejected.astype(int),
        verifiable=verifiable,
        inconsistent=sol.inconsistent & (sol.n_obs >= config.min_obs),
        fallback=available & sol.fallback,
        window_s=windows.length,
    )


def _reliability(yaw, sigma, available, yaw_angle, t_epoch, config):
    """Gyro-consistency with the earlier headings ([TK18] sec. 3.5): of the last
    ``reliability_epochs`` epochs (at least ``reliability_min_epochs`` available, all agreeing),
    or, with ``reliability_epochs`` None, of the last ``reliability_span_s`` seconds.

    Each earlier heading propagated by the gyro agrees with the current one when within
    max(gate, n_sigma · √(σ_k² + σ_j²)): a fixed gate for precise headings, the combined
    uncertainty for imprecise ones (so that a wrong solution, not mere noise, is rejected).
    The heading is consistent when the earlier available ones reach back at least
    ``reliability_min_span_s`` and at least ``reliability_agreement`` of them agree (a
    consensus: one earlier window caught by a reflection does not veto the rest). Counted in
    seconds, the same drive at 1 Hz and 20 Hz is judged over the same stretch of road.
    """
    m = len(yaw)
    count = np.zeros(m, dtype=int)
    agreeing = np.zeros(m, dtype=int)
    reach = np.zeros(m)
    by_epochs = config.reliability_epochs is not None
    span = np.inf if by_epochs else config.reliability_span_s
    last_lag = config.reliability_epochs - 1 if by_epochs else m
    lag = 1
    while lag < min(m, last_lag + 1) and np.any(t_epoch[lag:] - t_epoch[:-lag] <= span):
        inside = t_epoch[lag:] - t_epoch[:-lag] <= span
        both = available[lag:] & available[:-lag] & inside
        predicted = yaw[:-lag] + yaw_angle[lag:] - yaw_angle[:-lag]
        error = np.abs(wrap_angle(yaw[lag:] - predicted))
        allowed = np.maximum(
            config.reliability_gate_rad,
            config.reliability_n_sigma * np.hypot(sigma[lag:], sigma[:-lag]),
        )
        count[lag:] += both
        agreeing[lag:] += both & (error <= allowed)
        reach[lag:] = np.where(both, t_epoch[lag:] - t_epoch[:-lag], reach[lag:])
        lag += 1
    if by_epochs:
        return available & (count >= config.reliability_min_epochs) & (agreeing == count)
    consensus = agreeing >= config.reliability_agreement * np.maximum(count, 1)
    return available & (reach >= config.reliability_min_span_s) & consensus


@dataclass(frozen=True)
class HeadingSeries:
    """The window headings per epoch: yaw θ (rad), its σ (rad), whether it is available, and
    the epoch times (s)."""

    yaw: np.ndarray
    sigma: np.ndarray
    available: np.ndarray
    t_epoch: np.ndarray


def _independent_agreement(consistent, verifiable, headings: HeadingSeries, gyro, window_s, config):
    """Reliability: the epochs of ``consistent`` (the consecutive-epoch rule,
    :func:`_reliability`) whose heading also agrees with an informative heading from a window
    that shares no row with theirs, or whose own window is ``verifiable``.

    Headings of consecutive epochs come from windows that overlap by all but one epoch, so
    their agreement ([TK18] sec. 3.5) cannot reveal a fault that lasts as long as the window,
    such as reflected satellites that snooping mistook for the consistent majority (they stay
    biased for seconds). The reference j is the last reliable heading at least one window
    earlier (t_j ≤ t_k − W), or, when that is older than ``prior_max_age_s`` (or there is none),
    the last available one (so that a wrong reliable heading cannot lock the right ones out).
    Propagated by the gyro it must agree with θ_k within max(gate, n_sigma·√(σ_k² + σ_j² +
    (σ_b·(t_k − t_j))²)), σ_b the calibrated gyro bias's standard deviation, which the
    propagation inherits. A reference is informative when √(σ_j² + (σ_b·|t_k − t_j|)²) ≤
    ``reference_max_sigma_rad``. Where there is none (the first windows of a drive) or only a
    vaguer one (e.g. a one-satellite window's), the epoch is reliable when its own window is
    verifiable or, looking ahead, when it agrees with the first available heading at least one
    window later (t_j ≥ t_k + W, within ``prior_max_age_s``) and that one is informative: a
    window with one reflected satellite among too few to test it fits that satellite exactly,
    and only another window can reveal it.
    """
    yaw, available, t_epoch = headings.yaw, headings.available, headings.t_epoch
    reliable = np.zeros(len(yaw), dtype=bool)
    later = _next_available(available, t_epoch, window_s)
    available_epochs = np.flatnonzero(available)
    reliable_epochs: list[int] = []
    reliable_times: list[float] = []
    for k in np.flatnonzero(consistent):
        bound = t_epoch[k] - window_s[k]
        before = np.searchsorted(t_epoch[available_epochs], bound, side="right")
        last_available = available_epochs[before - 1] if before else -1
        n = bisect_right(reliable_times, bound)
        last_reliable = reliable_epochs[n - 1] if n else -1
        fresh = last_reliable >= 0 and t_epoch[k] - t_epoch[last_reliable] <= config.prior_max_age_s
        j = last_reliable if fresh else last_available
        agrees = _agrees(k, j, headings, gyro, config)
        if agrees is None:
            j = later[k]
            ahead = j >= 0 and t_epoch[j] - t_epoch[k] <= config.prior_max_age_s
            agrees = _agrees(k, j, headings, gyro, config) if ahead else None
            agrees = bool(verifiable[k] or agrees)
        reliable[k] = agrees
        if agrees:
            reliable_epochs.append(k)
            reliable_times.append(t_epoch[k])
    return reliable


def _next_available(available, t_epoch, window_s):
    """Per epoch k, the first available epoch j with t_j ≥ t_k + ``window_s`` (the window
    ending at j then shares no row with k's; per epoch or a scalar; −1 if none)."""
    candidates = np.flatnonzero(available)
    if not candidates.size:
        return np.full(len(t_epoch), -1)
    first = np.searchsorted(t_epoch, t_epoch + window_s, side="left")
    position = np.minimum(np.searchsorted(candidates, first), candidates.size - 1)
    return np.where(candidates[position] >= first, candidates[position], -1)


def _agrees(k, j, headings: HeadingSeries, gyro, config):
    """Whether θ_k agrees with the reference θ_j propagated by the gyro (None when there is no
    reference or it is not informative; :func:`_independent_agreement`)."""
    if j < 0:
        return None
    yaw, sigma, t_epoch = headings.yaw, headings.sigma, headings.t_epoch
    yaw_angle, bias_sigma = gyro
    reference_variance = sigma[j] ** 2 + (bias_sigma[k] * (t_epoch[k] - t_epoch[j])) ** 2
    if not reference_variance <= config.reference_max_sigma_rad**2:
        return None
    predicted = yaw[j] + yaw_angle[k] - yaw_angle[j]
    allowed = max(
        config.reliability_gate_rad,
        config.reliability_n_sigma * np.sqrt(sigma[k] ** 2 + reference_variance),
    )
    return bool(abs(wrap_angle(yaw[k] - predicted)) <= allowed)
