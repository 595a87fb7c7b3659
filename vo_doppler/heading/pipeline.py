"""Per-epoch heading from Doppler rows and vehicle sensors: calibration ([TK18] sec. 3.3–3.4)
feeding the tightly coupled heading (sec. 3.5), with the conventional heading (sec. 3.2) alongside.

Calibration is causal from its first estimate on: at each GNSS epoch the wheel scale and gyro
bias are refreshed from the conventional Doppler speed and course of the epochs so far (stored
recent data), and the estimates current at an epoch calibrate the sensors from that epoch to the
next; the epochs before the first estimate (for the gyro bias: the first with σ ≤
``backfill_bias_sigma_rad_s``) take the median of the drive's estimates (:func:`backfill_start`).
Only conventional velocities precise enough (``calibration_max_velocity_sigma_mps``)
calibrate: with four satellites and a poor geometry a
"valid" velocity can be metres per second off. The least-squares estimates are combined with a
prior (scale 1, bias 0, with the spread of uncalibrated sensors), so that a fit over a few
samples cannot swing the bias to tens of degrees per second; while none can be made after the
first, the prior (or the last estimate) holds. The standard deviations of the calibration go to
the tightly coupled solver, which propagates them into each heading's standard deviation.

Where the conventional calibration has no gyro bias estimate even so (a street canyon from the
start), the tightly coupled headings of a first pass give it (:func:`tight_gyro_bias`,
non-causal: the whole drive's headings) and the tight heading is solved again with it; the
wheel scale stays at the prior there (the tight model takes the speed as given).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from enum import StrEnum

import numpy as np

from vo_doppler.checks import sample_noise
from vo_doppler.choices import check_fields
from vo_doppler.heading.calibration import (
    PRIOR_GYRO_BIAS_SIGMA,
    PRIOR_WHEEL_SCALE_SIGMA,
    CalibrationEstimate,
    GateConfig,
    GyroBiasCalibrator,
    GyroBiasKalman,
    WheelScaleCalibrator,
    WheelScaleKalman,
    estimate_gyro_bias,
)
from vo_doppler.heading.conventional import (
    ConventionalVelocity,
    heading_from_velocity,
    vehicle_heading_from_antenna,
)
from vo_doppler.heading.grade import GradePriorConfig, accelerometer_grade, grade_prior
from vo_doppler.heading.integrity import (
    CarReference,
    ConsistencyConfig,
    ConventionalEpochs,
    ConventionalIntegrity,
    car_vertical_bound,
    conventional_integrity,
    velocity_integrity,
)
from vo_doppler.heading.smoother import (
    GyroAngle,
    HeadingSmootherConfig,
    SmoothedHeading,
    WindowHeadings,
    angle_random_walk,
    smooth_heading,
)
from vo_doppler.heading.tight_heading import (
    TightHeadingConfig,
    TightHeadingResult,
    antenna_offset_velocity,
    speed_scale_ratio,
    tight_heading_series,
)
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.heading import CalibrationSummary, HeadingTable
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import integral_at, sample
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.robust import nmad


class CalibrationMethod(StrEnum):
    """How the wheel scale and gyro bias are calibrated from the conventional Doppler velocity
    ([TK18] sec. 3.3–3.4): least squares over a sliding window, a Kalman filter, or not."""

    LS = "ls"
    KALMAN = "kalman"
    NONE = "none"


AUTO_ROBUST_BELOW_RATE_HZ = 10.0
""":meth:`HeadingPipelineConfig.auto`: GNSS rates below this take the robust settings."""
AMBIGUOUS_WARNING_SHARE = 0.1
"""Share of the moving epochs left without a tight heading by ambiguous windows from which
:func:`heading_pipeline` warns."""


class HeadingMethod(StrEnum):
    """``--heading-method``: ``auto``: :meth:`HeadingPipelineConfig.auto`, robust below 10 Hz
    and snooping from 10 Hz; ``snooping``: windows of 2 s, reflections detected and named by
    data snooping (tuned on 10–20 Hz recordings); ``robust``: :meth:`HeadingPipelineConfig.
    robust`, for any rate and deep street canyons (1-Hz receivers)."""

    AUTO = "auto"
    SNOOPING = "snooping"
    ROBUST = "robust"


@dataclass(frozen=True)
class HeadingPipelineConfig:
    """``calibration``: least squares, Kalman or none; fixed values override the estimates."""

    calibration: CalibrationMethod = CalibrationMethod.LS
    gate: GateConfig = field(default_factory=GateConfig)
    tight: TightHeadingConfig = field(default_factory=TightHeadingConfig)
    grade: GradePriorConfig = field(default_factory=GradePriorConfig)
    """The road grade prior from a forward accelerometer, where the recording has one."""
    integrity: ConsistencyConfig = field(default_factory=ConsistencyConfig)
    """The conventional velocity's test against the calibrated gyro and wheel speed."""
    conventional_min_speed_mps: float = 0.5
    calibration_max_velocity_sigma_mps: float = 2.0
    """Conventional velocities with a larger standard deviation (√trace of the 3-D velocity
    covariance) do not calibrate."""
    calibration_max_speed_mismatch_mps: float = 0.5
    calibration_max_speed_mismatch_ratio: float = 0.1
    """A conventional speed further than max(these, as m/s and as a fraction) from the raw wheel
    speed does not calibrate: wheel scale errors are a few per cent, a reflected (NLOS) Doppler
    is often far more."""
    prior_gyro_bias_sigma_rad_s: float = PRIOR_GYRO_BIAS_SIGMA
    """Spread of an uncalibrated gyro bias about zero (rad/s)."""
    prior_wheel_scale_sigma: float = PRIOR_WHEEL_SCALE_SIGMA
    """Spread of an uncalibrated wheel scale about one."""
    backfill_bias_sigma_rad_s: float = float(np.radians(0.05))
    """The gyro bias's first estimates with a larger σ (rad/s) give way to the drive's median
    (:func:`backfill_start`): 0.05 °/s held for 10 s turns the dead reckoning by 0.5°, for good
    (docs/design.md, "Sensor calibration"; measured in docs/benchmarks.md, "Error per 100 m on
    the simulator's drives")."""
    tight_calibration: bool = True
    """Where the conventional calibration has no gyro bias estimate, take it from the tightly
    coupled headings of a first pass and solve them again (:func:`tight_gyro_bias`)."""
    tight_calibration_max_sigma_rad: float = float(np.radians(5.0))
    """Tightly coupled headings with a larger σ (rad) do not calibrate. Where nothing has
    calibrated, a two-satellite heading's σ is 3–4°, most of it the prior's 3 % wheel-scale σ:
    an offset that changes only with the satellite geometry, which hardly tilts the bias's
    slope over the drive, so the gate lies above that σ; below it nothing calibrates in a canyon
    from the start, and an uncalibrated bias can tip two-satellite windows to their mirror root
    (docs/design.md, "Sensor calibration"; measured in docs/benchmarks.md, "A street canyon
    from the start")."""
    tight_scale_max_sigma: float = 0.005
    """Where nothing else calibrated the wheel scale, the Doppler rows given the tight headings
    do (:func:`tight_wheel_scale`) only when they pin it to this σ (relative), a sixth of the
    prior's 3 %: a scale error δ shifts a two-satellite heading by about δ rad, and that shift
    is shared by every window, which the correction cannot average away. At an even speed the
    rows hardly tell the scale from the grade, and the scale stays at the prior (docs/design.md,
    "Sensor calibration"; measured in docs/benchmarks.md, "A street canyon from the start")."""
    fixed_gyro_bias_rad_s: float | None = None
    fixed_wheel_scale: float | None = None
    smoother: HeadingSmootherConfig = field(default_factory=HeadingSmootherConfig)
    """The tight headings combined through the gyro (:mod:`vo_doppler.heading.smoother`)."""
    robust_below_rate_hz: float | None = None
    """Recordings whose GNSS epochs come at a lower rate take the settings of :meth:`robust`
    (:meth:`for_rate`); None: these settings at any rate."""
    method: HeadingMethod = HeadingMethod.SNOOPING
    """The name of these settings, kept in the heading table."""

    def __post_init__(self) -> None:
        check_fields(self, calibration=CalibrationMethod, method=HeadingMethod)

    @classmethod
    def robust(cls) -> HeadingPipelineConfig:
        """``--heading-method robust``: :meth:`TightHeadingConfig.robust` and calibration fits
        over the last 600 s, since a canyon's Doppler speeds scatter by metres per second
        (docs/design.md, "The robust heading method for any rate")."""
        return cls(
            tight=TightHeadingConfig.robust(),
            gate=GateConfig(window_s=600.0),
            smoother=HeadingSmootherConfig(enabled=True),
            method=HeadingMethod.ROBUST,
        )

    @classmethod
    def auto(cls) -> HeadingPipelineConfig:
        """``--heading-method auto`` (the default): :meth:`robust` for recordings below 10 Hz,
        the snooping settings (tuned at 10–20 Hz) at 10 Hz and above. At 1 and 5 Hz the robust
        method with its smoother holds the heading where snooping's 2-s windows hold a few
        epochs; at 10–20 Hz snooping keeps the bundled sample's error per 100 m lower
        (measured in docs/benchmarks.md, "The heading smoother")."""
        return cls(robust_below_rate_hz=AUTO_ROBUST_BELOW_RATE_HZ)

    def for_rate(self, t_epoch: np.ndarray) -> HeadingPipelineConfig:
        """These settings for a recording with GNSS epochs at ``t_epoch``: the robust method's
        tight, gate and smoother settings when its median epoch interval is longer than
        1/``robust_below_rate_hz`` (the rest of the settings kept)."""
        if self.robust_below_rate_hz is None or len(t_epoch) < 2:
            return self
        interval = float(np.median(np.diff(np.asarray(t_epoch, dtype=float))))
        if interval * self.robust_below_rate_hz <= 1.0 + 1e-9:
            return replace(self, robust_below_rate_hz=None)
        robust = type(self).robust()
        return replace(
            self,
            tight=robust.tight,
            gate=robust.gate,
            smoother=robust.smoother,
            method=robust.method,
            robust_below_rate_hz=None,
        )


