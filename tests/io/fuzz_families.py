"""Reader families for the fuzz harness (``tests/fuzz``): CAN logs in four formats, DBCs, the
sensor/gyro/GPS CSVs, NMEA, TUM/KITTI trajectories, heading tables, calibrations, times files and
``sequence.yaml``. Each family: seed files, a ``read(path)`` and a ``check(result, path)`` that
lists impossible values in a successful read.

The harness registers them with one line::

    register_all(register, Family, Seed)

(``register``, ``Family`` and ``Seed`` as the harness defines them: ``Family(name, seeds, read,
check)`` and ``Seed(name, load, pack=..., suffix=...)``).
"""

from __future__ import annotations

import contextlib
import io
import tempfile
from collections.abc import Callable
from pathlib import Path

import can
import numpy as np

from tests.conftest import REPO_ROOT, shared_data_dir
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.can import read_can_motion
from vo_doppler.io.doppler_sigma import read_doppler_sigma
from vo_doppler.io.gps_fixes import read_gps_fixes
from vo_doppler.io.heading_csv import COLUMNS, read_heading_csv
from vo_doppler.io.images import read_times
from vo_doppler.io.sensor_csv import read_speed_csv, read_yaw_rate_csv
from vo_doppler.io.sequence import read_sequence
from vo_doppler.io.trajectory import read_trajectory

SAMPLE = REPO_ROOT / "sample_sequences" / "urban_canyon_small"
SAMPLE_DBC = SAMPLE / "can" / "vehicle.dbc"
SAMPLE_SIGNALS = (
    "VEHICLE_DYNAMICS.YAW_RATE",
    "WHEEL_SPEEDS.WHEEL_SPEED_RL,WHEEL_SPEEDS.WHEEL_SPEED_RR",
)
COMMA = "comma2k19_example1"
COMMA_SIGNALS = (
    "KINEMATICS.YAW_RATE",
    "WHEEL_SPEEDS.WHEEL_SPEED_FL,WHEEL_SPEEDS.WHEEL_SPEED_FR",
)


def _file(path: Path) -> Callable[[], bytes]:
    return path.read_bytes


WRITABLE_TIMESTAMPS_S = (0.0, 4.0e9)
"""Timestamps every python-can writer can store (BLF keeps calendar dates, up to 2096)."""


def _as_format(suffix: str) -> Callable[[bytes], bytes]:
    """Pack candump text as another python-can format (the text is what gets mutated). A
    message whose timestamp the format cannot store is left out when writing fails on it."""

    def pack(data: bytes) -> bytes:
        with tempfile.TemporaryDirectory() as folder:
            source, target = Path(folder) / "in.log", Path(folder) / f"out{suffix}"
            source.write_bytes(data)
            messages = []
            with contextlib.suppress(ValueError, IndexError, UnicodeDecodeError):
                messages.extend(can.CanutilsLogReader(str(source)))  # stops where unreadable
            try:
                _write(target, messages)
            except (OverflowError, ValueError, OSError):
                low, high = WRITABLE_TIMESTAMPS_S
                _write(target, [m for m in messages if low <= m.timestamp <= high])
            return target.read_bytes()

    return pack


def _write(target: Path, messages: list) -> None:
    with can.Logger(str(target)) as writer:
        for message in messages:
            writer.on_message_received(message)


def _times_ok(t: np.ndarray, what: str) -> list[str]:
    t = np.asarray(t, dtype=float)
    bad = [] if np.isfinite(t).all() else [f"{what} times not finite"]
    if t.size > 1 and not (np.diff(t) > 0).all():
        bad.append(f"{what} times not strictly increasing")
    return bad


def _finite(values, what: str) -> list[str]:
    return [] if np.isfinite(np.asarray(values, dtype=float)).all() else [f"{what} not finite"]


