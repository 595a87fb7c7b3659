"""A ROS bag (ROS 1 ``.bag``, ROS 2 sqlite3 or MCAP) → a standard sequence folder
(``sequence.yaml``, format ``vo-doppler-sequence/1``, docs/sequence_format.md).

Topics are found by message type (the first topic of each kind, in name order; ``--list-topics``
shows what would be used) or named by options:

- ``sensor_msgs/Image`` → ``image_0/NNNNNN.png`` (mono8/8UC1, mono16/16UC1, bgr8, rgb8, bgra8,
  rgba8; the pixels as sent, row padding removed) or ``sensor_msgs/CompressedImage`` → the
  JPEG/PNG bytes as sent (``.jpg``/``.png``); ``times.txt``: one GPS time (s) per image;
- ``sensor_msgs/CameraInfo`` → ``calib.yaml`` (K, and D for ``plumb_bob`` /
  ``rational_polynomial`` with its terms past k3 zero), unless ``--calib`` gives a
  calibration file; the camera→vehicle extrinsic from ``/tf_static`` (the chain from
  ``--vehicle-frame``, default ``base_link``, to the camera's ``frame_id``), otherwise a
  forward-looking camera at the vehicle origin (logged);
- ``sensor_msgs/Imu`` → ``vehicle/yaw_rate.csv`` (counter-clockwise positive, rad/s) from the
  gyro axis given by ``--imu-yaw-axis`` (``z``, ``-z``, ``x`` …) or estimated: the axis along
  which the mean specific force is largest is the vertical, and its sign says up (+g) or down;
  without accelerometer data, the gyro axis of largest RMS, sign +, with a warning; or, with a
  DBC (``--dbc FILE --yaw-rate MSG.SIG [--yaw-rate-sign -1]``), the yaw-rate signal of a
  ``can_msgs/Frame`` topic (the DBC unit to rad/s, −1 for a bus reporting clockwise-positive
  yaw rate), the IMU then used for the forward acceleration only (a bag without an IMU has
  none);
  ``imu/forward_acceleration.csv`` from the horizontal accelerometer axis given by
  ``--imu-forward-axis`` or estimated (the signed horizontal axis whose specific force,
  averaged over 1 s, best matches the speed's change over that second; none when even the best
  misses by half the RMS acceleration, e.g. a drive at constant speed);
- ``geometry_msgs/TwistStamped`` / ``TwistWithCovarianceStamped`` / ``nav_msgs/Odometry`` →
  ``vehicle/wheel_speed.csv`` (``linear.x``, m/s); or, with a DBC (``--dbc FILE
  --wheel-speed MSG.A,MSG.B``), the wheel-speed signals of a ``can_msgs/Frame`` topic
  (:mod:`vo_doppler.io.rosbag_can`);
- raw GNSS (:mod:`vo_doppler.io.rosbag_gnss`) → ``gnss/rover.obs`` (RINEX 3.04; its approximate
  position the first NavSatFix fix, else the origin), and
  ``gnss/brdc.nav`` when the bag holds ephemerides (GLONASS ones from ``GnssGloEphemMsg`` or
  the GLONASS strings of ``RxmSFRBX``),
  ``gnss/doppler_sigma.csv`` when the receiver reported Doppler σ;
- the GNSS antenna lever arm (``gnss.antenna_lever_arm_m``) from ``/tf_static``: the vehicle
  frame → ``--gnss-frame`` or the NavSatFix topic's ``frame_id``; 0 without one;
- ``sensor_msgs/NavSatFix`` → the origin (its first fix with status ≥ 0, unless ``--origin``)
  and ``gnss/fixes.csv`` (a record); ground truth (``--ground-truth TOPIC`` only) from
  ``nav_msgs/Odometry``, ``geometry_msgs/PoseStamped`` or ``PoseWithCovarianceStamped`` (poses
  read as in the ENU frame of the origin: x east, y north, z up) or ``NavSatFix`` (positions
  in that frame, the yaw from the track, held below 0.5 m/s) → ``ground_truth.tum`` on GPS time.

Time: each message's time is its ``header.stamp`` (``--stamps header``, the default; the
receive time for a message without a header or with a zero stamp) or the time the bag recorded
it (``--stamps receive``). ROS times go to GPS time by one offset: ``--clock utc`` (default:
ROS time is Unix time, UTC: GPS = ROS − 315964800 s + the leap seconds of the bag's date),
``--clock gnss`` (estimated: the median of GPS epoch − ROS time of the raw GNSS messages; this
includes the receiver's output latency) or ``--clock-offset S``. Every file is written on GPS
time (``time_offset_s`` 0); the GNSS epochs are the receiver's own GPS times. The choices are
recorded under ``rosbag:`` in the manifest and returned in the summary.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field, replace
from enum import StrEnum
from pathlib import Path

import cv2
import numpy as np
import yaml
from scipy.spatial.transform import Rotation

from vo_doppler.choices import check_fields
from vo_doppler.errors import InputError, UsageError
from vo_doppler.geo import EnuFrame, geodetic_to_ecef
from vo_doppler.io.calibration import checked_camera, read_camera, write_camera_yaml
from vo_doppler.io.doppler_sigma import write_doppler_sigma
from vo_doppler.io.output_folder import check_output_folder, open_output_folder
from vo_doppler.io.rinex_write import observation_epochs, write_nav, write_obs
from vo_doppler.io.rosbag_bag import KIND_NAMES, Bag, Topic
from vo_doppler.io.rosbag_can import read_can_signals
from vo_doppler.io.rosbag_gnss import BagGnss, read_gnss_comm, read_ublox
from vo_doppler.io.rosbag_types import field as get
from vo_doppler.io.sensor_csv import (
    FORWARD_ACCELERATION_COLUMN,
    SPEED_COLUMN,
    YAW_RATE_COLUMN,
    write_sensor_csv,
)
from vo_doppler.io.sequence import FORMAT, MANIFEST
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD, Camera
from vo_doppler.model.gpstime import UNIX_TIME_AT_GPS_EPOCH_S, gps_minus_utc
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory

log = logging.getLogger(__name__)

IMAGES = "image_0"
TIMES = "times.txt"
CALIB = "calib.yaml"
YAW_RATE_CSV = "vehicle/yaw_rate.csv"
SPEED_CSV = "vehicle/wheel_speed.csv"
ACCELERATION_CSV = "imu/forward_acceleration.csv"
OBS = "gnss/rover.obs"
NAV = "gnss/brdc.nav"
SIGMA = "gnss/doppler_sigma.csv"
FIXES = "gnss/fixes.csv"
GROUND_TRUTH = "ground_truth.tum"
KINDS: dict[str, tuple[str, ...]] = {
    "image": ("sensor_msgs/msg/Image", "sensor_msgs/msg/CompressedImage"),
    "camera_info": ("sensor_msgs/msg/CameraInfo",),
    "imu": ("sensor_msgs/msg/Imu",),
    "speed": (
        "geometry_msgs/msg/TwistStamped",
        "geometry_msgs/msg/TwistWithCovarianceStamped",
        "nav_msgs/msg/Odometry",
    ),
    "can": ("can_msgs/msg/Frame",),
    "gnss": ("gnss_comm/msg/GnssMeasMsg", "ublox_msgs/msg/RxmRAWX"),
    "ephemeris": (
        "gnss_comm/msg/GnssEphemMsg",
        "gnss_comm/msg/GnssGloEphemMsg",
        "ublox_msgs/msg/RxmSFRBX",
    ),
    "iono": ("gnss_comm/msg/StampedFloat64Array",),
    "fix": ("sensor_msgs/msg/NavSatFix",),
    "ground_truth": (
        "nav_msgs/msg/Odometry",
        "geometry_msgs/msg/PoseStamped",
        "geometry_msgs/msg/PoseWithCovarianceStamped",
        "sensor_msgs/msg/NavSatFix",
    ),
    "tf": ("tf2_msgs/msg/TFMessage",),
}
AUTO_KINDS = ("image", "camera_info", "imu", "speed", "can", "gnss", "iono", "fix", "tf")
"""Kinds found without an option (ephemeris topics follow the GNSS interface; ground truth is
only taken when named: an Odometry topic is as often a wheel odometry as a reference). The
speed comes from a speed topic, or with a DBC from a CAN topic: only that one is looked for."""
AXES = ("x", "y", "z", "-x", "-y", "-z")
GRAVITY_MIN_MPS2 = 5.0
FORWARD_MAX_MISFIT = 0.5
"""An axis is taken when its specific force misses the speed's change by less than half the
RMS acceleration (a bias or a slope's gravity share stays well below that)."""
FORWARD_WINDOW_S = 1.0
"""The speed's change and the specific force are compared as means over this window: the
derivative of a wheel speed sample by sample is mostly its quantisation noise."""
HELD_COURSE_SPEED_MPS = 0.5
ENCODINGS = {  # ROS image encoding → (numpy dtype, channels, OpenCV conversion to BGR or None)
    "mono8": (np.uint8, 1, None),
    "8UC1": (np.uint8, 1, None),
    "mono16": (np.uint16, 1, None),
    "16UC1": (np.uint16, 1, None),
    "bgr8": (np.uint8, 3, None),
    "8UC3": (np.uint8, 3, None),
    "rgb8": (np.uint8, 3, cv2.COLOR_RGB2BGR),
    "bgra8": (np.uint8, 4, None),
    "rgba8": (np.uint8, 4, cv2.COLOR_RGBA2BGRA),
}


class StampSource(StrEnum):
    """A message's time (``--stamps``, module docstring): its ``header.stamp`` (the reception
    time for a message without one), or the time the bag recorded it."""

    HEADER = "header"
    RECEIVE = "receive"


class RosClock(StrEnum):
    """How ROS time goes to GPS time (``--clock``, module docstring)."""

    UTC = "utc"
    """ROS time is Unix UTC time: the leap seconds are added."""
    GNSS = "gnss"
    """Estimated from the raw GNSS messages' epochs and ROS times."""


@dataclass(frozen=True)
class RosbagOptions:
    """Topic choices (None: found by type), time handling and IMU axes (module docstring)."""

    image_topic: str | None = None
    camera_info_topic: str | None = None
    imu_topic: str | None = None
    speed_topic: str | None = None
    can_topic: str | None = None
    dbc: Path | None = None
    wheel_speed: str | None = None
    """``MSG.A,MSG.B``: the DBC's wheel-speed signals (averaged); the speed then comes from the
    CAN topic."""
    yaw_rate: str | None = None
    """``MSG.SIG``: the DBC's yaw-rate signal; the yaw rate then comes from the CAN topic."""
    yaw_rate_sign: float = 1.0
    """−1 when the bus reports clockwise-positive yaw rate."""
    gnss_topic: str | None = None
    ephemeris_topics: tuple[str, ...] | None = None
    iono_topic: str | None = None
    fix_topic: str | None = None
    ground_truth_topic: str | None = None
    tf_topic: str | None = None
    stamps: StampSource = StampSource.HEADER
    clock: RosClock = RosClock.UTC
    clock_offset_s: float | None = None
    imu_yaw_axis: str = "auto"
    imu_forward_axis: str = "auto"
    origin: tuple[float, float, float] | None = None
    calib: Path | None = None
    vehicle_frame: str = "base_link"
    gnss_frame: str | None = None

    def __post_init__(self) -> None:
        check_fields(self, stamps=StampSource, clock=RosClock)

    def problem(self) -> str | None:
        """Options that contradict each other (a usage error), else None."""
        signals = self.wheel_speed is not None or self.yaw_rate is not None
        if self.dbc is not None and not signals:
            return (
                "--dbc FILE needs the signals to decode: --wheel-speed MSG.SIG[,MSG.SIG] and/or "
                "--yaw-rate MSG.SIG"
            )
        if self.dbc is None and signals:
            return "--wheel-speed and --yaw-rate are signals of a DBC: give --dbc FILE"
        if self.dbc is None and self.can_topic is not None:
            return "--can-topic needs --dbc FILE and its signals (--wheel-speed, --yaw-rate)"
        if self.wheel_speed is not None and self.speed_topic is not None:
            return "--speed-topic and --wheel-speed both give the speed: keep one"
        if self.yaw_rate is None and self.yaw_rate_sign != 1.0:
            return "--yaw-rate-sign needs --yaw-rate MSG.SIG (the CAN yaw rate it applies to)"
        return None


@dataclass
class RosbagImportSummary:
    folder: Path
    bag: Path
    topics: dict[str, str]
    images: int
    gnss_epochs: int
    ephemerides: int
    yaw_rate_samples: int
    speed_samples: int
    speed_source: str
    yaw_rate_source: str
    ground_truth_poses: int
    clock: str
    gps_minus_ros_s: float
    stamps: StampSource
    yaw_axis: str
    forward_axis: str
    extrinsic_from: str
    warnings: list[str] = field(default_factory=list)


def discover(
    topics: list[Topic], options: RosbagOptions, path: Path | None = None
) -> dict[str, str | list[str]]:
    """The topic of each kind: given by an option (checked against its type) or found by type;
    ``path`` (the bag) is named in the errors."""
    by_name = {t.name: t for t in topics}
    chosen: dict[str, str | list[str]] = {}
    given = {
        "image": options.image_topic,
        "camera_info": options.camera_info_topic,
        "imu": options.imu_topic,
        "speed": options.speed_topic,
        "can": options.can_topic,
        "gnss": options.gnss_topic,
        "iono": options.iono_topic,
        "fix": options.fix_topic,
        "ground_truth": options.ground_truth_topic,
        "tf": options.tf_topic,
    }
    unused = {"speed"} if options.wheel_speed is not None else set()
    unused |= {"can"} if options.dbc is None else set()
    for kind, name in given.items():
        if name is None:
            if kind in AUTO_KINDS and kind not in unused:
                found = [t.name for t in topics if t.msgtype in KINDS[kind] and t.count]
                if kind == "speed":  # a Twist topic before an Odometry one
                    found.sort(key=lambda n: by_name[n].msgtype == "nav_msgs/msg/Odometry")
                if kind == "tf":
                    found.sort(key=lambda n: n != "/tf_static")
                if found:
                    chosen[kind] = found[0]
            continue
        if name not in by_name:
            raise InputError(f"no topic {name} ({kind}) in the bag: see --list-topics", path)
        if by_name[name].msgtype not in KINDS[kind]:
            raise InputError(
                f"topic {name} is {by_name[name].msgtype}, not one of the {kind} types "
                f"({', '.join(KINDS[kind])})",
                path,
            )
        chosen[kind] = name
    if options.ephemeris_topics is not None:
        for name in options.ephemeris_topics:
            if name not in by_name or by_name[name].msgtype not in KINDS["ephemeris"]:
                raise InputError(
                    f"{name} is not an ephemeris topic in the bag: see --list-topics", path
                )
        chosen["ephemeris"] = list(options.ephemeris_topics)
    elif "gnss" in chosen:
        interface = by_name[str(chosen["gnss"])].msgtype.split("/")[0]
        chosen["ephemeris"] = [
            t.name
            for t in topics
            if t.msgtype in KINDS["ephemeris"] and t.msgtype.startswith(interface + "/")
        ]
    return chosen


def list_topics(bag_path: str | Path, options: RosbagOptions | None = None) -> list[str]:
    """One line per topic: name, type, message count and what the import would use it for."""
    with Bag(bag_path) as bag:
        topics = bag.topics()
        chosen = discover(topics, options or RosbagOptions(), Path(bag_path))
    roles: dict[str, list[str]] = {}
    for kind, value in chosen.items():
        for name in [value] if isinstance(value, str) else value:
            roles.setdefault(name, []).append(kind)
    width = max((len(t.name) for t in topics), default=5)
    lines = [f"{bag_path} ({KIND_NAMES[Bag(bag_path).kind]}):"]
    for t in topics:
        role = ", ".join(roles.get(t.name, [])) or "-"
        lines.append(f"  {t.name:<{width}}  {t.msgtype:<45} {t.count:>7}  {role}")
    return lines


class _Timing:
    """Message time by the stamp choice (and which one each topic used), on GPS time once
    ``offset`` (GPS − ROS, s) is set. The whole seconds of stamp and offset are added as
    integers, so that a GPS time comes out as exactly as a float64 holds it."""

    def __init__(self, stamps: StampSource) -> None:
        self.stamps = stamps
        self.offset = 0.0
        self.used: dict[str, set[str]] = {}

    def time(self, topic: str, receive_ns: int, message) -> float:
        header = get(message, "header")
        if self.stamps is StampSource.HEADER and header is not None:
            stamp = get(header, "stamp")
            sec, nanosec = int(get(stamp, "sec", 0)), int(get(stamp, "nanosec", 0))
            if sec > 0 or nanosec > 0:
                self.used.setdefault(topic, set()).add("header stamp")
                return self._gps(sec, nanosec)
        self.used.setdefault(topic, set()).add("receive time")
        return self._gps(*divmod(int(receive_ns), 1_000_000_000))

    def _gps(self, sec: int, nanosec: int) -> float:
        whole = int(np.floor(self.offset))
        return float(sec + whole) + (nanosec * 1e-9 + (self.offset - whole))

    def described(self) -> dict[str, str]:
        return {topic: " and ".join(sorted(kinds)) for topic, kinds in self.used.items()}


def _vector(message, name: str) -> np.ndarray:
    v = get(message, name)
    return np.array(
        [float(get(v, "x", np.nan)), float(get(v, "y", np.nan)), float(get(v, "z", np.nan))]
    )


def _increasing(bag: Bag, topic: str, t: np.ndarray, at_least: int = 0) -> None:
    """Times strictly increasing (and at least ``at_least`` of them), else an error naming the
    message."""
    if t.size < at_least:
        raise bag.error(
            topic, int(t.size), f"only {t.size} messages could be read, {at_least} needed"
        )
    bad = np.flatnonzero(np.diff(t) <= 0.0)
    if bad.size:
        k = int(bad[0]) + 1
        raise bag.error(
            topic,
            k,
            f"time {t[k]:.9f} s is not after the previous message's {t[k - 1]:.9f} s "
            "(give --stamps receive, or reorder the bag)",
        )
    if not np.all(np.isfinite(t)):
        raise bag.error(topic, int(np.flatnonzero(~np.isfinite(t))[0]), "time is not finite")


def _read_imu(bag: Bag, topic: str, timing: _Timing):
    t, gyro, accel = [], [], []
    for _, receive_ns, m in bag.messages(topic):
        t.append(timing.time(topic, receive_ns, m))
        gyro.append(_vector(m, "angular_velocity"))
        accel.append(_vector(m, "linear_acceleration"))
    t_arr = np.array(t)
    _increasing(bag, topic, t_arr, 2)
    gyro_arr, accel_arr = np.array(gyro).reshape(-1, 3), np.array(accel).reshape(-1, 3)
    bad = ~np.all(np.isfinite(gyro_arr), axis=1)
    if np.any(bad):
        raise bag.error(topic, int(np.flatnonzero(bad)[0]), "angular velocity is not finite")
    return t_arr, gyro_arr, accel_arr


def _axis(name: str) -> tuple[int, float]:
    return "xyz".index(name[-1]), (-1.0 if name.startswith("-") else 1.0)


def yaw_axis(gyro: np.ndarray, accel: np.ndarray, choice: str) -> tuple[str, str]:
    """The gyro axis of the yaw rate (``z``, ``-y`` …) and how it was chosen."""
    if choice != "auto":
        return choice, "given (--imu-yaw-axis)"
    good = np.all(np.isfinite(accel), axis=1)
    mean = accel[good].mean(axis=0) if np.any(good) else np.zeros(3)
    k = int(np.argmax(np.abs(mean)))
    if abs(mean[k]) >= GRAVITY_MIN_MPS2:
        name = ("-" if mean[k] < 0 else "") + "xyz"[k]
        return name, (
            f"estimated: the mean specific force is {mean[k]:+.2f} m/s² along {'xyz'[k]} "
            f"(gravity), so {name} points up"
        )
    rms = np.sqrt(np.mean(gyro**2, axis=0))
    k = int(np.argmax(rms))
    return "xyz"[k], (
        f"estimated without gravity (no accelerometer data): {'xyz'[k]}, the axis of largest "
        "angular rate; its sign (counter-clockwise positive) is assumed, check it"
    )


def forward_axis(
    t: np.ndarray, accel: np.ndarray, up: str, speed: SensorSeries | None, choice: str
) -> tuple[str, str]:
    """The accelerometer axis along the vehicle's forward direction, or ``none``."""
    if choice != "auto":
        return choice, "given (--imu-forward-axis)"
    if speed is None or len(speed) < 3 or t.size < 3:
        return "none", "no speed topic to estimate it from"
    h = FORWARD_WINDOW_S / 2.0
    inside = (t >= speed.t[0] + h) & (t <= speed.t[-1] - h)
    if inside.sum() < 3:
        return "none", "the IMU does not overlap the speed"
    # the speed's change over the window against the mean specific force over it
    target = np.interp(t + h, speed.t, speed.value) - np.interp(t - h, speed.t, speed.value)
    target = target[inside] / FORWARD_WINDOW_S
    scale = float(np.sqrt(np.mean(target**2)))
    best, best_axis = np.inf, "none"
    for k in range(3):
        if "xyz"[k] == up[-1] or not np.all(np.isfinite(accel[:, k])):
            continue
        a = _window_mean(t, accel[:, k], h)[inside]
        for sign, prefix in ((1.0, ""), (-1.0, "-")):
            misfit = float(np.sqrt(np.mean((sign * a - target) ** 2)))
            if misfit < best:
                best, best_axis = misfit, prefix + "xyz"[k]
    if not best < FORWARD_MAX_MISFIT * scale:
        return "none", (
            f"no horizontal axis follows the speed's change (best misfit {best:.2f} m/s² for "
            f"{scale:.2f} m/s² of acceleration)"
        )
    return best_axis, (
        f"estimated: its 1-s means differ from the speed's change by {best:.2f} m/s² RMS "
        f"(acceleration {scale:.2f} m/s² RMS)"
    )


def _window_mean(t: np.ndarray, values: np.ndarray, h: float) -> np.ndarray:
    """The mean of ``values`` over [t − h, t + h] at each sample (trapezoid integral)."""
    integral = np.concatenate([[0.0], np.cumsum(np.diff(t) * (values[1:] + values[:-1]) / 2)])
    return (np.interp(t + h, t, integral) - np.interp(t - h, t, integral)) / (2.0 * h)


def _read_speed(bag: Bag, topic: str, timing: _Timing) -> SensorSeries:
    t, v = [], []
    for index, receive_ns, m in bag.messages(topic):
        twist = get(m, "twist")
        if get(twist, "twist") is not None:  # Odometry, TwistWithCovarianceStamped
            twist = get(twist, "twist")
        value = float(get(get(twist, "linear"), "x", np.nan))
        if not np.isfinite(value):
            raise bag.error(topic, index, "linear.x is not finite")
        t.append(timing.time(topic, receive_ns, m))
        v.append(value)
    t_arr = np.array(t)
    _increasing(bag, topic, t_arr, 2)
    return SensorSeries(t_arr, np.array(v))


def _read_fixes(bag: Bag, topic: str, timing: _Timing) -> np.ndarray:
    """Rows (ROS time, lat deg, lon deg, height m, status) of the fixes with status ≥ 0."""
    rows = []
    for index, receive_ns, m in bag.messages(topic):
        status = int(get(get(m, "status"), "status", 0))
        lat, lon = float(get(m, "latitude", np.nan)), float(get(m, "longitude", np.nan))
        height = float(get(m, "altitude", np.nan))
        if status < 0 or not np.all(np.isfinite([lat, lon, height])):
            continue
        if abs(lat) > 90.0 or abs(lon) > 180.0:
            raise bag.error(topic, index, f"latitude {lat} or longitude {lon} out of range")
        rows.append((timing.time(topic, receive_ns, m), lat, lon, height, status))
    return np.array(rows, dtype=float).reshape(-1, 5)


def _read_ground_truth(bag: Bag, topic: str, timing: _Timing, enu: EnuFrame) -> Trajectory:
    if bag.msgtype(topic) == "sensor_msgs/msg/NavSatFix":
        fixes = _read_fixes(bag, topic, timing)
        _increasing(bag, topic, fixes[:, 0], 2)
        positions = enu.geodetic_to_enu(
            np.radians(fixes[:, 1]), np.radians(fixes[:, 2]), fixes[:, 3]
        ).reshape(-1, 3)
        return Trajectory(fixes[:, 0], positions, _track_yaw(fixes[:, 0], positions))
    t, positions, quats = [], [], []
    for index, receive_ns, m in bag.messages(topic):
        pose = get(m, "pose")
        if get(pose, "pose") is not None:  # Odometry, PoseWithCovarianceStamped
            pose = get(pose, "pose")
        p = get(pose, "position")
        q = get(pose, "orientation")
        xyz = [float(get(p, a, np.nan)) for a in "xyz"]
        quat = [float(get(q, a, np.nan)) for a in "xyzw"]
        norm = float(np.linalg.norm(quat)) if np.all(np.isfinite(quat)) else 0.0
        if not np.all(np.isfinite(xyz)) or not 0.5 < norm < 1.5:
            raise bag.error(topic, index, "pose position not finite or orientation not a rotation")
        t.append(timing.time(topic, receive_ns, m))
        positions.append(xyz)
        quats.append(quat)
    t_arr = np.array(t)
    _increasing(bag, topic, t_arr, 2)
    rotations = (
        Rotation.from_quat(np.array(quats).reshape(-1, 4)) if quats else Rotation.identity(0)
    )
    return Trajectory(t_arr, np.array(positions).reshape(-1, 3), rotations)


def _track_yaw(t: np.ndarray, positions: np.ndarray) -> Rotation:
    """Yaw along the track (x forward), held through stops."""
    if t.size < 2:
        return Rotation.identity(t.size)
    velocity = np.gradient(positions[:, :2], t, axis=0)
    yaw = np.arctan2(velocity[:, 1], velocity[:, 0])
    moving = np.hypot(velocity[:, 0], velocity[:, 1]) >= HELD_COURSE_SPEED_MPS
    if np.any(moving):
        index = np.where(moving, np.arange(t.size), -1)
        index = np.maximum.accumulate(index)
        first = int(np.flatnonzero(moving)[0])
        index[index < 0] = first
        yaw = yaw[index]
    else:
        yaw = np.zeros(t.size)
    return Rotation.from_euler("z", yaw)


def _transforms(bag: Bag, topic: str) -> dict[str, tuple[str, np.ndarray]]:
    """child frame → (parent frame, T_parent_child) of every transform on the topic."""
    out: dict[str, tuple[str, np.ndarray]] = {}
    for index, _, m in bag.messages(topic):
        for item in get(m, "transforms", ()) or ():
            transform = get(item, "transform")
            translation = _vector(transform, "translation")
            q = get(transform, "rotation")
            quat = np.array([float(get(q, a, np.nan)) for a in "xyzw"])
            if not (np.all(np.isfinite(translation)) and np.all(np.isfinite(quat))) or not (
                0.5 < np.linalg.norm(quat) < 1.5
            ):
                raise bag.error(topic, index, "a transform is not finite or not a rotation")
            T = np.eye(4)
            T[:3, :3] = Rotation.from_quat(quat).as_matrix()
            T[:3, 3] = translation
            parent = str(get(get(item, "header"), "frame_id", "")).lstrip("/")
            out[str(get(item, "child_frame_id", "")).lstrip("/")] = (parent, T)
    return out


def _to_root(frames: dict[str, tuple[str, np.ndarray]], frame: str) -> tuple[str, np.ndarray]:
    T = np.eye(4)
    for _ in range(64):
        if frame not in frames:
            return frame, T
        parent, T_parent_child = frames[frame]
        T = T_parent_child @ T
        frame = parent
    return frame, T


def camera_extrinsic(
    frames: dict[str, tuple[str, np.ndarray]], vehicle: str, camera: str
) -> tuple[np.ndarray, str] | None:
    """``T_vehicle_camera`` from the transform tree, None when the frames are not connected."""
    camera = camera.lstrip("/")
    root_c, T_root_camera = _to_root(frames, camera)
    root_v, T_root_vehicle = _to_root(frames, vehicle)
    if not camera or root_c != root_v or (camera not in frames and vehicle not in frames):
        return None
    return np.linalg.inv(T_root_vehicle) @ T_root_camera, f"tf: {vehicle} → {camera}"


def _camera_info(bag: Bag, topic: str) -> tuple[Camera, str]:
    """Intrinsics of the first CameraInfo message and its frame id."""
    for index, _, m in bag.messages(topic):
        K = np.asarray(get(m, "k", get(m, "K", ())), dtype=float).ravel()
        D = np.asarray(get(m, "d", get(m, "D", ())), dtype=float).ravel()
        model = str(get(m, "distortion_model", "") or "plumb_bob")
        if K.size != 9 or not np.all(np.isfinite(K)) or K[0] <= 0 or K[4] <= 0:
            raise bag.error(topic, index, f"camera matrix K is not 9 finite values ({K.size})")
        if model not in ("plumb_bob", "rational_polynomial") or np.any(D[5:] != 0.0):
            raise bag.error(
                topic,
                index,
                f"distortion model {model!r} (D: {D.size} values) is not "
                "plumb_bob: give the calibration with --calib",
            )
        distortion = np.zeros(5)
        distortion[: min(5, D.size)] = D[:5]
        camera = Camera(
            float(K[0]),
            float(K[4]),
            float(K[2]),
            float(K[5]),
            int(get(m, "width", 0)),
            int(get(m, "height", 0)),
            distortion,
        )
        frame = str(get(get(m, "header"), "frame_id", ""))
        return checked_camera(camera, f"{bag.path} ({topic}, message {index})"), frame
    raise bag.error(topic, 0, "no CameraInfo message")


def _frame_id(bag: Bag, topic: str) -> str:
    for _, _, m in bag.messages(topic):
        return str(get(get(m, "header"), "frame_id", ""))
    return ""


def _write_images(bag: Bag, topic: str, folder: Path, timing: _Timing) -> tuple[np.ndarray, list]:
    """Write every image of the topic; its ROS times, and warnings for undecodable ones."""
    compressed = bag.msgtype(topic).endswith("CompressedImage")
    times, warnings = [], []
    for index, receive_ns, m in bag.messages(topic):
        name = f"{index:06d}"
        if compressed:
            data = bytes(np.asarray(get(m, "data", ()), dtype=np.uint8))
            fmt = str(get(m, "format", "")).lower()
            suffix = ".png" if "png" in fmt or data[:4] == b"\x89PNG" else ".jpg"
            (folder / (name + suffix)).write_bytes(data)
            if cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED) is None:
                warnings.append(
                    f"{bag.path}: topic {topic}, message {index}: the {fmt or 'compressed'} "
                    "image does not decode (run flags and bridges it)"
                )
        else:
            cv2.imwrite(str(folder / (name + ".png")), _raw_image(bag, topic, index, m))
        times.append(timing.time(topic, receive_ns, m))
    t = np.array(times)
    _increasing(bag, topic, t, 2)
    return t, warnings


