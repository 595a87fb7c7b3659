"""The comma2k19 processed-log layout: signals as folders of extensionless numpy arrays.

Each signal folder holds ``t`` (s, the logger's monotonic clock) and ``value``. Read here:
the IMU gyro as a yaw rate, the u-blox receiver fixes, and ground truth from ``global_pose``.
Conventions on the way out (docs/design.md): the IMU axes are forward/right/down, so the
counter-clockwise yaw rate is −gyro_z; the ground-truth yaw is the course of the ECEF velocity
rotated into the ENU frame at its own position, as a CCW-from-east angle, unwrapped. The
ground truth's body yaw is the same angle for the forward axis of ``frame_orientations``.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.lib import format as npformat
from scipy.spatial.transform import Rotation

from vo_doppler.bounds import (
    CARRIER_PHASE,
    CN0,
    FORWARD_ACCELERATION,
    GPS_TIME,
    HEIGHT,
    MEASUREMENT_SIGMA,
    PSEUDORANGE,
    RANGE_RATE,
    SPEED,
    TIME_OFFSET,
    YAW_RATE,
    SignalBounds,
    too_many_out_of_range,
)
from vo_doppler.errors import InputError
from vo_doppler.geo import ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.io.can import read_can_motion
from vo_doppler.io.gps_fixes import GpsFixes
from vo_doppler.model.gpstime import SECONDS_PER_WEEK, unix_to_gps_seconds

log = logging.getLogger(__name__)


def array_header(path: Path) -> tuple[tuple[int, ...], np.dtype]:
    """Shape and type an ``.npy`` file declares, checked against the file's size before any of
    its data is read (a header may claim terabytes). An :class:`InputError` names the file when
    it is not a numpy array file, holds Python objects, or holds fewer bytes than declared."""
    try:
        size = path.stat().st_size
        with path.open("rb") as handle:
            version = npformat.read_magic(handle)
            if version == (1, 0):
                shape, _, dtype = npformat.read_array_header_1_0(handle)
            elif version == (2, 0):
                shape, _, dtype = npformat.read_array_header_2_0(handle)
            else:
                raise ValueError(f"numpy format version {version[0]}.{version[1]}")
            offset = handle.tell()
    except OSError as exc:
        raise InputError(f"cannot read comma2k19 array: {exc.strerror or exc}", path) from exc
    except (ValueError, TypeError, SyntaxError, EOFError, OverflowError) as exc:
        raise InputError(f"not a numpy array file ({exc})", path) from exc
    if dtype.hasobject:
        raise InputError("the array holds Python objects, not data", path)
    declared = math.prod(shape) * dtype.itemsize
    if declared > size - offset:
        raise InputError(
            f"the header declares {declared:,} bytes of data ({shape}, {dtype}), the file holds "
            f"{size - offset:,}",
            path,
        )
    return tuple(shape), dtype


def load_array(base: str | Path, *parts: str) -> np.ndarray:
    """One extensionless numpy array of the layout, e.g. ``("global_pose", "frame_times")``;
    its header is checked first (:func:`array_header`)."""
    path = Path(base).joinpath(*parts)
    array_header(path)
    try:
        return np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError) as exc:
        raise InputError(f"cannot load comma2k19 array: {exc}", path) from exc


def numeric_array(
    base: str | Path,
    *parts: str,
    columns: int | None = None,
    at_least: bool = False,
    finite: bool = True,
) -> np.ndarray:
    """An array of numbers as floats: 1-D (``columns`` None) or 2-D with ``columns`` columns
    (at least that many with ``at_least``), not empty, every value finite unless ``finite`` is
    False. Anything else is an :class:`InputError` naming the array file (and the row)."""
    path = Path(base).joinpath(*parts)
    array = load_array(base, *parts)
    if array.dtype.kind not in "iuf":
        raise InputError(f"array of type {array.dtype}, not numbers", path)
    if columns is None:
        expected, shape_ok = "(N,)", array.ndim == 1
    else:
        expected = f"(N, {'at least ' if at_least else ''}{columns})"
        shape_ok = array.ndim == 2 and (
            array.shape[1] >= columns if at_least else array.shape[1] == columns
        )
    if not shape_ok:
        raise InputError(f"array of shape {array.shape}, expected {expected}", path)
    if array.shape[0] == 0:
        raise InputError("empty array", path)
    array = array.astype(float)
    if finite:
        bad = ~np.isfinite(array if array.ndim == 1 else array.reshape(array.shape[0], -1))
        if bad.any():
            row = int(np.flatnonzero(bad if bad.ndim == 1 else bad.any(axis=1))[0])
            raise InputError(f"row {row}: value not finite ({array[row]})", path)
    return array


def times_array(base: str | Path, *parts: str) -> np.ndarray:
    """A ``t`` array (s): finite, within ±``GPS_TIME``'s span and strictly increasing; an
    :class:`InputError` names the file and the first row that is not."""
    path = Path(base).joinpath(*parts)
    t = numeric_array(base, *parts)
    wild = np.abs(t) > GPS_TIME.high
    if wild.any():
        row = int(np.flatnonzero(wild)[0])
        raise InputError(f"row {row}: time {t[row]:g} s is beyond any clock's reading", path)
    back = np.flatnonzero(~(np.diff(t) > 0))
    if back.size:
        row = int(back[0]) + 1
        raise InputError(f"row {row}: time {t[row]!r} is not after the previous row's", path)
    return t


def read_signal(base: str | Path, *parts: str, columns: int) -> tuple[np.ndarray, np.ndarray]:
    """(t, value) of one signal folder, e.g. ``("processed_log", "IMU", "gyro")``: ``t`` (N,)
    finite and strictly increasing, and ``value`` (N, ``columns``) finite; an
    :class:`InputError` names the array file otherwise."""
    t = times_array(base, *parts, "t")
    value = numeric_array(base, *parts, "value", columns=columns)
    if value.shape[0] != t.size:
        raise InputError(
            f"{value.shape[0]} values for the {t.size} times of {Path(base, *parts, 't')}",
            Path(base).joinpath(*parts, "value"),
        )
    return t, value


def bounded(
    t: np.ndarray, value: np.ndarray, bounds: SignalBounds, path: Path, what: str
) -> tuple[np.ndarray, np.ndarray]:
    """The samples within ``bounds`` (:mod:`vo_doppler.bounds`): isolated ones
    outside are skipped with a warning naming the file, more are an :class:`InputError`."""
    outside = bounds.outside(value)
    n_out = int(outside.sum())
    if not n_out:
        return t, value
    first = int(np.flatnonzero(outside)[0])
    message = (
        f"{what} {value[first]:g} {bounds.unit} (row {first}) is outside what a vehicle can "
        f"report, {bounds}"
    )
    if too_many_out_of_range(n_out, value.size):
        raise InputError(f"{message}, and so are {n_out} of {value.size} samples", path)
    log.warning("%s: %s: %d samples skipped", path, message, n_out)
    return t[~outside], value[~outside]


def read_gyro_yaw_rate(base: str | Path, signal: str = "gyro") -> tuple[np.ndarray, np.ndarray]:
    """(t, yaw rate rad/s CCW) from ``processed_log/IMU/<signal>`` (−gyro_z)."""
    t, value = read_signal(base, "processed_log", "IMU", signal, columns=3)
    path = Path(base, "processed_log", "IMU", signal, "value")
    return bounded(t, -value[:, 2], YAW_RATE, path, "yaw rate")


def read_forward_acceleration(base: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(t, specific force m/s² along the device's forward axis) from
    ``processed_log/IMU/accelerometer`` (axes forward, right, down, as the gyro's)."""
    t, value = read_signal(base, "processed_log", "IMU", "accelerometer", columns=3)
    path = Path(base, "processed_log", "IMU", "accelerometer", "value")
    return bounded(t, value[:, 0], FORWARD_ACCELERATION, path, "forward acceleration")


