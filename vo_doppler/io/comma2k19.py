"""The comma2k19 processed-log layout: signals as folders of extensionless numpy arrays.

Each signal folder holds ``t`` (s, the logger's monotonic clock) and ``value``. Read here:
the IMU gyro as a yaw rate, the u-blox receiver fixes, and ground truth from ``global_pose``.
Conventions on the way out (docs/design.md): the IMU axes are forward/right/down, so the
counter-clockwise yaw rate is −gyro_z; the ground-truth yaw is the course of the ECEF velocity
rotated into the ENU frame at its own position, as a CCW-from-east angle, unwrapped. The
ground truth's body yaw is the same angle for the forward axis of ``frame_orientations``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.errors import InputError
from vo_doppler.geo import ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.io.can import read_can_motion
from vo_doppler.io.gps_fixes import GpsFixes
from vo_doppler.model.gpstime import SECONDS_PER_WEEK, unix_to_gps_seconds


def load_array(base: str | Path, *parts: str) -> np.ndarray:
    """One extensionless numpy array of the layout, e.g. ``("global_pose", "frame_times")``."""
    path = Path(base).joinpath(*parts)
    try:
        return np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot load comma2k19 array: {exc}", path) from exc


def read_signal(base: str | Path, *parts: str, columns: int) -> tuple[np.ndarray, np.ndarray]:
    """(t, value) of one signal folder, e.g. ``("processed_log", "IMU", "gyro")``: ``t`` (N,)
    and ``value`` (N, ``columns``), checked for those shapes."""
    t = load_array(base, *parts, "t")
    value = load_array(base, *parts, "value")
    if t.ndim != 1 or value.ndim != 2 or value.shape != (t.size, columns):
        raise InputError(
            f"comma2k19 signal of shape t {t.shape}, value {value.shape}; expected t (N,) and "
            f"value (N, {columns})",
            Path(base).joinpath(*parts),
        )
    return t.astype(float), value.astype(float)


def read_gyro_yaw_rate(base: str | Path, signal: str = "gyro") -> tuple[np.ndarray, np.ndarray]:
    """(t, yaw rate rad/s CCW) from ``processed_log/IMU/<signal>`` (−gyro_z)."""
    t, value = read_signal(base, "processed_log", "IMU", signal, columns=3)
    return t, -value[:, 2]


def read_forward_acceleration(base: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(t, specific force m/s² along the device's forward axis) from
    ``processed_log/IMU/accelerometer`` (axes forward, right, down, as the gyro's)."""
    t, value = read_signal(base, "processed_log", "IMU", "accelerometer", columns=3)
    return t, value[:, 0]