def can_seeds(seed_cls) -> list:
    seeds = [
        seed_cls("vehicle.log", _file(SAMPLE / "can" / "vehicle.log"), suffix=".log"),
        seed_cls("vehicle.asc", _file(SAMPLE / "can" / "vehicle.log"), _as_format(".asc"), ".asc"),
        seed_cls("vehicle.blf", _file(SAMPLE / "can" / "vehicle.log"), _as_format(".blf"), ".blf"),
        seed_cls("vehicle.csv", _file(SAMPLE / "can" / "vehicle.log"), _as_format(".csv"), ".csv"),
    ]
    comma = shared_data_dir() / COMMA / "can_motion.log"
    if comma.is_file():
        seeds.append(seed_cls("comma can_motion.log", _file(comma), suffix="_comma.log"))
    return seeds


def read_can(path: Path):
    if path.name.endswith("_comma.log"):
        dbc, signals = shared_data_dir() / COMMA / "toyota_2017_motion.dbc", COMMA_SIGNALS
    else:
        dbc, signals = SAMPLE_DBC, SAMPLE_SIGNALS
    return read_can_motion(path, dbc, *signals)


def check_can(motion, path: Path) -> list[str]:
    bad = []
    for name, series in (("yaw rate", motion.yaw_rate), ("speed", motion.speed)):
        if series is not None:
            bad += _times_ok(series.t, name) + _finite(series.value, name)
            if len(series) and np.abs(series.value).max() > 1000.0:
                bad.append(f"{name} beyond any DBC range")
    return bad


def dbc_seeds(seed_cls) -> list:
    seeds = [seed_cls("vehicle.dbc", _file(SAMPLE_DBC), suffix=".dbc")]
    comma = shared_data_dir() / COMMA / "toyota_2017_motion.dbc"
    if comma.is_file():
        seeds.append(seed_cls("toyota_2017_motion.dbc", _file(comma), suffix=".dbc"))
    return seeds


def read_dbc_and_decode(path: Path):
    """The DBC decoding the sample's log when it still names the signals (else only loaded)."""
    from vo_doppler.io.can import load_dbc

    db = load_dbc(path)
    names = {m.name for m in db.messages}
    if {"VEHICLE_DYNAMICS", "WHEEL_SPEEDS"} <= names:
        try:
            return read_can_motion(SAMPLE / "can" / "vehicle.log", path, *SAMPLE_SIGNALS)
        except Exception as exc:  # a project error is fine, anything else is re-raised
            from vo_doppler.errors import VoDopplerError

            if isinstance(exc, VoDopplerError):
                return db
            raise
    return db


def check_dbc(result, path: Path) -> list[str]:
    return check_can(result, path) if hasattr(result, "yaw_rate") else []


def _sample_motion():
    return read_can_motion(SAMPLE / "can" / "vehicle.log", SAMPLE_DBC, *SAMPLE_SIGNALS)


def _csv(header: str, columns: list[np.ndarray]) -> Callable[[], bytes]:
    def load() -> bytes:
        out = io.StringIO()
        np.savetxt(
            out, np.column_stack(columns()), fmt="%.9f", delimiter=",", header=header, comments=""
        )
        return out.getvalue().encode()

    return load


def sensor_seeds(seed_cls) -> list:
    speed = _csv("t,speed_mps", lambda: [_sample_motion().speed.t, _sample_motion().speed.value])
    return [seed_cls("speed.csv", speed, suffix=".csv")]


def check_series(series, path: Path) -> list[str]:
    return _times_ok(series.t, "sensor") + _finite(series.value, "sensor values")


def gyro_seeds(seed_cls) -> list:
    def columns():
        yaw = _sample_motion().yaw_rate
        return [yaw.t, yaw.value]

    return [seed_cls("gyro.csv", _csv("t,yaw_rate_rad_s", columns), suffix=".csv")]


def check_gyro(series, path: Path) -> list[str]:
    return _times_ok(series.t, "gyro") + _finite(series.value, "yaw rate")


def _nmea(sentence: str) -> str:
    checksum = 0
    for char in sentence:
        checksum ^= ord(char)
    return f"${sentence}*{checksum:02X}"