def _grade_prior(t_epoch, velocity, valid, speed, forward_acceleration, vertical_sigma, config):
    """(μ, σ) of the tight heading's grade per epoch: the accelerometer's where calibrated,
    else N(0, ``config.tight.grade_sigma``); and where it is the accelerometer's. ``speed``:
    the wheel speed times the recording's final wheel scale (dv/dt of an uncalibrated wheel
    speed moves the grade by the scale error times the acceleration: docs/benchmarks.md, "Real
    recording: comma2k19")."""
    m = len(t_epoch)
    level = np.zeros(m), np.full(m, config.tight.grade_sigma)
    if forward_acceleration is None or not len(forward_acceleration.t):
        return level, np.zeros(m, dtype=bool)
    raw = accelerometer_grade(t_epoch, config.tight.window_s, forward_acceleration, speed)
    mean, sigma = grade_prior(raw, velocity, valid, config.grade, vertical_sigma)
    known = np.isfinite(mean) & np.isfinite(sigma)
    return (np.where(known, mean, level[0]), np.where(known, sigma, level[1])), known


def _sigma_where(sigma: np.ndarray | None, valid: np.ndarray) -> np.ndarray | None:
    """σ at the ``valid`` epochs, NaN elsewhere (None where no σ is known)."""
    return None if sigma is None else np.where(valid, np.asarray(sigma, dtype=float), np.nan)


