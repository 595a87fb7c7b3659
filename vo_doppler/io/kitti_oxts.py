"""KITTI raw OXTS folders: ``oxts/timestamps.txt`` and ``oxts/data/NNNNNNNNNN.txt``.

Each data file holds one line of 30 numbers from the OXTS RT3003 (Geiger et al., "Vision meets
robotics: the KITTI dataset", IJRR 2013, Table 3 / the raw-data devkit's ``dataformat.txt``):
lat lon alt (deg, deg, m), roll pitch yaw (rad; yaw 0 = east, counter-clockwise), vn ve vf vl vu
(m/s), ax ay az af al au (m/s²), wx wy wz wf wl wu (rad/s), pos_accuracy vel_accuracy (m, m/s),
navstat numsats posmode velmode orimode.

Poses follow the devkit's ``convertOxtsToPose``: a Mercator projection whose scale
s = cos(lat₀) is fixed by the first frame's latitude, x = s·R_e·lon, y = s·R_e·ln tan(π/4 + lat/2)
(R_e = 6378137 m), z = alt; the rotation R = R_z(yaw)·R_y(pitch)·R_x(roll); each pose is then
expressed relative to the first one: T_i ← T_0⁻¹·T_i. Vehicle signals: yaw rate ``wz`` (rad/s,
about the vehicle's up axis) and forward speed ``vf`` (m/s) as ``SensorSeries``.

Times: ``timestamps.txt`` holds calendar times with nanoseconds; KITTI does not name their time
scale, so they are read as UTC and converted to GPS seconds with the leap seconds of the date
(differences between frames are exact whatever the scale).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.model.gpstime import calendar_to_gps_seconds, utc_to_gps_seconds
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory

EARTH_RADIUS_M = 6378137.0
OXTS_FIELDS = (
    *("lat", "lon", "alt", "roll", "pitch", "yaw", "vn", "ve", "vf", "vl", "vu"),
    *("ax", "ay", "az", "af", "al", "au", "wx", "wy", "wz", "wf", "wl", "wu"),
    *("pos_accuracy", "vel_accuracy", "navstat", "numsats", "posmode", "velmode", "orimode"),
)
_TIMESTAMP = re.compile(r"^(\d{4})-(\d\d)-(\d\d) (\d\d):(\d\d):(\d\d)(?:\.(\d{1,9}))?$")
_LIMITS = {"lat": 90.0, "lon": 180.0, "roll": np.pi, "pitch": np.pi, "yaw": np.pi + 1e-6}


@dataclass(frozen=True)
class OxtsRecord:
    """One OXTS folder: GPS times, the devkit's relative poses, vehicle signals, raw fields."""

    t: np.ndarray
    poses: np.ndarray
    yaw_rate: SensorSeries
    speed: SensorSeries
    fields: dict[str, np.ndarray]
    path: Path

    def trajectory(self) -> Trajectory:
        """The poses as a trajectory (first pose at the origin, x along its heading)."""
        return Trajectory.from_matrices(self.t, self.poses)


def read_oxts(folder: str | Path) -> OxtsRecord:
    """Read a KITTI raw ``oxts`` folder (the one holding ``timestamps.txt`` and ``data/``)."""
    folder = Path(folder)
    t = read_timestamps(folder / "timestamps.txt")
    files = sorted((folder / "data").glob("*.txt"))
    if len(files) != t.size:
        raise InputError(
            f"{len(files)} OXTS data files for {t.size} timestamps", folder / "timestamps.txt"
        )
    if not files:
        raise InputError("no OXTS data files", folder / "data")
    values = np.stack([_read_packet(path) for path in files])
    fields = {name: values[:, k] for k, name in enumerate(OXTS_FIELDS)}
    return OxtsRecord(
        t=t,
        poses=oxts_poses(fields["lat"], fields["lon"], fields["alt"], values[:, 3:6]),
        yaw_rate=SensorSeries(t, fields["wz"], "yaw_rate", "rad/s"),
        speed=SensorSeries(t, fields["vf"], "speed", "m/s"),
        fields=fields,
        path=folder,
    )


def read_timestamps(path: Path) -> np.ndarray:
    """``YYYY-MM-DD hh:mm:ss.nnnnnnnnn`` lines to GPS seconds (strictly increasing)."""
    try:
        lines = path.read_text(encoding="ascii").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read timestamps: {exc}", path) from exc
    whole, fraction = [], []
    for number, line in enumerate(lines, start=1):
        match = _TIMESTAMP.match(line.strip())
        if match is None:
            raise InputError(f"not a timestamp: {line.strip()[:40]!r}", path, number)
        y, mo, d, h, mi, s, nanos = match.groups()
        if not (1 <= int(mo) <= 12 and 1 <= int(d) <= 31 and int(h) < 24 and int(mi) < 60):
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


def _rx(a: np.ndarray) -> np.ndarray:
    c, s, one, zero = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([one, zero, zero, zero, c, -s, zero, s, c], axis=-1).reshape(-1, 3, 3)


def _ry(a: np.ndarray) -> np.ndarray:
    c, s, one, zero = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([c, zero, s, zero, one, zero, -s, zero, c], axis=-1).reshape(-1, 3, 3)


def _rz(a: np.ndarray) -> np.ndarray:
    c, s, one, zero = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([c, -s, zero, s, c, zero, zero, zero, one], axis=-1).reshape(-1, 3, 3)
