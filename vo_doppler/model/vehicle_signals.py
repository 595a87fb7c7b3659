"""The car's signals that the heading stage calibrates and couples with the GNSS Doppler
(docs/design.md, "Sensor calibration" and "Tightly coupled time-series heading"), on GPS time
and in SI units, with the names the checks give them."""

from __future__ import annotations

from dataclasses import dataclass, field

from vo_doppler.model.series import SensorSeries
from vo_doppler.model.vehicle_source import VehicleSignalSource


@dataclass(frozen=True)
class VehicleSignals:
    """Wheel speed and yaw rate, and a forward accelerometer where the recording has one."""

    wheel_speed: SensorSeries
    """Vehicle speed from the wheels, m/s (before the wheel-scale calibration)."""
    yaw_rate: SensorSeries
    """Counter-clockwise positive, rad/s (before the gyro-bias calibration)."""
    forward_acceleration: SensorSeries | None = None
    """Specific force along the vehicle's forward axis (m/s²): the tight heading's road-grade
    prior (:mod:`vo_doppler.heading.grade`); None where not recorded."""
    source: VehicleSignalSource = field(default_factory=VehicleSignalSource)
    """Where the wheel speed and yaw rate came from, for the checks' messages."""