def _raw_image(bag: Bag, topic: str, index: int, m) -> np.ndarray:
    encoding = str(get(m, "encoding", ""))
    if encoding not in ENCODINGS:
        raise bag.error(
            topic, index, f"image encoding {encoding!r} is not one of {', '.join(ENCODINGS)}"
        )
    dtype, channels, conversion = ENCODINGS[encoding]
    height, width, step = int(get(m, "height", 0)), int(get(m, "width", 0)), int(get(m, "step", 0))
    data = np.asarray(get(m, "data", ()), dtype=np.uint8)
    row = width * channels * np.dtype(dtype).itemsize
    if height <= 0 or width <= 0 or step < row or data.size < step * height:
        raise bag.error(
            topic,
            index,
            f"a {width}×{height} {encoding} image with step {step} "
            f"does not fit its {data.size} bytes",
        )
    rows = data[: step * height].reshape(height, step)[:, :row].copy()
    big = bool(get(m, "is_bigendian", 0))
    pixels = rows.view(np.dtype(dtype).newbyteorder(">" if big else "<")).astype(dtype)
    pixels = pixels.reshape(height, width, channels) if channels > 1 else pixels
    return cv2.cvtColor(pixels, conversion) if conversion is not None else pixels


def clock_offset(
    options: RosbagOptions, start_ros_s: float, gnss_pairs: np.ndarray | None, path: Path
) -> tuple[float, str]:
    """GPS − ROS time (s) and how it was found (``path``, the bag, named in an error)."""
    if options.clock_offset_s is not None:
        return float(options.clock_offset_s), "given (--clock-offset)"
    if options.clock is RosClock.GNSS:
        if gnss_pairs is None or not len(gnss_pairs):
            raise InputError("--clock gnss needs a raw GNSS topic (its epochs and ROS times)", path)
        offset = float(np.median(gnss_pairs[:, 0] - gnss_pairs[:, 1]))
        return offset, (
            f"estimated from {len(gnss_pairs)} GNSS epochs (median GPS epoch − ROS time; the "
            "receiver's output latency included)"
        )
    gps_guess = start_ros_s - UNIX_TIME_AT_GPS_EPOCH_S
    leap = float(gps_minus_utc(gps_guess + 18.0))
    return leap - UNIX_TIME_AT_GPS_EPOCH_S, (
        f"ROS time read as Unix time (UTC): GPS = ROS − {UNIX_TIME_AT_GPS_EPOCH_S:.0f} s + "
        f"{leap:.0f} leap seconds"
    )