def read_wheel_speed(base: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(t, mean of the four wheel speeds, m/s) from ``processed_log/CAN/wheel_speed``, the
    car's wheel speeds as comma decoded them from its bus (every car of the dataset)."""
    t, value = read_signal(base, "processed_log", "CAN", "wheel_speed", columns=4)
    return t, value.mean(axis=1)


@dataclass(frozen=True)
class GroundTruth:
    """``global_pose`` on the monotonic clock: yaw (rad, CCW, unwrapped) of the velocity and
    body yaw of the device's forward axis (a constant mounting offset apart, the same heading
    when the vehicle does not slip), lat/lon (rad); ``gps_minus_mono_s`` = GPS seconds of week
    − monotonic clock (``gps_minus_log`` within the pose's GPS week)."""

    t: np.ndarray
    yaw: np.ndarray
    body_yaw: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    height: np.ndarray
    gps_minus_mono_s: float


def read_ground_truth(base: str | Path) -> GroundTruth:
    t = load_array(base, "global_pose", "frame_times")
    positions = load_array(base, "global_pose", "frame_positions")
    velocity = load_array(base, "global_pose", "frame_velocities")
    quaternion_wxyz = load_array(base, "global_pose", "frame_orientations")
    gps_times = load_array(base, "global_pose", "frame_gps_times")
    lat, lon, height = ecef_to_geodetic(positions)
    rotation = np.stack([ecef_to_enu_rotation(a, b) for a, b in zip(lat, lon, strict=True)])
    enu = np.einsum("nij,nj->ni", rotation, velocity)
    yaw = np.unwrap(np.arctan2(enu[:, 1], enu[:, 0]))
    device_to_ecef = Rotation.from_quat(quaternion_wxyz[:, [1, 2, 3, 0]]).as_matrix()
    forward = np.einsum("nij,nj->ni", rotation, device_to_ecef[:, :, 0])
    body_yaw = np.unwrap(np.arctan2(forward[:, 1], forward[:, 0]))
    offset = gps_minus_log(base) - float(np.median(gps_times[:, 0])) * SECONDS_PER_WEEK
    return GroundTruth(t, yaw, body_yaw, lat, lon, height, offset)


def read_live_fixes(
    base: str | Path, gps_minus_mono_s: float | None = None, receiver: str = "live_gnss_ublox"
) -> GpsFixes:
    """Receiver fixes with their speed. Times are the fix epochs (from the UTC field) on the
    monotonic clock when ``gps_minus_mono_s`` (seconds of week − monotonic, see
    ``GroundTruth``) is given; otherwise the logging times, which lag the epochs."""
    folder = ("processed_log", "GNSS", receiver)
    value = load_array(base, *folder, "value")
    if gps_minus_mono_s is None:
        t = load_array(base, *folder, "t")
    else:
        t = np.mod(unix_to_gps_seconds(value[:, 3] / 1000.0), SECONDS_PER_WEEK) - gps_minus_mono_s
    return GpsFixes(
        t, np.radians(value[:, 0]), np.radians(value[:, 1]), value[:, 2], Path(base, *folder)
    )


def read_lowcost_inputs(base: Path):
    """Ground truth, receiver fixes, IMU yaw rate and CAN yaw rate ``(t, value)`` of a segment."""
    truth = read_ground_truth(base)
    fixes = read_live_fixes(base, truth.gps_minus_mono_s)
    gyro = read_gyro_yaw_rate(base)
    can = read_can_motion(
        base / "can_motion.log", base / "toyota_2017_motion.dbc", yaw_rate="KINEMATICS.YAW_RATE"
    ).yaw_rate
    return truth, fixes, gyro, (can.t, can.value)


RAW_GNSS = ("processed_log", "GNSS", "raw_gnss_ublox")
GLONASS_PRN_OFFSET = 64
"""comma2k19 numbers GLONASS satellites 65 + (slot − 1)."""


@dataclass(frozen=True)
class RawGnss:
    """``raw_gnss_ublox`` rows (one per satellite and epoch, u-blox RXM-RAWX): epoch GPS time
    (week × 604800 + time of week, s), system letter, PRN/slot, GLONASS frequency channel,
    pseudorange (m) and its σ, pseudorange rate (m/s, positive when the range grows) and its σ,
    C/N0 (dB-Hz), carrier phase (cycles, NaN when not tracked). Rows of other systems are
    dropped and counted."""

    t: np.ndarray
    system: np.ndarray
    prn: np.ndarray
    glonass_channel: np.ndarray
    pseudorange: np.ndarray
    pseudorange_sigma: np.ndarray
    range_rate: np.ndarray
    range_rate_sigma: np.ndarray
    cn0: np.ndarray
    carrier_phase: np.ndarray
    n_dropped: int


def read_raw_gnss(base: str | Path) -> RawGnss:
    """The rows of ``raw_gnss_ublox/value``. A row without a valid GPS week and time of week, or
    earlier than the row before it, is an :class:`InputError` naming the row; rows of other
    systems or with an impossible measurement (``_plausible``) are dropped and counted."""
    path = Path(base).joinpath(*RAW_GNSS, "value")
    value = load_array(base, *RAW_GNSS, "value")
    if value.ndim != 2 or value.shape[1] < 10 or value.dtype.kind not in "iuf":
        raise InputError(f"array of shape {value.shape} and type {value.dtype}, not (N, 10)", path)
    value = value.astype(float)
    week, tow = value[:, 1], value[:, 2]
    timed = (week == np.round(week)) & (week >= 0) & (week < 8192)
    timed &= (tow >= 0) & (tow < SECONDS_PER_WEEK)  # False for NaN too
    if not np.all(timed):
        row = int(np.flatnonzero(~timed)[0])
        raise InputError(f"row {row}: GPS week {week[row]}, time of week {tow[row]}", path)
    t = week * SECONDS_PER_WEEK + tow
    back = np.flatnonzero(np.diff(t) < 0)
    if back.size:
        raise InputError(f"row {int(back[0]) + 1}: time before the previous row's", path)
    number = np.where(np.isfinite(value[:, 0]), value[:, 0], 0).astype(np.int64)
    number[value[:, 0] != number] = 0
    gps = (number >= 1) & (number <= 32)
    glonass = (number > GLONASS_PRN_OFFSET) & (number <= GLONASS_PRN_OFFSET + 24)
    keep = (gps | glonass) & _plausible(value, glonass)
    rows = value[keep]
    return RawGnss(
        t=t[keep],
        system=np.where(gps[keep], "G", "R"),
        prn=np.where(gps[keep], number[keep], number[keep] - GLONASS_PRN_OFFSET),
        glonass_channel=rows[:, 3],
        pseudorange=rows[:, 4],
        pseudorange_sigma=rows[:, 5],
        range_rate=rows[:, 6],
        range_rate_sigma=rows[:, 7],
        cn0=rows[:, 8],
        carrier_phase=rows[:, 9],
        n_dropped=int((~keep).sum()),
    )


def _plausible(value: np.ndarray, glonass: np.ndarray) -> np.ndarray:
    """Rows whose measurements can be real (every comparison is False for NaN): pseudorange
    rate finite within 10 km/s and its σ positive, pseudorange within 1,000–100,000 km or
    missing, C/N0 within 0–100 dB-Hz, carrier phase finite or missing, GLONASS channel −7…6."""
    channel, pseudorange, carrier = value[:, 3], value[:, 4], value[:, 9]
    ok = (np.abs(value[:, 6]) < 1.0e4) & (value[:, 7] > 0) & np.isfinite(value[:, 7])
    ok &= np.isnan(pseudorange) | ((pseudorange > 1.0e6) & (pseudorange < 1.0e8))
    ok &= (value[:, 8] >= 0) & (value[:, 8] <= 100)
    ok &= ~np.isinf(carrier)
    return ok & (~glonass | ((channel >= -7) & (channel <= 6) & (channel == np.round(channel))))


def gps_minus_mono(base: str | Path) -> float:
    """GPS time (s since 1980) − the logs' monotonic clock as ``global_pose`` states it, from
    its paired ``frame_times`` and ``frame_gps_times`` (spread checked below 1 ms). Kept for
    the record only: ``gps_minus_log`` is the offset to use (its docstring says why)."""
    return _constant_offset(
        load_array(base, "global_pose", "frame_gps_times"),
        load_array(base, "global_pose", "frame_times"),
        Path(base, "global_pose"),
    )


def gps_minus_log(base: str | Path) -> float:
    """GPS time (s since 1980) − the logs' monotonic clock, from ``raw_gnss_ublox``: each
    row's receiver time tag (GPS week, time of week; the receiver clock error of a few ms
    apart) against its log time ``t`` (spread checked below 1 ms).

    ``global_pose``'s own ``frame_gps_times`` put the same clock 0.126 s later on the example
    segment, and they are the ones that are wrong: the pose agrees with the IMU on the log
    clock (gyro and accelerometer lag ≤ 0.01 s against the pose's rotation rate and
    acceleration), while the Doppler velocity, solved on the receiver's time tags, agrees with
    the pose velocity only when the pose is shifted by 0.129 ± 0.004 s (fitted as the speed
    error per unit acceleration), i.e. put on GPS time through this offset.
    """
    value = load_array(base, *RAW_GNSS, "value")
    return _constant_offset(value[:, 1:3], load_array(base, *RAW_GNSS, "t"), Path(base, *RAW_GNSS))


def _constant_offset(week_and_seconds: np.ndarray, log_t: np.ndarray, path: Path) -> float:
    """Median of (week × 604800 + seconds of week) − log time; InputError when it varies."""
    offsets = week_and_seconds[:, 0] * SECONDS_PER_WEEK + week_and_seconds[:, 1] - log_t
    if offsets.size == 0 or np.ptp(offsets) > 1e-3:
        spread = np.ptp(offsets) if offsets.size else np.nan
        raise InputError(f"GPS time − log time varies by {spread:.3f} s (or no rows)", path)
    return float(np.median(offsets))


MOVING_MPS = 5.0


@dataclass(frozen=True)
class DeviceMount:
    """How the device sits on the vehicle (rad), estimated by :func:`read_vehicle_poses`: the
    vehicle frame (x forward, y left, z up) is the device frame (x forward, y left, z up: its
    own y and z flipped) turned by Rz(yaw) · Ry(−pitch) · Rx(roll). ``yaw`` and ``pitch``: the
    direction of travel left of and above the device's forward axis; ``roll``: about that
    direction, so that the vehicle's y axis is level on average."""

    yaw: float
    pitch: float
    roll: float

    @property
    def vehicle_to_device(self) -> np.ndarray:
        """3×3 rotation: vehicle coordinates → device coordinates (x forward, y left, z up)."""
        return Rotation.from_euler("ZYX", [self.yaw, -self.pitch, self.roll]).as_matrix()


def read_vehicle_poses(
    base: str | Path,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, DeviceMount]:
    """``global_pose`` as vehicle poses: times on the log clock (``frame_times``, s; add
    ``gps_minus_log`` for GPS time), ECEF positions (m), vehicle→ECEF rotation matrices
    (vehicle x forward, y left, z up) and the device's mounting on the vehicle.

    ``frame_orientations`` (w, x, y, z) rotate the device frame (x forward, y right, z down)
    into ECEF: checked, its x axis follows ``frame_velocities`` to within the mounting angle.
    The device sits on the windscreen turned by a few degrees (the example segment: the
    direction of travel 3.8° above its forward axis and 0.8° right of it, 1.2° of roll), which
    the vehicle frame must not keep: its x axis is the direction of travel (a car does not
    slip, sideways or vertically) and its y axis level on average
    (:func:`estimate_device_mount`).
    """
    t = load_array(base, "global_pose", "frame_times")
    positions = load_array(base, "global_pose", "frame_positions")
    velocity = load_array(base, "global_pose", "frame_velocities")
    quaternion_wxyz = load_array(base, "global_pose", "frame_orientations")
    device_to_ecef = Rotation.from_quat(quaternion_wxyz[:, [1, 2, 3, 0]]).as_matrix()
    device_to_ecef = device_to_ecef * np.array([1.0, -1.0, -1.0])  # y left, z up
    lat, lon, _ = ecef_to_geodetic(positions)
    up = np.stack([ecef_to_enu_rotation(a, b)[2] for a, b in zip(lat, lon, strict=True)])
    mount = estimate_device_mount(device_to_ecef, velocity, up)
    return t, positions, device_to_ecef @ mount.vehicle_to_device, mount


def estimate_device_mount(
    device_to_world: np.ndarray, velocity: np.ndarray, up: np.ndarray
) -> DeviceMount:
    """The device's mounting from its attitude ``device_to_world`` (N, 3, 3; device x forward,
    y left, z up), the vehicle's velocity (N, 3) and the local vertical (N, 3), all in one
    world frame (e.g. ECEF), over the epochs faster than ``MOVING_MPS``.

    Yaw and pitch: the medians of the azimuth and elevation of the velocity in the device frame
    (a car's body points along its velocity; the median ignores the moments of wheel spin or
    suspension pitch). Roll: the median of the angle about that axis that levels the vehicle's
    y axis, i.e. the device's up axis against the local vertical. The data cannot tell the
    mounting roll from the road's: this takes the car's mean roll over the drive as zero. A
    road's crown (1.5–2 % across a lane) and a steady sideways slope would leave up to about
    1° in it; the yaw and the heading do not depend on it. Without a moving epoch, no turn.
    """
    moving = np.linalg.norm(velocity, axis=1) > MOVING_MPS
    if not moving.any():
        return DeviceMount(0.0, 0.0, 0.0)
    frames = device_to_world[moving]
    travel = np.einsum("nji,nj->ni", frames, velocity[moving])
    azimuth = np.arctan2(travel[:, 1], travel[:, 0])
    yaw = float(np.median(np.angle(np.exp(1j * azimuth))))
    pitch = float(np.median(np.arctan2(travel[:, 2], np.hypot(travel[:, 0], travel[:, 1]))))
    unrolled = DeviceMount(yaw, pitch, 0.0).vehicle_to_device
    vertical = np.einsum("ji,nkj,nk->ni", unrolled, frames, up[moving])
    roll = float(np.median(np.arctan2(-vertical[:, 1], vertical[:, 2])))
    return DeviceMount(yaw, pitch, roll)