def _scaled_sigma(sigma, test, valid):
    """:func:`_sigma_where` times the integrity test's σ factor (design (I1))."""
    shown = _sigma_where(sigma, valid)
    return shown if shown is None or test is None else test.sigma_factor * shown


def _calibrators(config: HeadingPipelineConfig):
    if config.calibration is CalibrationMethod.LS:
        return GyroBiasCalibrator(config.gate), WheelScaleCalibrator(config.gate)
    if config.calibration is CalibrationMethod.KALMAN:
        return (
            GyroBiasKalman(config=config.gate, prior_sigma=config.prior_gyro_bias_sigma_rad_s),
            WheelScaleKalman(config=config.gate, prior_sigma=config.prior_wheel_scale_sigma),
        )
    return None, None


@dataclass
class CalibrationSeries:
    """Gyro bias (rad/s) and wheel scale current at each epoch, with standard deviations."""

    bias: np.ndarray
    scale: np.ndarray
    bias_sigma: np.ndarray
    scale_sigma: np.ndarray
    bias_estimated: np.ndarray
    """Epochs whose bias is estimated from data (or fixed), not the prior alone."""
    scale_estimated: np.ndarray
    """Epochs whose wheel scale is estimated from data (or fixed), not the prior alone."""


def _with_prior(estimate, prior: float, prior_sigma: float) -> tuple[float, float]:
    """Inverse-variance combination of an estimate with the prior (the prior alone if none)."""
    if not estimate.valid:
        return prior, prior_sigma
    var_e, var_p = estimate.sigma**2, prior_sigma**2
    if var_e + var_p == 0:
        return estimate.value, 0.0
    value = (estimate.value * var_p + prior * var_e) / (var_e + var_p)
    return value, float(np.sqrt(var_e * var_p / (var_e + var_p)))


def causal_calibration(
    t_epoch: np.ndarray,
    doppler_speed: np.ndarray,
    doppler_yaw: np.ndarray,
    doppler_valid: np.ndarray,
    wheel_speed: np.ndarray,
    raw_yaw_angle: np.ndarray,
    config: HeadingPipelineConfig = HeadingPipelineConfig(),
) -> CalibrationSeries:
    """Gyro bias and wheel scale current at each epoch, refreshed epoch by epoch, with their
    standard deviations (least squares: combined with the prior; fixed values: zero)."""
    m = len(t_epoch)
    out = CalibrationSeries(
        np.zeros(m),
        np.ones(m),
        np.zeros(m),
        np.zeros(m),
        np.zeros(m, dtype=bool),
        np.zeros(m, dtype=bool),
    )
    bias_cal, scale_cal = _calibrators(config)
    current_bias = (0.0, config.prior_gyro_bias_sigma_rad_s)
    current_scale = (1.0, config.prior_wheel_scale_sigma)
    for k in range(m):
        if bias_cal is not None:
            b = bias_cal.add(
                t_epoch[k], doppler_yaw[k], raw_yaw_angle[k], doppler_speed[k], doppler_valid[k]
            )
            s = scale_cal.add(t_epoch[k], doppler_speed[k], wheel_speed[k], doppler_valid[k])
            out.bias_estimated[k] = b.valid and b.n_used > 0
            out.scale_estimated[k] = s.valid and s.n_used > 0
            if config.calibration == "ls":
                current_bias = _with_prior(b, 0.0, config.prior_gyro_bias_sigma_rad_s)
                current_scale = _with_prior(s, 1.0, config.prior_wheel_scale_sigma)
            else:
                current_bias = (b.value, b.sigma) if b.valid else current_bias
                current_scale = (s.value, s.sigma) if s.valid else current_scale
        out.bias[k], out.bias_sigma[k] = current_bias
        out.scale[k], out.scale_sigma[k] = current_scale
    if config.fixed_gyro_bias_rad_s is not None:
        out.bias[:], out.bias_sigma[:] = config.fixed_gyro_bias_rad_s, 0.0
        out.bias_estimated[:] = True
    if config.fixed_wheel_scale is not None:
        out.scale[:], out.scale_sigma[:] = config.fixed_wheel_scale, 0.0
        out.scale_estimated[:] = True
    return out