def _gnss_pairs(bag: Bag, topic: str, timing: _Timing) -> np.ndarray:
    """(GPS epoch, ROS time) of each raw GNSS message, for ``--clock gnss``."""
    pairs = []
    for _, receive_ns, m in bag.messages(topic):
        if get(m, "meas") and get(get(m, "meas")[0], "time") is not None:
            first = get(get(m, "meas")[0], "time")
            gps = float(get(first, "week", 0)) * 604800.0 + float(get(first, "tow", 0.0))
        else:
            gps = float(get(m, "week", 0)) * 604800.0 + float(get(m, "rcvTOW", 0.0))
        pairs.append((gps, timing.time(topic, receive_ns, m)))
    return np.array(pairs, dtype=float).reshape(-1, 2)


def import_rosbag(
    bag_path: str | Path, output: str | Path, options: RosbagOptions | None = None
) -> RosbagImportSummary:
    """Write the sequence folder ``output`` from the bag (module docstring). Everything but the
    images is read and checked before the folder is opened; the images are then streamed."""
    options = options or RosbagOptions()
    problem = options.problem()
    if problem:
        raise UsageError(problem)
    bag_path, output = Path(bag_path), Path(output)
    check_output_folder(output, "import", [bag_path, options.calib, options.dbc])
    warnings: list[str] = []
    timing = _Timing(options.stamps)
    with Bag(bag_path) as bag:
        topics = bag.topics()
        chosen = discover(topics, options, bag_path)
        _require_motion(topics, chosen, options, bag_path)
        start = bag.start_s()
        gnss = _gnss(bag, chosen)
        pairs = None
        if "gnss" in chosen and options.clock is RosClock.GNSS and options.clock_offset_s is None:
            pairs = _gnss_pairs(bag, str(chosen["gnss"]), timing)
        offset, clock_text = clock_offset(options, start, pairs, bag_path)
        timing.offset = offset
        can = None
        if options.dbc is not None:
            can = read_can_signals(
                bag,
                str(chosen["can"]),
                timing.time,
                options.dbc,
                options.wheel_speed,
                options.yaw_rate,
                options.yaw_rate_sign,
            )
            warnings += can.warnings
        if can is not None and can.speed is not None:
            speed, speed_source = can.speed, can.speed_source
        else:
            speed = _read_speed(bag, str(chosen["speed"]), timing)
            speed_source = f"topic {chosen['speed']}: twist linear.x"
        up, up_text, ahead, ahead_text = "none", "no IMU topic", "none", "no IMU topic"
        acceleration = yaw_rate = None
        yaw_rate_source = "none"
        if "imu" in chosen:
            imu_t, gyro, accel = _read_imu(bag, str(chosen["imu"]), timing)
            up, up_text = yaw_axis(gyro, accel, options.imu_yaw_axis)
            k, sign = _axis(up)
            yaw_rate = SensorSeries(imu_t, sign * gyro[:, k])
            yaw_rate_source = f"topic {chosen['imu']}: gyro {up}"
            ahead, ahead_text = forward_axis(imu_t, accel, up, speed, options.imu_forward_axis)
            if ahead != "none":
                k, sign = _axis(ahead)
                good = np.isfinite(accel[:, k])
                acceleration = SensorSeries(imu_t[good], sign * accel[good, k])
        if can is not None and can.yaw_rate is not None:
            yaw_rate, yaw_rate_source = can.yaw_rate, can.yaw_rate_source
        assert yaw_rate is not None  # _require_motion: an IMU topic or --yaw-rate
        fixes = _read_fixes(bag, str(chosen["fix"]), timing) if "fix" in chosen else None
        origin = _origin(options, fixes, bag, chosen, timing)
        enu = EnuFrame(np.radians(origin[0]), np.radians(origin[1]), origin[2])
        truth = None
        if "ground_truth" in chosen:
            truth = _read_ground_truth(bag, str(chosen["ground_truth"]), timing, enu)
        frames = _transforms(bag, str(chosen["tf"])) if "tf" in chosen else {}
        camera, extrinsic_from = None, "no camera"
        if "image" in chosen:
            camera, extrinsic_from = _camera(bag, chosen, options, frames, warnings)
        lever_arm, lever_arm_from = _lever_arm(bag, chosen, options, frames)
        open_output_folder(output, "import")
        for sub in (
            "vehicle",
            "imu" if acceleration is not None else None,
            "gnss" if gnss else None,
        ):
            if sub:
                (output / sub).mkdir(exist_ok=True)
        image_times = np.zeros(0)
        if camera is not None:
            (output / IMAGES).mkdir(exist_ok=True)
            image_times, image_warnings = _write_images(
                bag, str(chosen["image"]), output / IMAGES, timing
            )
            warnings += image_warnings
    manifest = _manifest(bag_path, output, origin, camera is not None, acceleration)
    if camera is not None:
        np.savetxt(output / TIMES, image_times, fmt="%.9f")
        write_camera_yaml(output / CALIB, camera)
    write_sensor_csv(output / YAW_RATE_CSV, yaw_rate, YAW_RATE_COLUMN)
    write_sensor_csv(output / SPEED_CSV, speed, SPEED_COLUMN)
    if acceleration is not None:
        write_sensor_csv(output / ACCELERATION_CSV, acceleration, FORWARD_ACCELERATION_COLUMN)
    if fixes is not None:
        (output / FIXES).parent.mkdir(exist_ok=True)
        np.savetxt(
            output / FIXES,
            fixes,
            fmt="%.9f",
            delimiter=",",
            header="gps_time_s,lat_deg,lon_deg,height_m,status",
            comments="",
        )
    if truth is not None:
        write_tum(output / GROUND_TRUTH, truth)
        manifest["ground_truth"] = {"trajectory": GROUND_TRUTH}
    gnss_epochs = 0
    if gnss is not None:
        approx = enu.origin_ecef
        if fixes is not None and len(fixes):
            approx = geodetic_to_ecef(np.radians(fixes[0, 1]), np.radians(fixes[0, 2]), fixes[0, 3])
        gnss_epochs = _write_gnss(output, gnss, approx, lever_arm, bag_path, manifest, warnings)
        if "gnss" in manifest:
            manifest["gnss"]["antenna_lever_arm_m"] = lever_arm
    for text in warnings:
        log.warning(text)
    manifest["rosbag"] = {
        "bag": str(bag_path),
        "topics": {k: v for k, v in chosen.items()},
        "times": timing.described(),
        "clock": clock_text,
        "gps_minus_ros_s": offset,
        "imu_yaw_axis": f"{up}: {up_text}",
        "imu_forward_axis": f"{ahead}: {ahead_text}",
        "yaw_rate": yaw_rate_source,
        "speed": speed_source,
        "camera_extrinsic": extrinsic_from,
        "antenna_lever_arm": lever_arm_from,
        "gnss": gnss.source if gnss else "none",
        "warnings": warnings,
    }
    (output / MANIFEST).write_text(yaml.safe_dump(manifest, sort_keys=False, allow_unicode=True))
    return RosbagImportSummary(
        output,
        bag_path,
        {k: str(v) for k, v in chosen.items()},
        int(image_times.size),
        gnss_epochs,
        len(gnss.ephemerides) if gnss else 0,
        len(yaw_rate),
        len(speed),
        speed_source,
        yaw_rate_source,
        len(truth) if truth is not None else 0,
        clock_text,
        offset,
        options.stamps,
        f"{up} ({up_text})",
        f"{ahead} ({ahead_text})",
        extrinsic_from,
        warnings,
    )


