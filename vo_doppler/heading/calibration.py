"""Wheel-speed scale ([TK18] sec. 3.3) and gyro yaw-rate bias (sec. 3.4) calibrated by Doppler.

Models (yaw counter-clockwise from east, yaw rate counter-clockwise positive):

* wheel scale k:  v_doppler(t) = k · v_wheel(t) + noise, so the calibrated speed is k · v_wheel;
* gyro bias b:    ω_measured = ω_true + b, hence with Φ(t) = ∫ ω_measured dt
  ψ_doppler(t) − Φ(t) = ψ₀ − b · (t − t_ref) + noise, and the calibrated rate is ω_measured − b.

Doppler samples pass an outlier gate on their short-term variation first (:func:`variation_gate`):
the change of the Doppler value between neighbouring samples must agree with the change the
vehicle sensor saw, to within a rate limit; a sample is dropped when it disagrees with every
neighbour. Course samples also need a minimum speed. Both fits are robust regressions over
stored recent data, refreshed as samples arrive (:class:`WheelScaleCalibrator`,
:class:`GyroBiasCalibrator`): Huber M-estimates by iteratively reweighted least squares
(:func:`huber_line`; Huber, "Robust estimation of a location parameter", Ann. Math. Statist.
1964), because a conventional Doppler velocity from reflected signals in a street canyon can
be tens of degrees off for seconds, coherently, which the variation gate lets through and
which drags a least-squares slope far off (on a simulated canyon drive with reflections: a gyro
bias of −1.47 °/s for +0.30, against +0.29 °/s robust). Kalman filters with a random-walk
state are the alternative (:class:`WheelScaleKalman`, :class:`GyroBiasKalman`). Each returns
the estimate and its standard deviation.

Prior: an uncalibrated wheel scale is one and an uncalibrated gyro bias zero, with the spreads
:data:`PRIOR_WHEEL_SCALE_SIGMA` and :data:`PRIOR_GYRO_BIAS_SIGMA`. The least-squares path
combines its estimates with this prior by inverse variance (``heading.pipeline``); the Kalman
filters start from it, which in the linear-Gaussian case (no random walk, measurement noise
equal to the least-squares residual spread) gives the same estimate and standard deviation.
Before any informative sample a Kalman filter therefore reports the prior.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np

from vo_doppler.geo import wrap_angle
from vo_doppler.robust import huber_variance, huber_weight, irls, nmad

PRIOR_WHEEL_SCALE = 1.0
PRIOR_WHEEL_SCALE_SIGMA = 0.03
"""Spread of an uncalibrated wheel scale about one (tyre radius, load, wear)."""
PRIOR_GYRO_BIAS = 0.0
PRIOR_GYRO_BIAS_SIGMA = float(np.radians(0.5))
"""Spread of an uncalibrated gyro yaw-rate bias about zero (rad/s)."""


@dataclass(frozen=True)
class GateConfig:
    """Outlier gate and data requirements of the calibration."""

    max_speed_jump_mps: float = 0.5
    max_speed_drift_mps2: float = 0.5
    max_yaw_jump_rad: float = np.radians(2.0)
    max_yaw_drift_rad_s: float = np.radians(1.0)
    min_speed_mps: float = 1.0
    stationary_speed_mps: float = 0.1
    window_s: float = 60.0
    min_samples: int = 10
    min_bias_span_s: float = 3.0
    """The gyro bias is a slope, so it needs samples spanning at least this long (s). Reflections
    come in episodes of about half a second (docs/design.md (I1)); over a span not much longer,
    one episode tilts the whole slope while the residuals' scatter, from a dozen samples, does
    not show it (a simulated drive's first estimate, from a braking corner's samples:
    docs/benchmarks.md, "The gyro bias needs samples over 3 s"). Least squares tilts the slope
    by 6·δ·e·(T − e)/T³ for courses δ off over the first e of T seconds: half a second weighs a
    fifth as much over 3 s as over 1 s."""
    huber_k: float = 1.345
    """k of the Huber fits (:func:`huber_line`), in robust standard deviations of the
    residuals (1.345: 95 % efficiency on Gaussian noise; inf: least squares)."""


@dataclass(frozen=True)
class CalibrationEstimate:
    """An estimated quantity with its standard deviation; NaN when not estimable."""

    value: float
    sigma: float
    n_used: int
    n_rejected: int

    @property
    def valid(self) -> bool:
        return bool(np.isfinite(self.value))


UNAVAILABLE = CalibrationEstimate(np.nan, np.nan, 0, 0)


def variation_gate(
    t: np.ndarray,
    discrepancy: np.ndarray,
    max_jump: float,
    max_drift: float,
    usable: np.ndarray,
) -> np.ndarray:
    """Mask of samples whose short-term variation is acceptable.

    ``discrepancy`` is the Doppler value minus the sensor's prediction; between two neighbouring
    usable samples ``dt`` apart its change must stay within ``max_jump + max_drift · dt``.
    A sample is kept when at least one of its neighbour links passes (a spike drops only itself).
    """
    t = np.asarray(t, dtype=float)
    keep = np.asarray(usable, dtype=bool).copy()
    index = np.flatnonzero(keep)
    if len(index) < 2:
        return np.zeros_like(keep)
    link_ok = np.abs(np.diff(discrepancy[index])) <= max_jump + max_drift * np.diff(t[index])
    ok_left = np.concatenate([[False], link_ok])
    ok_right = np.concatenate([link_ok, [False]])
    keep[index] = ok_left | ok_right
    return keep


MIN_ROBUST_SAMPLES = 30
"""Fewer samples are fitted by least squares: the MAD of n residuals has a relative standard
error of about 1.17/√n (over 20 % below 30 samples), too loose for weights and σ; the prior
of the uncalibrated sensor guards that regime instead."""


@dataclass(frozen=True)
class RobustLine:
    """Slope of a robust line fit, its standard deviation and the final weights."""

    slope: float
    sigma: float
    weights: np.ndarray


def _centred(
    values: np.ndarray, weights: np.ndarray, members: list[np.ndarray] | None
) -> np.ndarray:
    """``values`` less their weighted mean within each group (``members``: the indices of
    each; None: no intercept)."""
    if members is None:
        return values
    out = values.copy()
    for index in members:
        out[index] -= weights[index] @ values[index] / weights[index].sum()
    return out


def _line(x, y, weights, members) -> tuple[np.ndarray, np.ndarray, float | None]:
    """x and y centred per group (:func:`_centred`) and the weighted least-squares slope of
    one on the other (None when the weighted x has no spread)."""
    xc, yc = _centred(x, weights, members), _centred(y, weights, members)
    sxx = float((weights * xc) @ xc)
    return xc, yc, (float((weights * xc) @ yc) / sxx if sxx > 0 else None)


def huber_line(
    x: np.ndarray,
    y: np.ndarray,
    groups: np.ndarray | None = None,
    k: float = GateConfig.huber_k,
    iterations: int = 50,
) -> RobustLine:
    """Huber M-estimate of the slope β of y = β·x (``groups`` None) or of y = c_g + β·x with
    an intercept per group, by iteratively reweighted least squares
    (:func:`vo_doppler.robust.irls`): with residuals r_i and their scale s = NMAD(r), Huber's
    weights (R2) w_i = min(1, k·s/|r_i|), until the weights settle
    (least squares below :data:`MIN_ROBUST_SAMPLES`). σ_β is (R5) (Huber, "Robust
    Statistics", 1981, sec. 7.6) over Σx̃², x̃ centred per group; with k = ∞ it is the
    least-squares σ."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.size < MIN_ROBUST_SAMPLES:
        k = np.inf
    members = None if groups is None else [np.flatnonzero(groups == g) for g in np.unique(groups)]
    params = 1 + (0 if members is None else len(members))

    def fit(weights):
        xc, yc, slope = _line(x, y, weights, members)
        return None if slope is None else yc - slope * xc

    def weigh(residual, _pass):
        scale = nmad(residual)
        return None if scale <= 0 else huber_weight(residual, k, scale, floor=1e-300)

    weights = irls(fit, weigh, np.ones_like(x), iterations, tolerance=1e-6)
    xc, yc, slope = _line(x, y, weights, members)
    if slope is None:
        return RobustLine(np.nan, np.nan, weights)
    residual = yc - slope * xc
    n = x.size
    if n <= params:
        return RobustLine(slope, np.nan, weights)
    scale = nmad(residual)
    if not np.isfinite(k) or scale <= 0:
        sigma = np.sqrt(float(residual @ residual) / (n - params) / float(xc @ xc))
        return RobustLine(slope, float(sigma), weights)
    variance = huber_variance(residual, scale, k, params)
    return RobustLine(slope, float(np.sqrt(variance / float(xc @ xc))), weights)


def estimate_wheel_scale(
    t: np.ndarray,
    doppler_speed: np.ndarray,
    wheel_speed: np.ndarray,
    doppler_valid: np.ndarray | None = None,
    config: GateConfig = GateConfig(),
) -> CalibrationEstimate:
    """Wheel scale k ([TK18] sec. 3.3, a Huber fit: :func:`huber_line`) with its standard
    deviation."""
    t = np.asarray(t, dtype=float)
    vd, vw = np.asarray(doppler_speed, dtype=float), np.asarray(wheel_speed, dtype=float)
    usable = np.isfinite(vd) & np.isfinite(vw) & (vw >= config.min_speed_mps)
    if doppler_valid is not None:
        usable &= np.asarray(doppler_valid, dtype=bool)
    keep = variation_gate(
        t, vd - vw, config.max_speed_jump_mps, config.max_speed_drift_mps2, usable
    )
    n, rejected = int(keep.sum()), int(usable.sum() - keep.sum())
    if n < max(config.min_samples, 2):
        return CalibrationEstimate(np.nan, np.nan, n, rejected)
    fit = huber_line(vw[keep], vd[keep], k=config.huber_k)
    return CalibrationEstimate(fit.slope, fit.sigma, n, rejected)


def estimate_gyro_bias(
    t: np.ndarray,
    doppler_yaw: np.ndarray,
    integrated_yaw: np.ndarray,
    doppler_speed: np.ndarray,
    doppler_valid: np.ndarray | None = None,
    config: GateConfig = GateConfig(),
) -> CalibrationEstimate:
    """Yaw-rate bias b ([TK18] sec. 3.4, rad/s, a Huber fit: :func:`huber_line`) with its
    standard deviation.

    ``doppler_yaw`` is the Doppler course as yaw (rad, counter-clockwise from east),
    ``integrated_yaw`` is Φ(t), the integral of the measured (counter-clockwise) yaw rate.
    Moving samples share one intercept ψ₀. Extension beyond the seed: while the Doppler speed
    is below ``config.stationary_speed_mps`` the vehicle cannot turn, so −Φ(t) = c − b·t with an
    intercept of its own for each stationary run (no course is needed there).
    """
    t = np.asarray(t, dtype=float)
    speed = np.asarray(doppler_speed, dtype=float)
    phi = np.asarray(integrated_yaw, dtype=float)
    valid = np.ones(len(t), dtype=bool) if doppler_valid is None else np.asarray(doppler_valid)
    z = np.asarray(doppler_yaw, dtype=float) - phi
    moving = valid & np.isfinite(z) & np.isfinite(speed) & (speed >= config.min_speed_mps)
    stationary = valid & np.isfinite(phi) & (speed <= config.stationary_speed_mps)
    group = np.where(moving, 0, -1)
    run_starts = stationary & ~np.concatenate([[False], stationary[:-1]])
    group = np.where(stationary, np.cumsum(run_starts), group)
    value = np.full_like(z, np.nan)
    if moving.any():
        value[moving] = np.unwrap(wrap_angle(z[moving]))
    value[stationary] = -phi[stationary]
    keep = np.zeros(len(t), dtype=bool)
    for g in np.unique(group[group >= 0]):
        members = group == g
        keep |= variation_gate(
            t, value, config.max_yaw_jump_rad, config.max_yaw_drift_rad_s, members
        )
    usable = group >= 0
    n, rejected = int(keep.sum()), int(usable.sum() - keep.sum())
    if n < max(config.min_samples, 3) or np.ptp(t[keep]) < config.min_bias_span_s:
        return CalibrationEstimate(np.nan, np.nan, n, rejected)
    groups = group[keep]
    fit = huber_line(t[keep] - t[keep].mean(), value[keep], groups, config.huber_k)
    if not np.isfinite(fit.sigma):
        return CalibrationEstimate(np.nan, np.nan, n, rejected)
    return CalibrationEstimate(-fit.slope, fit.sigma, n, rejected)


class _RecentSamples:
    """Samples of the last ``window_s`` seconds, as columns."""

    def __init__(self, window_s: float, n_columns: int):
        self.window_s = window_s
        self.rows: deque[tuple[float, ...]] = deque()
        self.n_columns = n_columns

    def add(self, *row: float) -> np.ndarray:
        self.rows.append(tuple(float(v) for v in row))
        while self.rows and self.rows[-1][0] - self.rows[0][0] > self.window_s:
            self.rows.popleft()
        return np.array(self.rows, dtype=float).reshape(-1, self.n_columns).T


class _StreamingFit:
    """Stored recent samples plus the latest estimate, refreshed on every valid sample.

    Samples without a valid Doppler solution are not stored, so an outage keeps the data (and
    the estimate) from before it instead of ageing them out.
    """

    n_columns = 0

    def __init__(self, config: GateConfig = GateConfig()):
        self.config = config
        self._samples = _RecentSamples(config.window_s, self.n_columns)
        self.estimate = UNAVAILABLE


class WheelScaleCalibrator(_StreamingFit):
    """Streaming [TK18] sec. 3.3: least squares over the stored recent samples, per sample."""

    n_columns = 3

    def add(
        self, t: float, doppler_speed: float, wheel_speed: float, doppler_valid: bool = True
    ) -> CalibrationEstimate:
        if doppler_valid:
            tt, vd, vw = self._samples.add(t, doppler_speed, wheel_speed)
            self.estimate = estimate_wheel_scale(tt, vd, vw, None, self.config)
        return self.estimate


class GyroBiasCalibrator(_StreamingFit):
    """Streaming [TK18] sec. 3.4: least squares over the stored recent samples, per sample."""

    n_columns = 4

    def add(
        self,
        t: float,
        doppler_yaw: float,
        integrated_yaw: float,
        doppler_speed: float,
        doppler_valid: bool = True,
    ) -> CalibrationEstimate:
        if doppler_valid:
            tt, yaw, phi, speed = self._samples.add(t, doppler_yaw, integrated_yaw, doppler_speed)
            self.estimate = estimate_gyro_bias(tt, yaw, phi, speed, None, self.config)
        return self.estimate


class _StreamGate:
    """Streaming form of the variation gate: compare with the last accepted sample.

    After ``reset_after`` consecutive rejections the next sample is accepted, so that a
    lasting change (not a spike) is followed instead of rejected forever.
    """

    def __init__(self, max_jump: float, max_drift: float, reset_after: int = 3):
        self.max_jump = max_jump
        self.max_drift = max_drift
        self.reset_after = reset_after
        self._last: tuple[float, float] | None = None
        self._rejections = 0

    def passes(self, t: float, discrepancy: float) -> bool:
        if self._last is not None and self._rejections < self.reset_after:
            allowed = self.max_jump + self.max_drift * (t - self._last[0])
            if abs(discrepancy - self._last[1]) > allowed:
                self._rejections += 1
                return False
        self._last = (t, discrepancy)
        self._rejections = 0
        return True


class _KalmanFit:
    """A filterpy filter whose state ``index`` is the calibrated quantity, started at its prior."""

    index = 0

    def __init__(self, dim_x: int, config: GateConfig):
        # filterpy (with scipy.stats, about 0.4 s of imports) loads only for this alternative,
        # not with the module: the default calibration is the least-squares one.
        from filterpy.kalman import KalmanFilter

        self.filter = KalmanFilter(dim_x=dim_x, dim_z=1)
        self.config = config
        self._t: float | None = None
        self.n_used = 0
        self.n_rejected = 0

    @property
    def estimate(self) -> CalibrationEstimate:
        """The filtered value and its standard deviation: the prior until data inform it."""
        i = self.index
        value, sigma = float(self.filter.x[i, 0]), float(np.sqrt(self.filter.P[i, i]))
        return CalibrationEstimate(value, sigma, self.n_used, self.n_rejected)


class WheelScaleKalman(_KalmanFit):
    """Kalman variant of [TK18] sec. 3.3: state k, a random walk of ``q_per_sqrt_s`` per √s,
    starting
    at the prior ``prior`` ± ``prior_sigma``."""

    def __init__(
        self,
        speed_sigma_mps: float = 0.1,
        q_per_sqrt_s: float = 1e-4,
        prior: float = PRIOR_WHEEL_SCALE,
        prior_sigma: float = PRIOR_WHEEL_SCALE_SIGMA,
        config: GateConfig = GateConfig(),
    ):
        super().__init__(1, config)
        self.filter.x = np.array([[prior]])
        self.filter.P = np.array([[prior_sigma**2]])
        self.filter.R = np.array([[speed_sigma_mps**2]])
        self.q_per_sqrt_s = q_per_sqrt_s
        self._gate = _StreamGate(config.max_speed_jump_mps, config.max_speed_drift_mps2)

    def add(
        self, t: float, doppler_speed: float, wheel_speed: float, doppler_valid: bool = True
    ) -> CalibrationEstimate:
        usable = (
            doppler_valid
            and np.isfinite(doppler_speed)
            and np.isfinite(wheel_speed)
            and wheel_speed >= self.config.min_speed_mps
        )
        if not usable:
            return self.estimate
        if not self._gate.passes(t, doppler_speed - float(self.filter.x[0, 0]) * wheel_speed):
            self.n_rejected += 1
            return self.estimate
        if self._t is not None:
            dt = max(t - self._t, 0.0)
            self.filter.predict(Q=np.array([[self.q_per_sqrt_s**2 * dt]]))
        self._t = t
        self.filter.update(np.array([[doppler_speed]]), H=np.array([[wheel_speed]]))
        self.n_used += 1
        return self.estimate


class GyroBiasKalman(_KalmanFit):
    """Kalman variant of [TK18] sec. 3.4: state [e, b] with e = ψ_true − Φ, ė = −b, b a random walk.

    b starts at the prior ``prior`` ± ``prior_sigma``; e has no prior (a flat one), so the
    first accepted measurement sets it with the measurement variance and leaves b at its prior.
    The measurement is ψ_doppler − Φ = e + noise; it is unwrapped next to the predicted e.
    The variation gate applies to the change of the innovation between accepted samples.
    """

    index = 1

    @property
    def estimate(self) -> CalibrationEstimate:
        """The filtered bias and its standard deviation, NaN until the accepted samples span
        ``config.min_bias_span_s``: a bias is a slope, and over a shorter span one reflection
        episode tilts it (:class:`GateConfig`), which the filter's σ does not show either."""
        span = 0.0 if self._first_t is None else self._t - self._first_t
        if span < self.config.min_bias_span_s:
            return CalibrationEstimate(np.nan, np.nan, self.n_used, self.n_rejected)
        return super().estimate

    def __init__(
        self,
        yaw_sigma_rad: float = np.radians(0.5),
        bias_walk_rad_s_per_sqrt_s: float = np.radians(0.001),
        prior: float = PRIOR_GYRO_BIAS,
        prior_sigma: float = PRIOR_GYRO_BIAS_SIGMA,
        config: GateConfig = GateConfig(),
    ):
        super().__init__(2, config)
        self.filter.H = np.array([[1.0, 0.0]])
        self.filter.R = np.array([[yaw_sigma_rad**2]])
        self.filter.x = np.array([[0.0], [prior]])
        self.filter.P = np.diag([np.inf, prior_sigma**2])
        self.bias_walk = bias_walk_rad_s_per_sqrt_s
        self._gate = _StreamGate(config.max_yaw_jump_rad, config.max_yaw_drift_rad_s)
        self._first_t: float | None = None

    def add(
        self,
        t: float,
        doppler_yaw: float,
        integrated_yaw: float,
        doppler_speed: float,
        doppler_valid: bool = True,
    ) -> CalibrationEstimate:
        z = doppler_yaw - integrated_yaw
        usable = doppler_valid and np.isfinite(z) and doppler_speed >= self.config.min_speed_mps
        if not usable:
            return self.estimate
        if self._t is None:  # the flat prior on e updated by z: e = z ± R, b untouched
            self.filter.x[0, 0] = float(wrap_angle(z))
            self.filter.P[0, 0] = self.filter.R[0, 0]
            self._gate.passes(t, 0.0)
            self._t = self._first_t = t
            self.n_used = 1
            return self.estimate
        dt = max(t - self._t, 0.0)
        self.filter.predict(
            F=np.array([[1.0, -dt], [0.0, 1.0]]), Q=np.diag([0.0, self.bias_walk**2 * dt])
        )
        self._t = t
        predicted = float(self.filter.x[0, 0])
        z_near = predicted + float(wrap_angle(z - predicted))
        if not self._gate.passes(t, z_near - predicted):
            self.n_rejected += 1
            return self.estimate
        self.filter.update(np.array([[z_near]]))
        self.n_used += 1
        return self.estimate