def backfill_start(
    cal: CalibrationSeries, max_bias_sigma: float = np.inf, covered: np.ndarray | None = None
) -> CalibrationSeries:
    """The epochs before the first estimate of the gyro bias (of the wheel scale) take the
    median of the drive's estimates instead of the prior's value, and keep the prior's σ (in
    place; returned). So do the gyro bias's first estimates while their σ exceeds
    ``max_bias_sigma`` (keeping their own σ), when a later one is within it.

    A recording is processed after the fact, and the median of all the drive's estimates is
    steadier than the first (a few samples, pulled to the prior) or the last (the far end of a
    random walk); but nothing measured the sensor in those first seconds, when a gyro may
    still be warming up, so their σ stays the spread of an uncalibrated sensor. (With the last
    estimate's σ the tight heading's consistency tests rejected most rows of the sample's
    first seconds and lost headings.) Not causal there; causal from the first estimate on (from
    the first precise one for the bias). On the simulator's drives the first estimate comes
    seconds after the start (docs/benchmarks.md, "The calibration's first seconds").

    Why the bias's imprecise first estimates go too: a bias error b_e held for T seconds turns
    the dead reckoning by b_e·T for the rest of the drive, which no later estimate undoes. A
    first fit over 3–5 s of a dozen samples has σ 0.1–0.4 °/s
    (:attr:`HeadingPipelineConfig.backfill_bias_sigma_rad_s`)."""
    covered = np.ones(len(cal.bias), dtype=bool) if covered is None else covered
    bias_first = _first_precise(cal.bias_estimated, cal.bias_sigma, max_bias_sigma)
    scale_first = _first_precise(cal.scale_estimated, cal.scale_sigma, np.inf)
    for value, estimated, first in (
        (cal.bias, cal.bias_estimated, bias_first),
        (cal.scale, cal.scale_estimated, scale_first),
    ):
        if first is not None:
            drive = estimated[first:] & covered[first:]
            value[:first] = np.median(value[first:][drive if drive.any() else estimated[first:]])
            estimated[:first] = True
    return cal


def calibration_summary(cal: CalibrationSeries, covered: np.ndarray) -> CalibrationSummary | None:
    """:class:`~vo_doppler.model.heading.CalibrationSummary` over the ``covered`` epochs (None
    when the vehicle signals cover none)."""
    if not covered.any():
        return None
    last = int(np.flatnonzero(covered)[-1])

    def stats(value, sigma):
        v = value[covered]
        median = float(np.median(v))
        spread = nmad(v)
        return median, spread, float(np.median(sigma[covered])), float(value[last])

    return CalibrationSummary(
        *stats(cal.bias, cal.bias_sigma), *stats(cal.scale, cal.scale_sigma), int(covered.sum())
    )


def _first_precise(estimated: np.ndarray, sigma: np.ndarray, max_sigma: float) -> int | None:
    """The first estimated epoch with σ ≤ ``max_sigma``, else the first estimated one (None
    when there is none)."""
    if not estimated.any():
        return None
    precise = estimated & (sigma <= max_sigma)
    return int(np.argmax(precise if precise.any() else estimated))


def tight_gyro_bias(
    t_epoch: np.ndarray,
    tight_yaw: np.ndarray,
    tight_sigma: np.ndarray,
    tight_reliable: np.ndarray,
    raw_yaw_angle: np.ndarray,
    wheel_speed: np.ndarray,
    config: HeadingPipelineConfig = HeadingPipelineConfig(),
) -> tuple[float, float] | None:
    """Gyro bias (rad/s) and its σ from tightly coupled headings, combined with the prior; None
    where none can be estimated. This project's addition, for drives without conventional
    velocities to calibrate (a street canyon from the start).

    [TK18] sec. 3.4's model with the tight heading ψ_TC in place of the Doppler course,

        ψ_TC(t) − Φ(t) = ψ₀ − b·(t − t_ref),

    fitted by :func:`~vo_doppler.heading.calibration.estimate_gyro_bias` (its gate and Huber
    line) over the whole drive (post-processing, not causal), on the reliable headings with
    σ ≤ ``config.tight_calibration_max_sigma_rad``. Each window sees the gyro over only
    ``config.tight.window_s``, so a bias error b_e tilts its heading by a fraction of
    b_e·window_s while the slope is fitted over the drive's tens of seconds: the bias the first
    pass used hardly enters. The headings of overlapping windows share their
    Doppler rows, so the fit's σ (which takes the samples as independent) is multiplied by
    √(epochs per window)."""
    t_epoch = np.asarray(t_epoch, dtype=float)
    sigma = np.nan_to_num(np.asarray(tight_sigma, dtype=float), nan=np.inf)
    informative = np.asarray(tight_reliable, dtype=bool) & (
        sigma <= config.tight_calibration_max_sigma_rad
    )
    estimate = estimate_gyro_bias(
        t_epoch, tight_yaw, raw_yaw_angle, wheel_speed, informative, config.gate
    )
    if not estimate.valid or len(t_epoch) < 2:
        return None
    per_window = max(config.tight.window_s / float(np.median(np.diff(t_epoch))), 1.0)
    inflated = replace(estimate, sigma=estimate.sigma * float(np.sqrt(per_window)))
    return _with_prior(inflated, 0.0, config.prior_gyro_bias_sigma_rad_s)