def _require_motion(topics: list[Topic], chosen: dict, options: RosbagOptions, path: Path):
    """An :class:`InputError` unless the bag gives a yaw rate (an IMU topic, or a CAN topic
    with ``--yaw-rate``) and a speed (a speed topic, or a CAN topic with ``--wheel-speed``),
    saying what is missing."""
    can = [t.name for t in topics if t.msgtype in KINDS["can"] and t.count]
    if options.dbc is not None and "can" not in chosen:
        raise InputError(
            "--dbc is given but the bag has no can_msgs/Frame topic (see --list-topics)", path
        )

    def hint(option: str) -> str:
        return f"; its CAN topic {can[0]} gives one with --dbc FILE {option} MSG.SIG" if can else ""

    if options.yaw_rate is None and "imu" not in chosen:
        raise InputError(
            "the sequence needs a yaw rate: the bag has no sensor_msgs/Imu topic"
            f"{hint('--yaw-rate')} (see --list-topics)",
            path,
        )
    if options.wheel_speed is None and "speed" not in chosen:
        raise InputError(
            "the sequence needs a speed: the bag has no TwistStamped, "
            f"TwistWithCovarianceStamped or Odometry topic{hint('--wheel-speed')} (see "
            "--list-topics)",
            path,
        )


def _gnss(bag: Bag, chosen: dict) -> BagGnss | None:
    if "gnss" not in chosen:
        return None
    topic = str(chosen["gnss"])
    ephemeris = list(chosen.get("ephemeris", []))
    if bag.msgtype(topic).startswith("gnss_comm/"):
        return read_gnss_comm(bag, topic, ephemeris, chosen.get("iono"))
    sfrbx = next((t for t in ephemeris if bag.msgtype(t).endswith("RxmSFRBX")), None)
    return read_ublox(bag, topic, sfrbx)


