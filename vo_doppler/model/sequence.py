"""A recording: what one run of the main job reads, already on GPS time and in SI units."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vo_doppler.geo import EnuFrame
from vo_doppler.model.camera import Camera
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.image_files import ImageFiles
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.observations import Observations
from vo_doppler.model.precise_orbits import PreciseOrbits
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.model.vehicle_source import VehicleSignalSource


@dataclass
class Sequence:
    """Images and camera, GNSS observations and navigation (either may be missing), vehicle
    signals, the local ENU
    frame, the antenna lever arm and (when known) the ground truth of one recording.

    Every time is GPS seconds: the reader applied each sensor's clock offset (kept in
    ``clock_offsets_s`` by sensor name for the record).
    """

    name: str
    image_paths: ImageFiles
    """The images in order; any paths given (a list, say) are held as :class:`ImageFiles`."""
    image_times: np.ndarray
    camera: Camera | None
    observations: Observations | None
    """None for a recording without GNSS (e.g. an imported KITTI raw drive)."""
    navigation: Navigation | PreciseOrbits | None
    """Broadcast ephemerides or precise orbits (+ clocks): the GNSS stage takes either; None
    without GNSS."""
    yaw_rate: SensorSeries
    """Counter-clockwise positive, rad/s."""
    wheel_speed: SensorSeries
    """Vehicle speed from the wheels, m/s (before the wheel-scale calibration)."""
    enu: EnuFrame
    truth: Trajectory | None = None
    """Vehicle poses in the ENU frame, if known."""
    antenna_lever_arm_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    """GNSS antenna in the vehicle frame (x forward, y left, z up) from the vehicle origin (m)."""
    clock_offsets_s: dict[str, float] = field(default_factory=dict)
    """GPS time − sensor time per sensor ('camera', 'can', …) as the manifest gave it."""
    doppler_sigma: ReportedSigma | None = None
    """The receiver's σ of each Doppler range rate, when it reported one."""
    forward_acceleration: SensorSeries | None = None
    """Specific force along the vehicle's forward axis (m/s², an accelerometer's), if recorded:
    the tight heading's road grade prior."""
    vehicle_source: VehicleSignalSource = field(default_factory=VehicleSignalSource)
    """Where the yaw rate and wheel speed came from, for the checks' messages."""

    def __post_init__(self) -> None:
        self.image_paths = ImageFiles.of(self.image_paths)

    @property
    def has_gnss(self) -> bool:
        return self.observations is not None and self.navigation is not None

    @property
    def has_camera(self) -> bool:
        return self.camera is not None and len(self.image_paths) > 0

    @property
    def vehicle_signals(self) -> VehicleSignals:
        """The wheel speed, yaw rate and forward accelerometer with their source, as the
        heading stage takes them."""
        return VehicleSignals(
            self.wheel_speed, self.yaw_rate, self.forward_acceleration, self.vehicle_source
        )

    @property
    def vehicle_span(self) -> tuple[float, float] | None:
        """The GPS-time span (s) both vehicle signals (wheel speed and yaw rate) cover: where
        the calibration, the tightly coupled heading and the dead reckoning can run; None when
        they do not overlap."""
        if len(self.wheel_speed) == 0 or len(self.yaw_rate) == 0:
            return None
        begin = max(float(self.wheel_speed.t[0]), float(self.yaw_rate.t[0]))
        end = min(float(self.wheel_speed.t[-1]), float(self.yaw_rate.t[-1]))
        return (begin, end) if begin <= end else None
