"""Integrity of the conventional Doppler velocity against the vehicle's own sensors
(docs/design.md, "Conventional velocity integrity against the car's sensors").

Several reflected satellites at once can be fitted by a wrong velocity that the GNSS stage's
chi-square test cannot see (five or six satellites leave it one or two degrees of freedom).
A car knows its turning and its speed without GNSS: over a few seconds the conventional course
minus the integrated calibrated yaw rate is a constant plus a slope, what is left of the gyro
bias (prior N(0, σ_b²) from the calibration), and the conventional speed minus the calibrated
wheel speed a constant plus a slope (the wheel scale and the wheel's lag in accelerations). At
each epoch k both differences of the other valid epochs within ``half_window_s`` (±5 s) are
fitted by such a line and the epoch's own difference is tested against it, test (I1) of
:mod:`vo_doppler.gnss.windowed_line`; the course and speed σ are reported times their σ factor
λ (an upper bound: the gyro's and the wheel's own noise are in it).

The line is the gyro-propagated course of the neighbours, several times more precise than one
epoch's course in a street canyon (Hong Kong, 1 Hz: σ 0.6° against 2.2° at the median, its
residual within 0.8° of the true course error at the median), so it bounds each epoch's course
error whatever σ the velocity states (I1a): a course is valid only where that bound is within
``COURSE_ALERT_LIMIT``. An epoch the sensors cover whose window holds epochs enough but too few
valid ones (its neighbours failed or could not be tested) cannot be confirmed and is not valid;
where the recording's rate leaves too few epochs in the window (below 0.5 Hz), or the sensors do
not cover it, it keeps the GNSS stage's verdict, with a warning
(:func:`integrity_rate_warning`). The GNSS stage's own continuity test
(:mod:`vo_doppler.gnss.continuity`) is the same test over ±0.5 s without the car's sensors:
it sees faults of one epoch, this one faults of a few seconds.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from vo_doppler.gnss.doppler_velocity import GRADE_SIGMA, VERTICAL_FLOOR_MPS, VERTICAL_GATE
from vo_doppler.gnss.windowed_line import (
    ConsistencyConfig,
    ConsistencyTest,
    consistency_test,
    epochs_in_window,
)
from vo_doppler.model.gnss_solutions import VelocitySolution
from vo_doppler.model.heading import HeadingTable

SENSOR_TEST = ConsistencyConfig()
"""±5 s, α = 0.001 per test, at least 5 neighbours."""
WHEEL_AT_REST_MPS = 0.05
"""A wheel speed below this is a car at rest: wheel encoders read zero when the wheels stand."""
AT_REST_MAX_MPS = 0.2
"""With the wheels at rest a conventional speed above this is a fault, whatever its σ: the
receivers standing in the Hong Kong street canyon show 0.02–0.07 m/s at p95 (u-blox F9P, M8T),
while fixes a few reflected satellites pulled reached 0.75 m/s and passed the speed test's 3σ
(zero-velocity update from the wheels)."""
COURSE_ALERT_LIMIT = np.radians(5.0)
"""A conventional course is valid only where the gyro bounds its error within this at
``PROTECTION_QUANTILE``: the accuracy asked of a heading from the Doppler velocity (issue 29:
p95 within 5°). A wider limit validates more of a street canyon's epochs but lets their p95
beyond that accuracy (docs/design.md (I1a); the Hong Kong canyon drive at three limits in
docs/benchmarks.md, "The heading stage's settings")."""
PROTECTION_QUANTILE = 1.96
"""The bound holds the course error at 95 % (two-sided) where the reference's σ is honest."""
REST_FALSE_ALARM = 0.01
"""Share of a standing receiver's healthy velocities beyond :func:`rest_speed_bound`."""
MIN_REST_EPOCHS = 10
"""Fewer epochs at rest measure no rest noise: the bound is then ``AT_REST_MAX_MPS``."""


@dataclass(frozen=True)
class ConventionalIntegrity:
    """The course and speed tests of the conventional velocity (None where its σ is unknown),
    the epochs still valid after them, and the epochs the sensors covered that the tests could
    not judge (too few valid neighbours within the window: not valid)."""

    course: ConsistencyTest | None
    speed: ConsistencyTest | None
    valid: np.ndarray
    untested: np.ndarray
    tested: np.ndarray | None = None
    """The epochs the tests took: valid so far and within the car's vertical bound."""


@dataclass(frozen=True)
class VelocityIntegrity:
    """The conventional velocity's own verdict (:func:`velocity_integrity`): ``valid`` per
    epoch and the rest bound it used (m/s)."""

    valid: np.ndarray
    rest_bound_mps: float