def _origin(options, fixes, bag: Bag, chosen: dict, timing: _Timing) -> tuple[float, float, float]:
    if options.origin is not None:
        return options.origin
    candidates = [fixes]
    truth = chosen.get("ground_truth")
    if truth and bag.msgtype(str(truth)) == "sensor_msgs/msg/NavSatFix":
        candidates.append(_read_fixes(bag, str(truth), timing))
    for rows in candidates:
        if rows is not None and len(rows):
            return float(rows[0, 1]), float(rows[0, 2]), float(rows[0, 3])
    raise InputError(
        "no NavSatFix topic with a fix for the origin of the ENU frame: give --origin LAT,LON,H",
        bag.path,
    )


def _lever_arm(bag: Bag, chosen: dict, options: RosbagOptions, frames) -> tuple[list, str]:
    """The GNSS antenna in the vehicle frame from tf: the frame ``--gnss-frame``, or the
    NavSatFix topic's ``frame_id``; [0, 0, 0] when tf does not connect it."""
    frame = options.gnss_frame
    if frame is None and "fix" in chosen:
        frame = _frame_id(bag, str(chosen["fix"]))
    found = camera_extrinsic(frames, options.vehicle_frame, frame) if frame else None
    if found is None:
        return [0.0, 0.0, 0.0], f"no transform from {options.vehicle_frame} to a GNSS frame: 0"
    return [float(v) for v in found[0][:3, 3]], f"tf: {options.vehicle_frame} → {frame}"


