"""KITTI raw OXTS folders: ``oxts/timestamps.txt`` and ``oxts/data/NNNNNNNNNN.txt``.

Each data file holds one line of 30 numbers from the OXTS RT3003 (Geiger et al., "Vision meets
robotics: the KITTI dataset", IJRR 2013, Table 3 / the raw-data devkit's ``dataformat.txt``):
lat lon alt (deg, deg, m), roll pitch yaw (rad; yaw 0 = east, counter-clockwise), vn ve vf vl vu
(m/s), ax ay az af al au (m/s²), wx wy wz wf wl wu (rad/s), pos_accuracy vel_accuracy (m, m/s),
navstat numsats posmode velmode orimode.

Poses follow the devkit's ``convertOxtsToPose``: a Mercator projection whose scale
s = cos(lat₀) is fixed by the first frame's latitude, x = s·R_e·lon, y = s·R_e·ln tan(π/4 + lat/2)
(R_e = 6378137 m), z = alt; the rotation R = R_z(yaw)·R_y(pitch)·R_x(roll); each pose is then
expressed relative to the first one: T_i ← T_0⁻¹·T_i. Every field is checked against what a road
vehicle's OXTS can report (``BOUNDS``: height, speeds, accelerations, angular rates). Vehicle
signals: yaw rate ``wz`` (rad/s, about the vehicle's up axis) and forward speed ``vf`` (m/s) as
``SensorSeries``.

ENU poses (:meth:`OxtsRecord.enu_trajectory`, what ``vo-doppler import kitti-raw`` writes as
ground truth): each fix (lat, lon, alt; alt taken as the ellipsoidal height, which KITTI does not
state: a geoid offset only moves the frame's height) goes through ECEF into the east-north-up
frame of an origin, by default the first fix; the orientation is R_z(yaw)·R_y(pitch)·R_x(roll),
the vehicle frame (x forward, y left, z up, dataformat.txt: roll positive left side up, pitch
positive front down, yaw 0 = east counter-clockwise) in the local level frame of the fix, turned
into the origin's ENU axes. The devkit's Mercator plane is not that frame: its distances are on
a sphere of radius R_e scaled by cos(lat₀), off the WGS 84 ground distances by −0.19 % east and
+0.10 % north at Karlsruhe's 49° (growing with sec(lat)/sec(lat₀) away from the first fix), and
its poses are relative to the first pose's heading, not to east and north.

Times: ``timestamps.txt`` holds calendar times with nanoseconds; KITTI does not name their time
scale, so they are read as UTC and converted to GPS seconds with the leap seconds of the date
(differences between frames are exact whatever the scale).

Subsampled drives: data file ``NNNNNNNNNN.txt`` is frame NNNNNNNNNN, timed by line NNNNNNNNNN + 1
of ``timestamps.txt``. Some published drives keep the full timestamp list but only some of the
data files (the kitti_raw_mini fixture: 108 timestamps, 5 files): the frames that exist are
read, each with its own line, and a warning names both counts (:func:`match_frame_files`). A
file whose number has no timestamp line, or a name that is not a frame number, is an error.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.bounds import (
    ANGULAR_RATE,
    FORWARD_ACCELERATION,
    HEIGHT,
    SPEED,
    VELOCITY_COMPONENT,
    SignalBounds,
)
from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame, ecef_to_enu_rotation, geodetic_to_ecef
from vo_doppler.model.gpstime import calendar_to_gps_seconds, utc_to_gps_seconds
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory

log = logging.getLogger(__name__)

EARTH_RADIUS_M = 6378137.0
OXTS_FIELDS = (
    *("lat", "lon", "alt", "roll", "pitch", "yaw", "vn", "ve", "vf", "vl", "vu"),
    *("ax", "ay", "az", "af", "al", "au", "wx", "wy", "wz", "wf", "wl", "wu"),
    *("pos_accuracy", "vel_accuracy", "navstat", "numsats", "posmode", "velmode", "orimode"),
)
_TIMESTAMP = re.compile(r"^(\d{4})-(\d\d)-(\d\d) (\d\d):(\d\d):(\d\d)(?:\.(\d{1,9}))?$")
_FRAME_NAME = re.compile(r"^\d{1,10}$")
_LIMITS = {"lat": 90.0, "lon": 180.0, "roll": np.pi, "pitch": np.pi, "yaw": np.pi + 1e-6}
BOUNDS: dict[str, SignalBounds] = {
    "alt": HEIGHT,
    "vf": SPEED,
    **dict.fromkeys(("vn", "ve", "vl", "vu"), VELOCITY_COMPONENT),
    **dict.fromkeys(("ax", "ay", "az", "af", "al", "au"), FORWARD_ACCELERATION),
    **dict.fromkeys(("wx", "wy", "wz", "wf", "wl", "wu"), ANGULAR_RATE),
}
"""What a road vehicle's OXTS can report (:mod:`vo_doppler.bounds`): a packet with
a value beyond is an error naming the file and the field."""


@dataclass(frozen=True)
class OxtsRecord:
    """One OXTS folder: GPS times, the devkit's relative poses, vehicle signals, raw fields,
    the frame number of every row and what reading it warned about (a subsampled drive)."""

    t: np.ndarray
    poses: np.ndarray
    yaw_rate: SensorSeries
    speed: SensorSeries
    fields: dict[str, np.ndarray]
    path: Path
    frames: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    """Frame number (the data file's NNNNNNNNNN) of each row."""
    warnings: tuple[str, ...] = ()
    n_timestamps: int = 0
    """Lines of ``timestamps.txt`` (more than rows in a subsampled drive)."""

    def trajectory(self) -> Trajectory:
        """The poses as a trajectory (first pose at the origin, x along its heading)."""
        return Trajectory.from_matrices(self.t, self.poses)

    def origin(self) -> EnuFrame:
        """The ENU frame at the first fix (lat, lon, alt as the ellipsoidal height)."""
        lat, lon, alt = (float(self.fields[name][0]) for name in ("lat", "lon", "alt"))
        return EnuFrame(np.radians(lat), np.radians(lon), alt)

    def enu_trajectory(self, frame: EnuFrame | None = None) -> Trajectory:
        """Vehicle poses (x forward, y left, z up) in the ENU frame ``frame`` (default: the
        first fix's), through ECEF (module docstring); not the devkit's Mercator poses."""
        return oxts_enu_trajectory(self.t, self.fields, frame or self.origin())


def read_oxts(folder: str | Path) -> OxtsRecord:
    """Read a KITTI raw ``oxts`` folder (the one holding ``timestamps.txt`` and ``data/``): the
    data files that exist, each timed by the line of its frame number (module docstring)."""
    folder = Path(folder)
    stamps = folder / "timestamps.txt"
    all_t = read_timestamps(stamps)
    frames, files, warning = match_frame_files(folder / "data", (".txt",), all_t.size, stamps)
    t = all_t[frames]
    values = np.stack([_read_packet(path) for path in files])
    fields = {name: values[:, k] for k, name in enumerate(OXTS_FIELDS)}
    return OxtsRecord(
        t=t,
        poses=oxts_poses(fields["lat"], fields["lon"], fields["alt"], values[:, 3:6]),
        yaw_rate=SensorSeries(t, fields["wz"], "yaw_rate", "rad/s"),
        speed=SensorSeries(t, fields["vf"], "speed", "m/s"),
        fields=fields,
        path=folder,
        frames=frames,
        warnings=(warning,) if warning else (),
        n_timestamps=int(all_t.size),
    )


def match_frame_files(
    folder: Path, suffixes: tuple[str, ...], n_stamps: int, stamps: Path
) -> tuple[np.ndarray, list[Path], str | None]:
    """The KITTI frame files of ``folder`` (names ``NNNNNNNNNN`` + one of ``suffixes``), sorted
    by frame number, their numbers, and a warning when fewer exist than ``stamps`` (a
    timestamps file of ``n_stamps`` lines) times: frame k is timed by line k + 1.

    An :class:`InputError` names the folder when it has no frame file, or the file whose name
    is not a frame number or whose number has no line in ``stamps``."""
    if not folder.is_dir():
        raise InputError("no data folder", folder)
    numbered = []
    for path in folder.iterdir():
        if path.suffix.lower() not in suffixes:
            continue
        if not _FRAME_NAME.match(path.stem):
            raise InputError("not a KITTI frame file name (NNNNNNNNNN)", path)
        frame = int(path.stem)
        if frame >= n_stamps:
            raise InputError(f"frame {frame} has no timestamp: {stamps} has {n_stamps} lines", path)
        numbered.append((frame, path))
    if not numbered:
        raise InputError(f"no KITTI frame files ({', '.join(suffixes)})", folder)
    numbered.sort()
    frames = np.array([frame for frame, _ in numbered], dtype=int)
    if np.any(np.diff(frames) == 0):
        twice = int(frames[np.flatnonzero(np.diff(frames) == 0)[0]])
        names = [p.name for f, p in numbered if f == twice]
        raise InputError(f"frame {twice} is given twice ({', '.join(names)})", folder)
    warning = None
    if frames.size < n_stamps:
        warning = (
            f"{folder}: {frames.size} data files for the {n_stamps} timestamps of {stamps} "
            f"(a subsampled drive): the {frames.size} frames that exist are used, each with "
            "the timestamp line of its number"
        )
        log.warning("%s", warning)
    return frames, [path for _, path in numbered], warning


def read_timestamps(path: Path) -> np.ndarray:
    """``YYYY-MM-DD hh:mm:ss.nnnnnnnnn`` lines to GPS seconds (strictly increasing)."""
    try:
        lines = path.read_text(encoding="ascii").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read timestamps: {exc}", path) from exc
    while lines and not lines[-1].strip():  # blank lines at the end only: inside, a blank
        lines.pop()  # line would shift the frame numbers of the lines after it
    if not lines:
        raise InputError("no timestamps", path)
    whole, fraction = [], []
    for number, line in enumerate(lines, start=1):
        match = _TIMESTAMP.match(line.strip())
        if match is None:
            raise InputError(f"not a timestamp: {line.strip()[:40]!r}", path, number)
        y, mo, d, h, mi, s, nanos = match.groups()
        if (
            not (1 <= int(mo) <= 12 and 1 <= int(d) <= 31 and int(h) < 24 and int(mi) < 60)
            or int(s) > 60
        ):
            raise InputError(f"date or time out of range: {line.strip()!r}", path, number)
        whole.append(calendar_to_gps_seconds(int(y), int(mo), int(d), int(h), int(mi), int(s)))
        fraction.append(int((nanos or "0").ljust(9, "0")) * 1e-9)
    t = utc_to_gps_seconds(np.asarray(whole, dtype=float)) + np.asarray(fraction)
    steps = np.diff(t)
    if np.any(steps <= 0):
        line = int(np.flatnonzero(steps <= 0)[0]) + 2
        raise InputError("timestamps do not increase", path, line)
    return t


def _read_packet(path: Path) -> np.ndarray:
    try:
        text = path.read_text(encoding="ascii")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read OXTS packet: {exc}", path) from exc
    lines = [line for line in text.splitlines() if line.strip()]
    if len(lines) != 1:
        raise InputError(f"expected one line of {len(OXTS_FIELDS)} numbers", path)
    try:
        values = np.array([float(v) for v in lines[0].split()])
    except ValueError as exc:
        raise InputError(f"not a number: {exc}", path, 1) from exc
    if values.size != len(OXTS_FIELDS):
        raise InputError(f"{values.size} numbers, expected {len(OXTS_FIELDS)}", path, 1)
    if not np.all(np.isfinite(values)):
        raise InputError("non-finite value", path, 1)
    for name, limit in _LIMITS.items():
        value = values[OXTS_FIELDS.index(name)]
        if abs(value) > limit:
            raise InputError(f"{name} = {value} out of range", path, 1)
    for name, bounds in BOUNDS.items():
        value = values[OXTS_FIELDS.index(name)]
        if bounds.outside(np.array([value]))[0]:
            raise InputError(f"{name} = {value:g} is outside {bounds}", path, 1)
    return values


def oxts_poses(lat_deg, lon_deg, alt, roll_pitch_yaw) -> np.ndarray:
    """(N, 4, 4) poses relative to the first, by the devkit's Mercator convention (docstring)."""
    lat, lon = np.radians(lat_deg), np.radians(lon_deg)
    scale = np.cos(lat[0])
    poses = np.tile(np.eye(4), (lat.size, 1, 1))
    poses[:, 0, 3] = scale * EARTH_RADIUS_M * lon
    poses[:, 1, 3] = scale * EARTH_RADIUS_M * np.log(np.tan(np.pi / 4 + lat / 2))
    poses[:, 2, 3] = alt
    roll, pitch, yaw = np.asarray(roll_pitch_yaw, dtype=float).T
    poses[:, :3, :3] = _rz(yaw) @ _ry(pitch) @ _rx(roll)
    return np.linalg.inv(poses[0]) @ poses


def oxts_enu_trajectory(
    t: np.ndarray, fields: dict[str, np.ndarray], frame: EnuFrame
) -> Trajectory:
    """Vehicle poses in the ENU frame ``frame`` from the OXTS fields (module docstring): the
    positions through ECEF, the rotation R_z(yaw)·R_y(pitch)·R_x(roll) of each fix's local
    level frame turned into the frame's axes."""
    lat, lon = np.radians(fields["lat"]), np.radians(fields["lon"])
    ecef = geodetic_to_ecef(lat, lon, fields["alt"])
    positions = frame.ecef_to_enu(np.asarray(ecef).reshape(-1, 3))
    local = _rz(fields["yaw"]) @ _ry(fields["pitch"]) @ _rx(fields["roll"])
    # local ENU at each fix → ECEF → the frame's ENU
    to_frame = np.stack(
        [frame.rotation @ ecef_to_enu_rotation(a, b).T for a, b in zip(lat, lon, strict=True)]
    )
    return Trajectory(t, positions, Rotation.from_matrix(to_frame @ local))


def _rx(a: np.ndarray) -> np.ndarray:
    c, s, one, zero = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([one, zero, zero, zero, c, -s, zero, s, c], axis=-1).reshape(-1, 3, 3)


def _ry(a: np.ndarray) -> np.ndarray:
    c, s, one, zero = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([c, zero, s, zero, one, zero, -s, zero, c], axis=-1).reshape(-1, 3, 3)


def _rz(a: np.ndarray) -> np.ndarray:
    c, s, one, zero = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([c, -s, zero, s, c, zero, zero, zero, one], axis=-1).reshape(-1, 3, 3)