def car_vertical_bound(velocity_enu: np.ndarray) -> np.ndarray:
    """Whether each ENU velocity (…, 3) climbs or falls as a car can, whatever the solution's
    own σ (design (I1b)): |v_u| ≤ 3·√((g·s)² + f²), s the horizontal speed, the grade g and
    floor f of the GNSS stage's test (2a) without its share of the solution's own vertical
    variance, which widens that test exactly where the solution is worst. False where unknown."""
    v = np.asarray(velocity_enu, dtype=float)
    speed = np.hypot(v[..., 0], v[..., 1])
    bound = VERTICAL_GATE * np.sqrt((GRADE_SIGMA * speed) ** 2 + VERTICAL_FLOOR_MPS**2)
    with np.errstate(invalid="ignore"):
        return np.abs(v[..., 2]) <= bound


def rest_speed_bound(speed: np.ndarray, at_rest: np.ndarray) -> float:
    """The horizontal speed (m/s) a standing receiver's healthy velocities stay below but for
    a share ``REST_FALSE_ALARM``, measured on the epochs ``at_rest`` (design (I1c)): with
    equal independent noise σ on east and north the speed is Rayleigh distributed,
    σ = median / √(2 ln 2) (robust while fewer than half of the epochs are faulty), and the
    bound is σ·√(−2 ln α), at most ``AT_REST_MAX_MPS``; ``AT_REST_MAX_MPS`` itself with fewer
    than ``MIN_REST_EPOCHS`` epochs."""
    speed = np.asarray(speed, dtype=float)[np.asarray(at_rest, dtype=bool)]
    speed = speed[np.isfinite(speed)]
    if speed.size < MIN_REST_EPOCHS:
        return AT_REST_MAX_MPS
    sigma = float(np.median(speed)) / np.sqrt(2.0 * np.log(2.0))
    return min(sigma * np.sqrt(-2.0 * np.log(REST_FALSE_ALARM)), AT_REST_MAX_MPS)


def course_protection(course: ConsistencyTest, quantile: float = PROTECTION_QUANTILE) -> np.ndarray:
    """The bound the gyro puts on each tested epoch's course error (rad, NaN where untested),
    design (I1a): |e_k| + Q·λ·σ_c₀,k, the residual against the gyro-propagated course of the
    neighbours plus that reference's own σ at quantile Q, scaled by the test's σ factor λ."""
    return np.abs(course.residual) + quantile * course.sigma_factor * course.line_sigma


@dataclass(frozen=True)
class ConventionalEpochs:
    """The conventional velocity as test (I1) takes it, one value per GNSS epoch: ``valid`` so
    far, the yaw (rad) and horizontal speed (m/s, NaN where not valid) with their σ (None: that
    test is not made), and the car's vertical bound (:func:`car_vertical_bound`; None: none)."""

    t: np.ndarray
    valid: np.ndarray
    yaw: np.ndarray
    yaw_sigma: np.ndarray | None
    speed: np.ndarray
    speed_sigma: np.ndarray | None
    vertical_bound: np.ndarray | None = None


@dataclass(frozen=True)
class CarReference:
    """What the car's own sensors say at the same epochs: the integrated calibrated yaw rate
    (rad), the calibrated wheel speed (m/s; NaN where the signals do not cover the epoch) and
    the σ of what is left of the gyro bias (rad/s)."""

    yaw_angle: np.ndarray
    wheel_speed: np.ndarray
    gyro_bias_sigma: np.ndarray


def conventional_integrity(
    epochs: ConventionalEpochs,
    car: CarReference,
    config: ConsistencyConfig = SENSOR_TEST,
    course_alert_limit: float = COURSE_ALERT_LIMIT,
) -> ConventionalIntegrity:
    """Test (I1) of the conventional yaw against the integrated calibrated yaw rate and of its
    horizontal speed against the calibrated wheel speed, at the epochs valid so far (module
    docstring). The course line's slope is what is left of the gyro bias: its prior is
    N(0, ``car.gyro_bias_sigma``²). A course whose error the gyro cannot bound within
    ``course_alert_limit`` (:func:`course_protection`) is not valid, nor is an epoch the sensors
    cover that the tests could not judge. Where the wheels stand (``WHEEL_AT_REST_MPS``) a
    speed above ``AT_REST_MAX_MPS`` fails outright. Epochs beyond the vertical bound are
    neither tested nor valid."""
    t, wheel = epochs.t, np.asarray(car.wheel_speed, dtype=float)
    valid = np.asarray(epochs.valid, dtype=bool)
    if epochs.vertical_bound is not None and config.enabled:
        valid = valid & np.asarray(epochs.vertical_bound, dtype=bool)
    none = np.zeros(valid.shape, dtype=bool)
    if not config.enabled:
        return ConventionalIntegrity(None, None, valid.copy(), none)
    course = speed_test = None
    failed = none.copy()
    unjudged = none.copy()
    if epochs.yaw_sigma is not None:
        course = consistency_test(
            t,
            np.asarray(epochs.yaw) - np.asarray(car.yaw_angle),
            epochs.yaw_sigma,
            valid,
            config,
            angular=True,
            slope_sigma=car.gyro_bias_sigma,
        )
        with np.errstate(invalid="ignore"):
            failed |= course.failed | (course_protection(course) > course_alert_limit)
        unjudged |= course.unjudged
    if epochs.speed_sigma is not None:
        difference = np.asarray(epochs.speed) - wheel
        speed_test = consistency_test(t, difference, epochs.speed_sigma, valid, config)
        failed |= speed_test.failed
        unjudged |= speed_test.unjudged
    untested = valid & unjudged & np.isfinite(car.yaw_angle) & np.isfinite(wheel)
    at_rest = np.abs(np.nan_to_num(wheel, nan=np.inf)) < WHEEL_AT_REST_MPS
    failed |= at_rest & (np.nan_to_num(epochs.speed, nan=0.0) > AT_REST_MAX_MPS)
    return ConventionalIntegrity(course, speed_test, valid & ~failed & ~untested, untested, valid)