def _camera(bag: Bag, chosen: dict, options: RosbagOptions, frames, warnings: list[str]):
    if options.calib is not None:
        return read_camera(options.calib), f"--calib {options.calib}"
    if "camera_info" not in chosen:
        raise InputError(
            "no sensor_msgs/CameraInfo topic for the camera's calibration: give --calib FILE",
            bag.path,
        )
    intrinsics, frame = _camera_info(bag, str(chosen["camera_info"]))
    frame = frame or _frame_id(bag, str(chosen["image"]))
    found = camera_extrinsic(frames, options.vehicle_frame, frame)
    if found is None:
        warnings.append(
            f"{bag.path}: no transform from {options.vehicle_frame} to the camera frame "
            f"{frame!r}: the camera is taken as looking forward from the vehicle origin"
        )
        extrinsic, source = CAMERA_TO_VEHICLE_FORWARD.copy(), "assumed: a forward camera"
    else:
        extrinsic, source = found
    return checked_camera(replace(intrinsics, T_vehicle_camera=extrinsic), bag.path), source


def _write_gnss(
    output: Path, gnss: BagGnss, approx, lever_arm, bag_path: Path, manifest, warnings
) -> int:
    obs = gnss.observations
    warnings.extend(gnss.problems)
    if not len(obs):
        warnings.append(f"{bag_path}: the GNSS topic holds no measurement: no gnss section")
        return 0
    epochs = observation_epochs(obs)
    interval = float(np.median(np.diff(epochs.epoch_time))) if epochs.epoch_time.size > 1 else 0.0
    write_obs(
        output / OBS,
        epochs,
        approx,
        interval,
        marker_name=bag_path.stem or "ROSBAG",
        receiver=gnss.source.split(" ")[0],
        program="vo-doppler import",
        observer="ROS bag",
        antenna="UNKNOWN",
        antenna_height_m=lever_arm[2],
        glonass_channels=obs.header.glonass_channels,
    )
    if not gnss.ephemerides:
        warnings.append(
            f"{bag_path}: no ephemeris in the bag: {OBS} written, but no "
            "gnss section (add gnss.nav or gnss.orbits by hand)"
        )
        return len(epochs.epoch_time)
    leap = int(gps_minus_utc(float(epochs.epoch_time[0])))
    write_nav(output / NAV, gnss.ephemerides, leap_seconds=leap, klobuchar=gnss.klobuchar)
    section = {"obs": OBS, "nav": [NAV], "time_offset_s": 0.0}
    if gnss.doppler_sigma is not None and len(gnss.doppler_sigma):
        write_doppler_sigma(output / SIGMA, gnss.doppler_sigma)
        section["doppler_sigma"] = SIGMA
    manifest["gnss"] = section
    return len(epochs.epoch_time)


def _manifest(bag_path: Path, output: Path, origin, has_camera: bool, acceleration):
    manifest: dict = {
        "format": FORMAT,
        "name": output.name,
        "source": f"ROS bag {bag_path} (vo-doppler import rosbag)",
        "origin": {"lat_deg": origin[0], "lon_deg": origin[1], "height_m": origin[2]},
    }
    if has_camera:
        manifest["camera"] = {
            "images": IMAGES,
            "times": TIMES,
            "calib": CALIB,
            "time_offset_s": 0.0,
        }
    manifest["vehicle"] = {
        "yaw_rate": YAW_RATE_CSV,
        "wheel_speed": SPEED_CSV,
        "time_offset_s": 0.0,
    }
    if acceleration is not None:
        manifest["imu"] = {"forward_acceleration": ACCELERATION_CSV, "time_offset_s": 0.0}
    return manifest