def _tight_calibration_needed(cal: CalibrationSeries, config: HeadingPipelineConfig) -> bool:
    """A second pass calibrated by :func:`tight_gyro_bias` is needed: the calibration is on
    and some epochs have no estimated gyro bias."""
    return (
        config.tight_calibration
        and config.calibration != "none"
        and not bool(np.all(cal.bias_estimated))
    )


def tight_wheel_scale(
    solved: _Pass, scale: float, config: HeadingPipelineConfig
) -> tuple[float, float] | None:
    """Wheel scale and its σ from the Doppler rows of a pass solved with the wheel ``scale``,
    given its headings (:func:`~vo_doppler.heading.tight_heading.speed_scale_ratio`),
    combined with the prior; None where the rows do not pin it to
    ``config.tight_scale_max_sigma``. This project's addition, for drives without conventional
    velocities (a street canyon from the start). The windows used are reliable, with
    σ ≤ ``config.tight_calibration_max_sigma_rad`` and no rejected row.

    The headings of a pass carry its scale's error (a two-satellite heading turns by about the
    relative speed error, in radians), which pulls the fit towards that scale, from the
    prior's 1 part of the way to the true one. Fitting again from there comes closer, but the
    sample's canyon from the start then keeps a third fewer reliable headings (the same with
    the true scale given as fixed). The lost ones are right; the reliability test shuts them
    out: the drive's first windows (a fraction of a second of rows, two satellites, one
    reflected) give a heading far off at a small σ that counts as verifiable, hence reliable,
    and the smaller gyro-bias σ of that calibration keeps it an informative reference for the
    seconds that follow (``TightHeadingConfig.prior_max_age_s``). One fit it is, until such a
    first window is caught (docs/benchmarks.md, "The heading stage's settings")."""
    result = solved.result
    informative = (
        result.reliable
        & (np.nan_to_num(result.sigma, nan=np.inf) <= config.tight_calibration_max_sigma_rad)
        & (result.n_rejected == 0)
    )
    ratio = speed_scale_ratio(**solved.tight_inputs, yaw=result.yaw, informative=informative)
    if ratio is None or not ratio[1] <= config.tight_scale_max_sigma:
        return None
    estimate = CalibrationEstimate(scale * ratio[0], scale * ratio[1], int(informative.sum()), 0)
    return _with_prior(estimate, 1.0, config.prior_wheel_scale_sigma)


def _tight_scale_needed(cal: CalibrationSeries, config: HeadingPipelineConfig) -> bool:
    """The wheel scale is to come from the tight heading: the calibration is on and nothing
    else estimated it anywhere in the drive."""
    return (
        config.tight_calibration
        and config.calibration != "none"
        and not bool(np.any(cal.scale_estimated))
    )


@dataclass(frozen=True)
class _Pass:
    """One solution of the heading stage under a given calibration."""

    conv_yaw: np.ndarray
    integrity: ConventionalIntegrity
    grade: tuple[np.ndarray, np.ndarray]
    grade_from_accelerometer: np.ndarray
    result: TightHeadingResult
    tight_inputs: dict


def _smoothed(
    solved: _Pass,
    yaw_rate: SensorSeries,
    cal: CalibrationSeries,
    covered: np.ndarray,
    config: HeadingPipelineConfig,
) -> SmoothedHeading:
    """The pass's window headings smoothed through its calibrated yaw angle, with the gyro's
    angle random walk from the yaw rate's sample noise unless configured."""
    smoother = config.smoother
    walk = smoother.angle_random_walk_rad_per_sqrt_s
    if walk is None:
        interval = float(np.median(np.diff(yaw_rate.t))) if len(yaw_rate.t) > 1 else 0.0
        walk = angle_random_walk(sample_noise(np.asarray(yaw_rate.value)), interval)
    result = solved.result
    bias_sigma = cal.bias_sigma[covered]
    windows = WindowHeadings(
        result.t, np.where(result.available, result.yaw, np.nan), result.sigma, result.window_s
    )
    gyro = GyroAngle(
        solved.tight_inputs["yaw_angle"],
        float(np.median(bias_sigma)) if bias_sigma.size else config.prior_gyro_bias_sigma_rad_s,
        walk,
    )
    return smooth_heading(windows, gyro, smoother, config.tight.max_sigma_rad)