def nmea_text() -> bytes:
    lines = []
    for k in range(120):
        hh, mm, ss = 12, k // 60, k % 60
        lat = f"35{41.6 + 0.001 * k:07.4f}"
        time = f"{hh:02d}{mm:02d}{ss:02d}.00"
        lines.append(_nmea(f"GPGGA,{time},{lat},N,13942.204,E,1,08,0.9,40.0,M,39.0,M,,"))
        lines.append(_nmea(f"GPRMC,{time},A,{lat},N,13942.204,E,10.5,90.0,140325,,,A"))
    return ("\r\n".join(lines) + "\r\n").encode()


def gps_seeds(seed_cls) -> list:
    def columns():
        t = np.arange(0.0, 60.0, 0.5)
        return [t, 35.69 + 1e-5 * t, 139.70 + 1e-5 * t, np.full_like(t, 10.0)]

    return [
        seed_cls("gps.csv", _csv("t,lat_deg,lon_deg,speed_mps", columns), suffix=".csv"),
        seed_cls("fixes.nmea", nmea_text, suffix=".nmea"),
    ]


def check_gps(fixes, path: Path) -> list[str]:
    bad = _times_ok(fixes.t, "fix")
    if np.abs(fixes.lat).max(initial=0) > np.pi / 2 or np.abs(fixes.lon).max(initial=0) > np.pi:
        bad.append("latitude or longitude out of range")
    return bad + _finite(np.concatenate([fixes.lat, fixes.lon]), "coordinates")


def trajectory_seeds(seed_cls) -> list:
    seeds = [seed_cls("ground_truth.tum", _file(SAMPLE / "ground_truth.tum"), suffix=".tum")]
    kitti = shared_data_dir() / "kitti06_0000_0050" / "poses.txt"
    if kitti.is_file():
        seeds.append(seed_cls("kitti poses.txt", _file(kitti), suffix=".txt"))
    return seeds


def check_trajectory(trajectory, path: Path) -> list[str]:
    bad = _finite(trajectory.positions, "positions") + _finite(trajectory.t, "times")
    if path.suffix == ".tum":
        bad += _times_ok(trajectory.t, "pose")
    rotations = trajectory.orientations.as_matrix()
    if not np.allclose(np.einsum("nji,njk->nik", rotations, rotations), np.eye(3), atol=1e-6):
        bad.append("orientation not a rotation")
    return bad


def heading_text() -> bytes:
    rows = [",".join(COLUMNS)]
    for k in range(200):
        rows.append(f"{1000 + 0.05 * k:.3f},{k % 360}.0,0.5,1,8,6,{k % 360}.0,1,0.3,1.02")
    return ("\n".join(rows) + "\n").encode()


def heading_seeds(seed_cls) -> list:
    return [seed_cls("heading.csv", heading_text, suffix=".csv")]


def check_heading(table, path: Path) -> list[str]:
    return _times_ok(table.t, "heading") + _finite(table.wheel_scale, "wheel scale")


def calibration_seeds(seed_cls) -> list:
    seeds = [seed_cls("calib.yaml", _file(SAMPLE / "calib.yaml"), suffix=".yaml")]
    kitti = shared_data_dir() / "kitti06_0000_0050" / "calib.txt"
    if kitti.is_file():
        seeds.append(seed_cls("kitti calib.txt", _file(kitti), suffix=".txt"))
    return seeds


def check_camera(camera, path: Path) -> list[str]:
    bad = [] if camera.fx > 0 and camera.fy > 0 else ["non-positive focal length"]
    bad += _finite([camera.fx, camera.fy, camera.cx, camera.cy], "intrinsics")
    R = np.asarray(camera.T_vehicle_camera)[:3, :3]
    if not (np.allclose(R.T @ R, np.eye(3), atol=1e-3) and np.linalg.det(R) > 0):
        bad.append("extrinsic not rigid")
    return bad