def read_wheel_speed(base: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(t, mean of the four wheel speeds, m/s) from ``processed_log/CAN/wheel_speed``, the
    car's wheel speeds as comma decoded them from its bus (every car of the dataset)."""
    t, value = read_signal(base, "processed_log", "CAN", "wheel_speed", columns=4)
    path = Path(base, "processed_log", "CAN", "wheel_speed", "value")
    return bounded(t, value.mean(axis=1), SPEED, path, "wheel speed")


POSE = "global_pose"
QUATERNION_NORM_TOLERANCE = 0.01
"""How far from 1 the norm of a ``frame_orientations`` quaternion may be (a rotation's is 1)."""
MAX_POSE_JUMP_SPEED_MPS = 2.0 * SPEED.high
"""Fastest movement between consecutive poses (m/s): a vehicle's top speed, doubled for the
poses' own noise; beyond it a position is not the vehicle's."""


@dataclass(frozen=True)
class PoseArrays:
    """``global_pose``'s arrays, read and checked (:func:`read_pose_arrays`); ``gps_times``
    None when not asked for."""

    t: np.ndarray
    positions: np.ndarray
    velocities: np.ndarray
    quaternion_wxyz: np.ndarray
    gps_times: np.ndarray | None


def read_pose_arrays(base: str | Path, gps_times: bool = True) -> PoseArrays:
    """``global_pose``: frame times (strictly increasing), ECEF positions at a road vehicle's
    height (``HEIGHT``) and never moving faster than ``MAX_POSE_JUMP_SPEED_MPS`` between frames,
    velocities within a vehicle's speed (``SPEED``), unit quaternions and (with ``gps_times``)
    GPS (week, seconds of week), one row per frame; an :class:`InputError` names the array file
    and the row."""
    folder = Path(base, POSE)
    t = times_array(base, POSE, "frame_times")
    positions = numeric_array(base, POSE, "frame_positions", columns=3)
    velocities = numeric_array(base, POSE, "frame_velocities", columns=3)
    quaternion = numeric_array(base, POSE, "frame_orientations", columns=4)
    gps = numeric_array(base, POSE, "frame_gps_times", columns=2) if gps_times else None
    for name, array in (
        ("frame_positions", positions),
        ("frame_velocities", velocities),
        ("frame_orientations", quaternion),
        ("frame_gps_times", np.zeros((t.size, 2)) if gps is None else gps),
    ):
        if array.shape[0] != t.size:
            raise InputError(f"{array.shape[0]} rows for {t.size} frame_times", folder / name)
    _, _, height = ecef_to_geodetic(positions)
    _first_bad(HEIGHT.outside(height), folder / "frame_positions", "height", height, "m")
    speed = np.linalg.norm(velocities, axis=1)
    _first_bad(SPEED.outside(speed), folder / "frame_velocities", "speed", speed, "m/s")
    jump = np.zeros(t.size)
    jump[1:] = np.linalg.norm(np.diff(positions, axis=0), axis=1) / np.diff(t)
    wild = jump > MAX_POSE_JUMP_SPEED_MPS
    _first_bad(wild, folder / "frame_positions", "movement from the previous frame", jump, "m/s")
    norm = np.linalg.norm(quaternion, axis=1)
    off = np.abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE
    _first_bad(off, folder / "frame_orientations", "quaternion norm", norm, "")
    if gps is not None:
        week, seconds = gps[:, 0], gps[:, 1]
        total = week * SECONDS_PER_WEEK + seconds
        untimed = (week != np.round(week)) | (seconds < 0) | (seconds >= SECONDS_PER_WEEK)
        untimed |= GPS_TIME.outside(total)
        _first_bad(untimed, folder / "frame_gps_times", "GPS time", total, "s")
    return PoseArrays(t, positions, velocities, quaternion, gps)


def _first_bad(bad: np.ndarray, path: Path, what: str, values: np.ndarray, unit: str) -> None:
    """An :class:`InputError` naming the first row of ``bad``, if any."""
    if bad.any():
        row = int(np.flatnonzero(bad)[0])
        raise InputError(f"row {row}: {what} {values[row]:g} {unit} is impossible".strip(), path)


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
    pose = read_pose_arrays(base)
    t, positions, velocity = pose.t, pose.positions, pose.velocities
    quaternion_wxyz, gps_times = pose.quaternion_wxyz, pose.gps_times
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
    value = numeric_array(base, *folder, "value", columns=6)
    if gps_minus_mono_s is None:
        t = times_array(base, *folder, "t")
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
    value = numeric_array(base, *RAW_GNSS, "value", columns=10, at_least=True, finite=False)
    week, tow = value[:, 1], value[:, 2]
    timed = (week == np.round(week)) & (week >= 0) & (week < 8192)
    timed &= (tow >= 0) & (tow < SECONDS_PER_WEEK)  # False for NaN too
    timed &= ~GPS_TIME.outside(week * SECONDS_PER_WEEK + tow)
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


def _raw_arrays(base: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """``raw_gnss_ublox``'s log times (finite, never going back) and its value rows (N, ≥ 10),
    one per time; an :class:`InputError` names the array file otherwise."""
    t = numeric_array(base, *RAW_GNSS, "t")
    value = numeric_array(base, *RAW_GNSS, "value", columns=10, at_least=True, finite=False)
    if value.shape[0] != t.size:
        raise InputError(
            f"{value.shape[0]} rows for the {t.size} times of {Path(base, *RAW_GNSS, 't')}",
            Path(base, *RAW_GNSS, "value"),
        )
    path = Path(base, *RAW_GNSS, "t")
    wild = np.abs(t) > GPS_TIME.high
    if wild.any():
        row = int(np.flatnonzero(wild)[0])
        raise InputError(f"row {row}: time {t[row]:g} s is beyond any clock's reading", path)
    back = np.flatnonzero(np.diff(t) < 0)
    if back.size:
        raise InputError(f"row {int(back[0]) + 1}: time before the previous row's", path)
    return t, value


def _plausible(value: np.ndarray, glonass: np.ndarray) -> np.ndarray:
    """Rows whose measurements can be real (:mod:`vo_doppler.bounds`; NaN is outside
    every bound): pseudorange rate within ``RANGE_RATE`` and its σ within
    ``MEASUREMENT_SIGMA``, pseudorange within ``PSEUDORANGE`` or missing, C/N0 within ``CN0``,
    carrier phase within ``CARRIER_PHASE`` or missing, GLONASS channel −7…6."""
    channel, pseudorange, carrier = value[:, 3], value[:, 4], value[:, 9]
    ok = ~RANGE_RATE.outside(value[:, 6]) & ~MEASUREMENT_SIGMA.outside(value[:, 7])
    ok &= np.isnan(pseudorange) | ~PSEUDORANGE.outside(pseudorange)
    ok &= ~CN0.outside(value[:, 8])
    ok &= np.isnan(carrier) | ~CARRIER_PHASE.outside(carrier)
    return ok & (~glonass | ((channel >= -7) & (channel <= 6) & (channel == np.round(channel))))


def gps_minus_mono(base: str | Path) -> float:
    """GPS time (s since 1980) − the logs' monotonic clock as ``global_pose`` states it, from
    its paired ``frame_times`` and ``frame_gps_times`` (spread checked below 1 ms). Kept for
    the record only: ``gps_minus_log`` is the offset to use (its docstring says why)."""
    t = times_array(base, POSE, "frame_times")
    gps_times = numeric_array(base, POSE, "frame_gps_times", columns=2)
    path = Path(base, POSE, "frame_gps_times")
    if gps_times.shape[0] != t.size:
        raise InputError(f"{gps_times.shape[0]} rows for {t.size} frame_times", path)
    return _constant_offset(gps_times, t, path)


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
    t, value = _raw_arrays(base)
    return _constant_offset(value[:, 1:3], t, Path(base, *RAW_GNSS, "value"))


def _constant_offset(week_and_seconds: np.ndarray, log_t: np.ndarray, path: Path) -> float:
    """Median of (week × 604800 + seconds of week) − log time; an InputError naming ``path``
    when it varies, is not finite or lies beyond ``TIME_OFFSET``."""
    offsets = week_and_seconds[:, 0] * SECONDS_PER_WEEK + week_and_seconds[:, 1] - log_t
    if offsets.size == 0 or not np.isfinite(offsets).all():
        raise InputError("GPS time − log time is not a number (or no rows)", path)
    if np.ptp(offsets) > 1e-3:
        raise InputError(f"GPS time − log time varies by {np.ptp(offsets):.3f} s", path)
    offset = float(np.median(offsets))
    if TIME_OFFSET.outside(np.array([offset]))[0]:
        raise InputError(f"GPS time − log time {offset:g} s is outside {TIME_OFFSET}", path)
    return offset


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
    pose = read_pose_arrays(base, gps_times=False)
    t, positions, velocity = pose.t, pose.positions, pose.velocities
    quaternion_wxyz = pose.quaternion_wxyz
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