@dataclass(frozen=True)
class _Epochs:
    """The heading stage's inputs at the GNSS epochs, the same for every pass
    (:func:`_epochs`): the conventional velocity as the antenna's and as the vehicle's heading
    and speed, the raw vehicle signals there, and which epochs calibrate."""

    t: np.ndarray
    rows: DopplerRows
    conventional: ConventionalVelocity
    vehicle: VehicleSignals
    lever_arm_m: Sequence[float]
    """The GNSS antenna (x forward, y left[, z up], m) from the vehicle origin."""
    velocity: np.ndarray
    """The conventional ENU velocity (m/s), (E, 3)."""
    valid: np.ndarray
    """The GNSS stage's verdict."""
    conv_ok: np.ndarray
    """Valid, with a heading (moving at ``conventional_min_speed_mps`` or more)."""
    antenna: tuple[np.ndarray, np.ndarray]
    """Heading (rad) and horizontal speed (m/s) of the antenna's conventional velocity at the
    valid and untestable epochs (NaN elsewhere)."""
    conv_yaw: np.ndarray
    """The vehicle's heading (rad): the antenna's less the angle of ω × r for the raw yaw
    rate (:func:`~vo_doppler.heading.conventional.vehicle_heading_from_antenna`)."""
    conv_speed: np.ndarray
    """The vehicle's horizontal speed (m/s), likewise."""
    wheel: np.ndarray
    """The raw wheel speed (m/s)."""
    raw_rate: np.ndarray
    """The raw yaw rate (rad/s)."""
    raw_angle: np.ndarray
    """Its integral Φ (rad)."""
    covered: np.ndarray
    """Epochs that the wheel speed and the yaw rate both cover."""
    car: np.ndarray
    """Velocities within the car's vertical bound (docs/design.md (I1b))."""
    calibrating: np.ndarray
    """Epochs whose conventional velocity may calibrate the sensors (:func:`_calibrating`)."""

    @property
    def lever(self) -> bool:
        """The antenna lies off the vehicle origin horizontally."""
        return any(float(v) != 0.0 for v in tuple(self.lever_arm_m)[:2])


def _epochs(
    t_epoch: np.ndarray,
    rows: DopplerRows,
    conventional: ConventionalVelocity,
    vehicle: VehicleSignals,
    lever_arm_m: Sequence[float],
    config: HeadingPipelineConfig,
) -> _Epochs:
    """The inputs of :func:`heading_pipeline` at its epochs ``t_epoch`` (:class:`_Epochs`)."""
    velocity = np.asarray(conventional.velocity_enu, dtype=float).reshape(-1, 3)
    valid = np.asarray(conventional.valid, dtype=bool)
    candidates = valid.copy()
    if conventional.untestable is not None:
        candidates |= np.asarray(conventional.untestable, dtype=bool)
    antenna_yaw, conv_seen = heading_from_velocity(
        velocity, candidates, config.conventional_min_speed_mps
    )
    # Horizontal speed: the tightly coupled model's velocity is horizontal, and the vertical
    # component of a canyon fix is noisy (large VDOP), which would bias |v| and the scale up.
    antenna_speed = np.where(candidates, np.hypot(velocity[:, 0], velocity[:, 1]), np.nan)
    speed, yaw_rate = vehicle.wheel_speed, vehicle.yaw_rate
    wheel = sample(speed.t, speed.value, t_epoch)
    raw_rate = sample(yaw_rate.t, yaw_rate.value, t_epoch)
    conv_yaw, conv_speed = antenna_yaw, antenna_speed
    if any(float(v) != 0.0 for v in tuple(lever_arm_m)[:2]):
        offset = antenna_offset_velocity(raw_rate, lever_arm_m)
        conv_yaw, conv_speed = vehicle_heading_from_antenna(
            antenna_yaw, antenna_speed, wheel, offset
        )
    raw_angle = integral_at(yaw_rate.t, yaw_rate.value, t_epoch)
    return _Epochs(
        t=t_epoch,
        rows=rows,
        conventional=conventional,
        vehicle=vehicle,
        lever_arm_m=lever_arm_m,
        velocity=velocity,
        valid=valid,
        conv_ok=conv_seen & valid,
        antenna=(antenna_yaw, antenna_speed),
        conv_yaw=conv_yaw,
        conv_speed=conv_speed,
        wheel=wheel,
        raw_rate=raw_rate,
        raw_angle=raw_angle,
        covered=np.isfinite(wheel) & np.isfinite(raw_angle),
        car=car_vertical_bound(velocity),
        calibrating=_calibrating(candidates, conv_speed, wheel, conventional.sigma_mps, config),
    )


def _calibrating(
    candidates: np.ndarray,
    conv_speed: np.ndarray,
    wheel: np.ndarray,
    sigma_mps: np.ndarray | None,
    config: HeadingPipelineConfig,
) -> np.ndarray:
    """The ``candidates`` (valid or untestable) whose velocity may calibrate the sensors: σ
    within ``calibration_max_velocity_sigma_mps`` where known, and a speed near the raw wheel
    speed (``calibration_max_speed_mismatch_mps`` / ``_ratio``)."""
    calibrating = candidates.copy()
    if sigma_mps is not None:
        sigma = np.nan_to_num(np.asarray(sigma_mps, dtype=float), nan=np.inf)
        calibrating &= sigma <= config.calibration_max_velocity_sigma_mps
    tolerance = np.maximum(
        config.calibration_max_speed_mismatch_mps,
        config.calibration_max_speed_mismatch_ratio * np.abs(wheel),
    )
    calibrating &= np.abs(np.nan_to_num(conv_speed - wheel, nan=np.inf)) <= tolerance
    return calibrating


def _conventional_calibration(epochs: _Epochs, config: HeadingPipelineConfig) -> CalibrationSeries:
    """The causal calibration from the conventional velocities (:func:`causal_calibration`)
    with its first epochs backfilled (:func:`backfill_start`). A redundantly tested course
    beyond the car's vertical bound calibrates no gyro bias (design (I1b)); its speed still
    calibrates the wheels, the untestable epochs both."""
    e = epochs
    course = np.where(e.car | ~e.valid, e.conv_yaw, np.nan)
    return backfill_start(
        causal_calibration(e.t, e.conv_speed, course, e.calibrating, e.wheel, e.raw_angle, config),
        config.backfill_bias_sigma_rad_s,
        e.covered,
    )