def times_seeds(seed_cls) -> list:
    return [seed_cls("times.txt", _file(SAMPLE / "times.txt"), suffix=".txt")]


def read_times_any_count(path: Path):
    """Times with the count the file itself suggests (non-empty lines), so mutations reach the
    parser rather than the count check."""
    count = sum(1 for line in path.read_bytes().split(b"\n") if line.strip())
    return read_times(path, count)


def check_times(times, path: Path) -> list[str]:
    return _times_ok(times, "image")


def doppler_sigma_text() -> bytes:
    rows = ["gps_time_s,sat,code,sigma_mps"]
    for epoch in range(40):
        for sat in ("G05", "G13", "E24", "C11"):
            rows.append(f"{1.4e9 + 0.1 * epoch:.3f},{sat},D1C,{0.02 + 0.001 * epoch:.6g}")
    return ("\n".join(rows) + "\n").encode()


def doppler_sigma_seeds(seed_cls) -> list:
    return [seed_cls("doppler_sigma.csv", doppler_sigma_text, suffix=".csv")]


def check_doppler_sigma(table, path: Path) -> list[str]:
    bad = _finite(table.t, "epoch") + _finite(table.sigma_mps, "sigma")
    if table.sigma_mps.size and not (table.sigma_mps > 0).all():
        bad.append("sigma not positive")
    keys = list(
        zip(
            np.round(table.t * 1e3).tolist(),
            table.sat_id.tolist(),
            table.code.tolist(),
            strict=True,
        )
    )
    if len(set(keys)) != len(keys):
        bad.append("repeated (epoch, satellite, code)")
    return bad


def manifest_text() -> bytes:
    """The sample's manifest as it is: its paths relative, so a case's bytes are the same
    wherever the checkout lies (:func:`read_manifest_sequence` gives them the sample's files)."""
    return (SAMPLE / "sequence.yaml").read_bytes()


def manifest_seeds(seed_cls) -> list:
    return [seed_cls("sequence.yaml", manifest_text, suffix=".yaml")]


def read_manifest_sequence(path: Path):
    """The manifest ``path`` read beside links to the sample's files, made once in its folder
    (outside paths allowed, as a mutation may name any)."""
    for entry in SAMPLE.iterdir():
        link = path.parent / entry.name
        if entry.name != "sequence.yaml" and not link.is_symlink():
            link.symlink_to(entry)
    return read_sequence(path, allow_outside=True)


def check_sequence(sequence, path: Path) -> list[str]:
    bad = _times_ok(sequence.image_times, "image") + _times_ok(sequence.wheel_speed.t, "speed")
    if not (abs(sequence.enu.lat_rad) <= np.pi / 2 and abs(sequence.enu.lon_rad) <= np.pi):
        bad.append("origin out of range")
    return bad + _finite(sequence.antenna_lever_arm_m, "lever arm")


def register_all(register, family_cls, seed_cls) -> None:
    """Register every family of this module with the harness."""

    def seeds(make):
        return lambda: make(seed_cls)

    for name, make, read, check in (
        ("can-log", can_seeds, read_can, check_can),
        ("dbc", dbc_seeds, read_dbc_and_decode, check_dbc),
        ("sensor-csv", sensor_seeds, read_speed_csv, check_series),
        ("gyro-csv", gyro_seeds, read_yaw_rate_csv, check_gyro),
        ("gps-csv-nmea", gps_seeds, read_gps_fixes, check_gps),
        ("trajectory", trajectory_seeds, read_trajectory, check_trajectory),
        ("heading-csv", heading_seeds, read_heading_csv, check_heading),
        ("calibration", calibration_seeds, read_camera, check_camera),
        ("times", times_seeds, read_times_any_count, check_times),
        ("manifest", manifest_seeds, read_manifest_sequence, check_sequence),
        ("doppler-sigma", doppler_sigma_seeds, read_doppler_sigma, check_doppler_sigma),
    ):
        register(family_cls(name, seeds(make), read, check))
