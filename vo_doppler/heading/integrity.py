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
λ (an upper bound: the gyro's and the wheel's own noise are in it). Epochs with too few
neighbours keep the GNSS stage's verdict. The GNSS stage's own continuity test
(:mod:`vo_doppler.gnss.continuity`) is the same test over ±0.5 s without the car's sensors:
it sees faults of one epoch, this one faults of a few seconds.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.gnss.windowed_line import ConsistencyConfig, ConsistencyTest, consistency_test

SENSOR_TEST = ConsistencyConfig()
"""±5 s, α = 0.001 per test, at least 5 neighbours."""
WHEEL_AT_REST_MPS = 0.05
"""A wheel speed below this is a car at rest: wheel encoders read zero when the wheels stand."""
AT_REST_MAX_MPS = 0.2
"""With the wheels at rest a conventional speed above this is a fault, whatever its σ: the
receivers standing in the Hong Kong street canyon show 0.02–0.07 m/s at p95 (u-blox F9P, M8T),
while fixes a few reflected satellites pulled reached 0.75 m/s and passed the speed test's 3σ
(zero-velocity update from the wheels)."""


@dataclass(frozen=True)
class ConventionalIntegrity:
    """The course and speed tests of the conventional velocity (None where its σ is unknown)
    and the epochs still valid after them."""

    course: ConsistencyTest | None
    speed: ConsistencyTest | None
    valid: np.ndarray


def conventional_integrity(
    t: np.ndarray,
    valid: np.ndarray,
    yaw: np.ndarray,
    yaw_sigma: np.ndarray | None,
    yaw_angle: np.ndarray,
    speed: np.ndarray,
    speed_sigma: np.ndarray | None,
    wheel_speed: np.ndarray,
    gyro_bias_sigma: np.ndarray,
    config: ConsistencyConfig = SENSOR_TEST,
) -> ConventionalIntegrity:
    """Test (I1) of the conventional yaw against the integrated calibrated yaw rate
    ``yaw_angle`` and of its horizontal speed against the calibrated ``wheel_speed``, at the
    epochs ``valid`` so far (rad, m/s; module docstring). The course line's slope is what is
    left of the gyro bias: its prior is N(0, ``gyro_bias_sigma``²) (rad/s, per epoch). Where the
    wheels stand (``WHEEL_AT_REST_MPS``) a speed above ``AT_REST_MAX_MPS`` fails outright."""
    valid = np.asarray(valid, dtype=bool)
    if not config.enabled:
        return ConventionalIntegrity(None, None, valid.copy())
    course = speed_test = None
    failed = np.zeros(valid.shape, dtype=bool)
    if yaw_sigma is not None:
        course = consistency_test(
            t,
            np.asarray(yaw) - np.asarray(yaw_angle),
            yaw_sigma,
            valid,
            config,
            angular=True,
            slope_sigma=gyro_bias_sigma,
        )
        failed |= course.failed
    if speed_sigma is not None:
        speed_test = consistency_test(
            t, np.asarray(speed) - np.asarray(wheel_speed), speed_sigma, valid, config
        )
        failed |= speed_test.failed
    at_rest = np.abs(np.nan_to_num(np.asarray(wheel_speed, dtype=float), nan=np.inf))
    failed |= (at_rest < WHEEL_AT_REST_MPS) & (np.nan_to_num(speed, nan=0.0) > AT_REST_MAX_MPS)
    return ConventionalIntegrity(course, speed_test, valid & ~failed)