def _solve(epochs: _Epochs, cal: CalibrationSeries, config: HeadingPipelineConfig) -> _Pass:
    """The integrity test (I1), grade prior and tight heading (3)–(4) under calibration
    ``cal``."""
    e, conventional = epochs, epochs.conventional
    # Φ_cal(t_k) = Φ_raw(t_k) − ∫ b̂ dt, with b̂ of epoch j held until epoch j + 1.
    steps = cal.bias[:-1] * np.diff(e.t)
    bias_integral = np.concatenate([[0.0], np.cumsum(steps)])[: len(e.t)]
    yaw_angle = e.raw_angle - bias_integral
    offset = antenna_offset_velocity(e.raw_rate - cal.bias, e.lever_arm_m)
    conv_yaw = e.conv_yaw
    if e.lever:
        conv_yaw, _ = vehicle_heading_from_antenna(*e.antenna, cal.scale * e.wheel, offset)
    epochs = ConventionalEpochs(
        e.t,
        e.conv_ok,
        conv_yaw,
        conventional.yaw_sigma_rad,
        np.where(e.valid, e.conv_speed, np.nan),
        conventional.speed_sigma_mps,
        e.car,
    )
    car = CarReference(yaw_angle, cal.scale * e.wheel, cal.bias_sigma)
    integrity = conventional_integrity(epochs, car, config.integrity)
    speed = e.vehicle.wheel_speed
    grade, grade_from_accelerometer = _grade_prior(
        e.t,
        e.velocity,
        e.valid,
        SensorSeries(speed.t, speed.value * cal.scale[-1]),
        e.vehicle.forward_acceleration,
        conventional.vertical_sigma_mps,
        config,
    )
    inputs = {
        "rows": e.rows,
        "t_epoch": e.t,
        "speed": cal.scale * e.wheel,
        "yaw_angle": yaw_angle,
        "config": config.tight,
        "lever_velocity": np.nan_to_num(offset),
        "grade_prior": grade,
        "calibration": (cal.scale, cal.bias, bias_integral),
    }
    result = tight_heading_series(
        **inputs,
        speed_scale_sigma=cal.scale_sigma / cal.scale,
        gyro_bias_sigma=cal.bias_sigma,
    )
    return _Pass(conv_yaw, integrity, grade, grade_from_accelerometer, result, inputs)


def _tight_calibrated(
    epochs: _Epochs, cal: CalibrationSeries, solved: _Pass, config: HeadingPipelineConfig
) -> _Pass:
    """``solved`` solved again where the conventional velocities left the gyro bias or the
    wheel scale unestimated and the pass's tight headings give them: the bias
    (:func:`tight_gyro_bias`), then the scale (:func:`tight_wheel_scale`); ``cal`` is updated
    in place."""
    if _tight_calibration_needed(cal, config):
        result = solved.result
        bias = tight_gyro_bias(
            epochs.t,
            result.yaw,
            result.sigma,
            result.reliable,
            epochs.raw_angle,
            epochs.wheel,
            config,
        )
        if bias is not None:
            cal.bias_sigma[~cal.bias_estimated] = bias[1]
            cal.bias[~cal.bias_estimated] = bias[0]
            solved = _solve(epochs, cal, config)
    if _tight_scale_needed(cal, config):
        scale = tight_wheel_scale(solved, float(cal.scale[-1]), config)
        if scale is not None:
            cal.scale[:], cal.scale_sigma[:] = scale
            solved = _solve(epochs, cal, config)
    return solved


def _smoothed_heading(
    epochs: _Epochs, solved: _Pass, cal: CalibrationSeries, config: HeadingPipelineConfig
) -> tuple[SmoothedHeading | None, list[str]]:
    """The pass's windows smoothed through the gyro ((S1)–(S2), :func:`_smoothed`) where the
    smoother is on; None with a warning where the windows disagree with the gyro-propagated
    heading by more than ``max_variance_factor`` times their σ."""
    if not config.smoother.enabled:
        return None, []
    tight = _smoothed(solved, epochs.vehicle.yaw_rate, cal, epochs.covered, config)
    if not tight.variance_factor > config.smoother.max_variance_factor:
        return tight, []
    return None, [
        f"heading smoother: the windows disagree with the gyro-propagated heading by "
        f"{tight.variance_factor:.1f} times their σ (above "
        f"{config.smoother.max_variance_factor:g}): the gyro does not link them (course "
        "and yaw apart?); the windows' own headings are kept"
    ]


