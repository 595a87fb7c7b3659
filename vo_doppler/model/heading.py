"""The heading table: one row per GNSS epoch with every heading and calibration of the epoch."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vo_doppler.geo import yaw_to_course
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import hold

DEFAULT_TC_WINDOW_S = 2.0
"""The tight heading's window where a heading file does not state its own."""


@dataclass(frozen=True)
class CalibrationSummary:
    """Gyro bias (rad/s) and wheel scale over the epochs the vehicle signals cover: the median
    of the estimates current at those epochs, their spread (normalised MAD: how far the causal
    estimate wandered) and the median of their σ; and the value at the last covered epoch (the
    table holds it beyond, where nothing calibrates)."""

    gyro_bias: float
    gyro_bias_spread: float
    gyro_bias_sigma: float
    final_gyro_bias: float
    wheel_scale: float
    wheel_scale_spread: float
    wheel_scale_sigma: float
    final_wheel_scale: float
    epochs: int

    def to_dict(self) -> dict:
        """Degrees per second for the bias, for people."""
        return {
            "gyro_bias_dps": float(np.degrees(self.gyro_bias)),
            "gyro_bias_spread_dps": float(np.degrees(self.gyro_bias_spread)),
            "gyro_bias_sigma_dps": float(np.degrees(self.gyro_bias_sigma)),
            "final_gyro_bias_dps": float(np.degrees(self.final_gyro_bias)),
            "wheel_scale": self.wheel_scale,
            "wheel_scale_spread": self.wheel_scale_spread,
            "wheel_scale_sigma": self.wheel_scale_sigma,
            "final_wheel_scale": self.final_wheel_scale,
            "epochs": self.epochs,
        }


@dataclass(frozen=True)
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
    rejected_rows: np.ndarray | None = None
    """Doppler rows of the window rejected as biased (NLOS) by the tightly coupled solver."""
    tc_verifiable: np.ndarray | None = None
    """A bias on any satellite the tightly coupled heading used would have shown in the
    residuals (False where it could hide, and where the heading is unavailable)."""
    sigma_conv: np.ndarray | None = None
    """Standard deviation (rad) of the conventional heading, NaN where unknown or invalid (the
    heading stage's is the velocity's times the factor of its gyro test, design (I1))."""
    speed_sigma_conv: np.ndarray | None = None
    """Standard deviation (m/s) of the conventional horizontal speed, NaN where unknown or
    invalid (scaled as ``sigma_conv``, by the wheel-speed test's factor)."""
    hdop_conv: np.ndarray | None = None
    """Horizontal DOP of the conventional velocity's geometry, NaN where unknown or invalid."""
    tc_window_s: float = DEFAULT_TC_WINDOW_S
    """The tightly coupled solver's window (s): its headings' errors are correlated over it."""
    conv_gnss_valid: np.ndarray | None = None
    """The conventional heading as the published method has it: valid by the GNSS tests alone
    (redundancy, χ², vertical velocity, course continuity; no gyro or wheel speed), the
    comparison pipeline's input (read through :attr:`published_conventional`)."""
    sigma_conv_gnss: np.ndarray | None = None
    """Standard deviation (rad) of the conventional heading from the velocity solution alone,
    NaN where unknown or not ``conv_gnss_valid``."""
    conv_velocity_valid: np.ndarray | None = None
    """The conventional velocity (its speed and, away from rest, its cross-track error) valid
    after the car's sensors' tests (docs/design.md (I1c)); the ``valid`` column of ``vel.csv``
    in the outputs of ``run`` and ``heading --vel``. None where not computed."""
    grade_prior_sigma: np.ndarray | None = None
    """σ of the road-grade prior of the tight window ending at each epoch (rise over run)."""
    grade_from_accelerometer: np.ndarray | None = None
    """Whether that prior came from a calibrated forward accelerometer (else the zero-mean
    default)."""
    warnings: list[str] = field(default_factory=list)
    """What the checks of the heading stage found doubtful in its inputs and calibration
    (:func:`vo_doppler.heading.from_gnss.heading_from_gnss`); not written to a heading CSV."""
    clock_residual_offset_s: float | None = None
    """The wheel speed's residual clock offset (s) against the GNSS Doppler speed, None when
    no lag was found or not checked (:func:`vo_doppler.checks.estimate_clock_offset`)."""
    calibration: CalibrationSummary | None = None
    """The drive's calibration over the epochs the vehicle signals cover."""
    method: str = ""
    """The tight heading's settings that made the table: "snooping" or "robust"
    (:meth:`vo_doppler.heading.pipeline.HeadingPipelineConfig.for_rate`); empty where unknown
    (a table read from a file)."""

    def __post_init__(self) -> None:
        n = len(self.t)
        defaults = {
            "rejected_rows": np.zeros(n, dtype=int),
            "tc_verifiable": np.zeros(n, dtype=bool),
            "grade_from_accelerometer": np.zeros(n, dtype=bool),
            **{
                name: np.full(n, np.nan)
                for name in ("sigma_conv", "speed_sigma_conv", "hdop_conv", "grade_prior_sigma")
            },
        }
        for name, default in defaults.items():
            if getattr(self, name) is None:
                object.__setattr__(self, name, default)

    def __len__(self) -> int:
        return len(self.t)

    @property
    def published_conventional(self) -> tuple[np.ndarray, np.ndarray]:
        """Validity and σ (rad) of the conventional heading by the GNSS tests alone (the
        published method), falling back on ``conv_valid`` and ``sigma_conv`` where not given."""
        valid = self.conv_valid if self.conv_gnss_valid is None else self.conv_gnss_valid
        sigma = self.sigma_conv if self.sigma_conv_gnss is None else self.sigma_conv_gnss
        return valid, sigma

    @property
    def tc_available(self) -> np.ndarray:
        return np.isfinite(self.yaw_tc)

    @property
    def course_tc(self) -> np.ndarray:
        """Tightly coupled heading as course (rad, clockwise from north), NaN if unavailable."""
        return np.where(self.tc_available, yaw_to_course(np.nan_to_num(self.yaw_tc)), np.nan)

    @property
    def course_conv(self) -> np.ndarray:
        """Conventional heading as course (rad) where it passed the GNSS tests
        (:attr:`published_conventional`; ``conv_valid``, every test, is a subset), NaN
        elsewhere."""
        shown = self.published_conventional[0]
        return np.where(shown, yaw_to_course(np.nan_to_num(self.yaw_conv)), np.nan)

    def calibrated_speed(self, wheel: SensorSeries) -> SensorSeries:
        """Wheel speed × the wheel scale current at each sample (held between epochs and
        beyond the first and last epoch)."""
        scale = hold(self.t, self.wheel_scale, wheel.t, outside="hold")
        return SensorSeries(wheel.t, wheel.value * scale, "speed", "m/s")

    def calibrated_yaw_rate(self, yaw_rate: SensorSeries) -> SensorSeries:
        """Yaw rate minus the gyro bias current at each sample (held as the wheel scale is)."""
        bias = hold(self.t, self.gyro_bias, yaw_rate.t, outside="hold")
        return SensorSeries(yaw_rate.t, yaw_rate.value - bias, "yaw rate", "rad/s")
