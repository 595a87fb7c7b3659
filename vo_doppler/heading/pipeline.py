"""Per-epoch heading from Doppler rows and vehicle sensors: calibration (sec. 3.3–3.4) feeding
the tightly coupled heading (sec. 3.5), with the conventional heading (sec. 3.2) alongside.

Calibration is causal: at each GNSS epoch the wheel scale and gyro bias are refreshed from the
conventional Doppler speed and course of the epochs so far (stored recent data), and the
estimates current at an epoch calibrate the sensors from that epoch to the next. Before the
first estimate, and while none can be made, scale 1 and bias 0 (or the last estimate) hold.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vo_doppler.geo import yaw_to_course
from vo_doppler.heading.calibration import (
    GateConfig,
    GyroBiasCalibrator,
    GyroBiasKalman,
    WheelScaleCalibrator,
    WheelScaleKalman,
)
from vo_doppler.heading.conventional import heading_from_velocity
from vo_doppler.heading.rows import DopplerRows
from vo_doppler.heading.sensors import integrate_rate, sample_at
from vo_doppler.heading.tight_heading import TightHeadingConfig, tight_heading_series
from vo_doppler.io.sensor_csv import SensorSeries

CALIBRATION_METHODS = ("ls", "kalman", "none")


@dataclass(frozen=True)
class HeadingPipelineConfig:
    """``calibration``: least squares, Kalman or none; fixed values override the estimates."""

    calibration: str = "ls"
    gate: GateConfig = field(default_factory=GateConfig)
    tight: TightHeadingConfig = field(default_factory=TightHeadingConfig)
    conventional_min_speed_mps: float = 0.5
    fixed_gyro_bias: float | None = None
    fixed_wheel_scale: float | None = None


@dataclass
class HeadingTable:
    """One row per GNSS epoch. Yaw in rad counter-clockwise from east (NaN when unavailable)."""

    t: np.ndarray
    yaw_tc: np.ndarray
    sigma_tc: np.ndarray
    tc_reliable: np.ndarray
    n_obs_window: np.ndarray
    n_sat_epoch: np.ndarray
    yaw_conv: np.ndarray
    conv_valid: np.ndarray
    gyro_bias: np.ndarray
    wheel_scale: np.ndarray

    def __len__(self) -> int:
        return len(self.t)

    @property
    def tc_available(self) -> np.ndarray:
        return np.isfinite(self.yaw_tc)

    @property
    def course_tc(self) -> np.ndarray:
        """Tightly coupled heading as course (rad, clockwise from north), NaN if unavailable."""
        return np.where(self.tc_available, yaw_to_course(np.nan_to_num(self.yaw_tc)), np.nan)

    @property
    def course_conv(self) -> np.ndarray:
        return np.where(self.conv_valid, yaw_to_course(np.nan_to_num(self.yaw_conv)), np.nan)

    def absolute_heading(self, source: str = "tc+conv") -> tuple[np.ndarray, np.ndarray]:
        """Yaw and validity for heading correction: ``tc`` reliable tightly coupled headings,
        ``conv`` conventional ones, ``tc+conv`` the former where reliable, else the latter."""
        tc_ok = self.tc_reliable & self.tc_available
        if source == "tc":
            return np.where(tc_ok, self.yaw_tc, np.nan), tc_ok
        if source == "conv":
            return np.where(self.conv_valid, self.yaw_conv, np.nan), self.conv_valid.copy()
        if source == "tc+conv":
            ok = tc_ok | self.conv_valid
            return np.where(
                tc_ok, self.yaw_tc, np.where(self.conv_valid, self.yaw_conv, np.nan)
            ), ok
        raise ValueError(f"unknown heading source {source!r} (tc, conv or tc+conv)")


def _calibrators(config: HeadingPipelineConfig):
    if config.calibration == "ls":
        return GyroBiasCalibrator(config.gate), WheelScaleCalibrator(config.gate)
    if config.calibration == "kalman":
        return GyroBiasKalman(config=config.gate), WheelScaleKalman(config=config.gate)
    if config.calibration == "none":
        return None, None
    raise ValueError(f"unknown calibration {config.calibration!r} ({CALIBRATION_METHODS})")


def causal_calibration(
    t_epoch: np.ndarray,
    doppler_speed: np.ndarray,
    doppler_yaw: np.ndarray,
    doppler_valid: np.ndarray,
    wheel_speed: np.ndarray,
    raw_yaw_angle: np.ndarray,
    config: HeadingPipelineConfig = HeadingPipelineConfig(),
) -> tuple[np.ndarray, np.ndarray]:
    """Gyro bias (rad/s) and wheel scale current at each epoch, refreshed epoch by epoch."""
    m = len(t_epoch)
    bias = np.zeros(m)
    scale = np.ones(m)
    bias_cal, scale_cal = _calibrators(config)
    current_bias, current_scale = 0.0, 1.0
    for k in range(m):
        if bias_cal is not None:
            b = bias_cal.add(
                t_epoch[k], doppler_yaw[k], raw_yaw_angle[k], doppler_speed[k], doppler_valid[k]
            )
            s = scale_cal.add(t_epoch[k], doppler_speed[k], wheel_speed[k], doppler_valid[k])
            current_bias = b.value if b.valid else current_bias
            current_scale = s.value if s.valid else current_scale
        bias[k], scale[k] = current_bias, current_scale
    if config.fixed_gyro_bias is not None:
        bias[:] = config.fixed_gyro_bias
    if config.fixed_wheel_scale is not None:
        scale[:] = config.fixed_wheel_scale
    return bias, scale


def heading_pipeline(
    t_epoch: np.ndarray,
    rows: DopplerRows,
    conventional_velocity_enu: np.ndarray,
    conventional_valid: np.ndarray,
    speed: SensorSeries,
    yaw_rate: SensorSeries,
    config: HeadingPipelineConfig = HeadingPipelineConfig(),
) -> HeadingTable:
    """Headings at every epoch (sensor series already on GPS time, yaw rate counter-clockwise)."""
    t_epoch = np.asarray(t_epoch, dtype=float)
    velocity = np.asarray(conventional_velocity_enu, dtype=float).reshape(-1, 3)
    conv_yaw, conv_ok = heading_from_velocity(
        velocity, conventional_valid, config.conventional_min_speed_mps
    )
    conv_speed = np.where(conventional_valid, np.linalg.norm(velocity, axis=1), np.nan)
    wheel = sample_at(speed.t, speed.value, t_epoch)
    raw_angle = integrate_rate(yaw_rate.t, yaw_rate.value, t_epoch)
    bias, scale = causal_calibration(
        t_epoch,
        conv_speed,
        conv_yaw,
        np.asarray(conventional_valid, bool),
        wheel,
        raw_angle,
        config,
    )
    # Φ_cal(t_k) = Φ_raw(t_k) − ∫ b̂ dt, with b̂ of epoch j held until epoch j + 1.
    bias_integral = np.concatenate([[0.0], np.cumsum(bias[:-1] * np.diff(t_epoch))])[: len(bias)]
    yaw_angle = raw_angle - bias_integral
    result = tight_heading_series(rows, t_epoch, scale * wheel, yaw_angle, config.tight)
    return HeadingTable(
        t=t_epoch,
        yaw_tc=result.yaw,
        sigma_tc=result.sigma,
        tc_reliable=result.reliable,
        n_obs_window=result.n_obs,
        n_sat_epoch=result.n_sat_epoch,
        yaw_conv=conv_yaw,
        conv_valid=conv_ok,
        gyro_bias=bias,
        wheel_scale=scale,
    )