def heading_pipeline(
    t_epoch: np.ndarray,
    rows: DopplerRows,
    conventional: ConventionalVelocity,
    vehicle: VehicleSignals,
    config: HeadingPipelineConfig = HeadingPipelineConfig(),
    antenna_lever_arm_m: Sequence[float] = (0.0, 0.0),
) -> HeadingTable:
    """Headings at every epoch (sensor series already on GPS time, yaw rate counter-clockwise):
    the sensors calibrated by the conventional velocities ([TK18] sec. 3.3–3.4), those
    velocities tested against the calibrated gyro and wheel speed (docs/design.md (I1)–(I1c)),
    the tightly coupled heading (sec. 3.5, (3)–(4)), solved again where its own headings
    calibrate the gyro bias or the wheel scale (:func:`_tight_calibrated`), and smoothed
    through the gyro where configured ((S1)–(S2)).

    ``conventional``: the GNSS stage's velocities and what σ it gives
    (:class:`~vo_doppler.heading.conventional.ConventionalVelocity` says what each does). Where
    the heading and speed σ are given, epochs that fail the test (I1) are not valid in the
    table, and the table's conventional heading and speed σ are the given ones times the factor
    by which the test's residuals exceed them.

    ``antenna_lever_arm_m``: the GNSS antenna (x forward, y left[, z up], m) from the vehicle
    origin. In turns the antenna moves at ω × r relative to the vehicle, so the Doppler
    velocity is not the vehicle's: the tightly coupled model adds ω × r (ω the calibrated yaw
    rate at each epoch) and the conventional heading and speed are turned into the vehicle's
    (:func:`~vo_doppler.heading.conventional.vehicle_heading_from_antenna`), with the raw yaw
    rate for the calibration (the bias is not known yet) and the calibrated one in the table.

    ``vehicle.forward_acceleration`` (m/s², specific force along the vehicle's forward axis):
    the road grade prior of the tight heading comes from it and the wheel speed, its offset
    calibrated on the conventional velocities (:mod:`vo_doppler.heading.grade`); without it,
    and before that calibration, the prior is N(0, ``config.tight.grade_sigma``).
    """
    t_epoch = np.asarray(t_epoch, dtype=float)
    config = config.for_rate(t_epoch)
    epochs = _epochs(t_epoch, rows, conventional, vehicle, antenna_lever_arm_m, config)
    cal = _conventional_calibration(epochs, config)
    solved = _tight_calibrated(epochs, cal, _solve(epochs, cal, config), config)
    tight, warnings = _smoothed_heading(epochs, solved, cal, config)
    moving = epochs.wheel >= config.tight.min_speed_mps
    warnings = _ambiguity_warning(solved.result, moving) + warnings
    return _heading_table(epochs, cal, solved, tight, warnings, config)


def _ambiguity_warning(result: TightHeadingResult, moving: np.ndarray) -> list[str]:
    """A warning when ambiguous windows (two headings fitting alike, docs/design.md,
    "Ambiguity") leave at least ``AMBIGUOUS_WARNING_SHARE`` of the ``moving`` epochs without
    a tight heading."""
    unresolved = int(np.count_nonzero(result.ambiguous & ~result.available))
    n_moving = int(np.count_nonzero(moving))
    if unresolved == 0 or unresolved < AMBIGUOUS_WARNING_SHARE * n_moving:
        return []
    return [
        f"tight heading: {unresolved} of {n_moving} moving epochs without one: two headings "
        "fit their window's Doppler rows within the noise (few satellites on a straight "
        "road) and no earlier heading propagated by the gyro chose between them"
    ]


def _heading_table(
    epochs: _Epochs,
    cal: CalibrationSeries,
    solved: _Pass,
    tight: SmoothedHeading | None,
    warnings: list[str],
    config: HeadingPipelineConfig,
) -> HeadingTable:
    """The table of the final pass ``solved`` under calibration ``cal``, its tight headings
    the smoothed ``tight`` where given, else the windows' own."""
    result, integrity, conventional = solved.result, solved.integrity, epochs.conventional
    conv_ok = epochs.conv_ok
    horizontal_speed = np.hypot(epochs.velocity[:, 0], epochs.velocity[:, 1])
    return HeadingTable(
        t=epochs.t,
        yaw_tc=result.yaw if tight is None else tight.yaw,
        sigma_tc=result.sigma if tight is None else tight.sigma,
        tc_reliable=result.reliable if tight is None else tight.reliable,
        n_obs_window=result.n_obs,
        n_sat_epoch=result.n_sat_epoch,
        yaw_conv=np.where(conv_ok, solved.conv_yaw, np.nan),
        conv_valid=integrity.valid,
        gyro_bias=cal.bias,
        wheel_scale=cal.scale,
        rejected_rows=result.n_rejected,
        tc_verifiable=result.verifiable,
        sigma_conv=_scaled_sigma(conventional.yaw_sigma_rad, integrity.course, integrity.valid),
        speed_sigma_conv=_scaled_sigma(
            conventional.speed_sigma_mps, integrity.speed, integrity.valid
        ),
        tc_window_s=config.tight.window_s
        if tight is None
        else 2.0 * config.smoother.consensus_span_s,
        conv_gnss_valid=conv_ok,
        conv_velocity_valid=velocity_integrity(
            integrity, epochs.valid & epochs.car, horizontal_speed, cal.scale * epochs.wheel
        ).valid,
        sigma_conv_gnss=_sigma_where(conventional.yaw_sigma_rad, conv_ok),
        grade_prior_sigma=solved.grade[1],
        grade_from_accelerometer=solved.grade_from_accelerometer,
        calibration=calibration_summary(cal, epochs.covered),
        method=config.method,
        warnings=warnings,
    )