def velocity_integrity(
    integrity: ConventionalIntegrity,
    gnss_valid: np.ndarray,
    speed: np.ndarray,
    wheel_speed: np.ndarray,
    course_alert_limit: float = COURSE_ALERT_LIMIT,
) -> VelocityIntegrity:
    """Whether each conventional velocity (its horizontal ``speed``, m/s) is valid, design
    (I1c); ``gnss_valid``: the GNSS stage's verdict within the car's vertical bound. Where the
    calibrated ``wheel_speed`` stands (``WHEEL_AT_REST_MPS``): a velocity ``gnss_valid`` whose
    speed is within :func:`rest_speed_bound`. Where the car moves: an epoch the tests of
    ``integrity`` judged that passed the speed and course tests (I1) and whose cross-track
    error the gyro bounds, s·PL_k ≤ max(s·AL, v_rest) (I1a with the rest noise as its floor: a
    slow car's course may be as uncertain as the noise of a standing receiver makes it).
    Where the sensors do not cover the epoch: ``gnss_valid``."""
    gnss_valid = np.asarray(gnss_valid, dtype=bool)
    speed = np.asarray(speed, dtype=float)
    wheel = np.asarray(wheel_speed, dtype=float)
    at_rest = np.abs(np.nan_to_num(wheel, nan=np.inf)) < WHEEL_AT_REST_MPS
    bound = rest_speed_bound(speed, gnss_valid & at_rest)
    with np.errstate(invalid="ignore"):
        resting = at_rest & (speed <= bound)
    moving = integrity.valid.copy()
    if integrity.tested is not None and integrity.course is not None:
        with np.errstate(invalid="ignore", divide="ignore"):
            limit = np.maximum(course_alert_limit, bound / speed)
            failed = integrity.course.failed | (course_protection(integrity.course) > limit)
        if integrity.speed is not None:
            failed = failed | integrity.speed.failed
        moving = integrity.tested & ~failed & ~integrity.untested
    valid = gnss_valid & np.where(at_rest, resting, moving | ~np.isfinite(wheel))
    return VelocityIntegrity(valid, bound)


def car_checked_velocity(solution: VelocitySolution, table: HeadingTable) -> VelocitySolution:
    """``solution`` (the conventional velocity ``table`` was made from) with ``valid`` the
    car's verdict, ``table.conv_velocity_valid`` (design (I1c)): the ``vel.csv`` of ``run`` and
    of ``heading --vel``. Unchanged where the table has no such verdict."""
    if table.conv_velocity_valid is None:
        return solution
    if len(solution.t) != len(table.t):
        raise ValueError(
            f"the heading table has {len(table.t)} epochs, the velocity {len(solution.t)}: "
            "not the velocity it was made from"
        )
    return replace(solution, valid=np.asarray(table.conv_velocity_valid, dtype=bool))


def integrity_rate_warning(t: np.ndarray, config: ConsistencyConfig = SENSOR_TEST) -> str | None:
    """A warning when the recording's rate leaves most epochs too few others within the test's
    window to be judged (they keep the GNSS stage's verdict); None when it can judge, or is
    off."""
    t = np.asarray(t, dtype=float)
    if not config.enabled or t.size < 2:
        return None
    needed = max(config.min_neighbours, config.degree + 1)
    share = float(np.mean(epochs_in_window(t, config.half_window_s) < needed))
    if share < 0.5:
        return None
    return (
        f"conventional velocity against the gyro and wheels (I1): {share:.0%} of the epochs "
        f"have fewer than {needed} others within ±{config.half_window_s:g} s (they are "
        f"{float(np.median(np.diff(t))):.2g} s apart) and keep the GNSS stage's verdict"
    )
