"""Fuzz families of the recording importers and the minimal heading CSV: the smartLoc raw CSV
reader, the KITTI raw drive importer (a whole drive folder, fuzzed as one text) and the minimal
heading CSV (``correct --heading``'s way to bring one's own absolute heading).

Seeds: the smartLoc Berlin file and the kitti_raw_mini drive of ``../shared/data`` when present
(smartLoc also gets a synthetic seed, so the family runs without them); the heading CSVs are
made here. Registered by ``families.py`` with::

    register_imports(register, Family, Seed, check_observations, same_observations)
"""

from __future__ import annotations

import math
import re
import shutil
import zlib
from pathlib import Path

import numpy as np

from tests.conftest import shared_data_dir
from tests.helpers.smartloc_text import Measurement, Truth, smartloc_text
from vo_doppler.bounds import SPEED, YAW_RATE
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.kitti_raw_import import import_kitti_raw
from vo_doppler.io.sequence import read_sequence
from vo_doppler.io.smartloc import read_smartloc
from vo_doppler.model.gpstime import SECONDS_PER_WEEK

SMARTLOC = "smartloc_berlin/tu_chemnitz_berlin_1_raw.csv"
KITTI_DAY = "kitti_raw_mini/2011_09_26"
KITTI_DRIVE = "2011_09_26_drive_0001_sync"
GPS_SECONDS = (0.0, 4096 * SECONDS_PER_WEEK)


def _shared(relative: str) -> Path:
    return shared_data_dir() / relative


def _times(t: np.ndarray, what: str, gps: bool = True) -> list[str]:
    t = np.asarray(t, dtype=float)
    if not np.isfinite(t).all():
        return [f"{what} times not finite"]
    if gps and t.size and (t.min() < GPS_SECONDS[0] or t.max() > GPS_SECONDS[1]):
        return [f"{what} times outside GPS weeks 0–4095"]
    if t.size > 1 and not (np.diff(t) > 0).all():
        return [f"{what} times do not increase strictly"]
    return []


def _within(values: np.ndarray, low: float, high: float, what: str) -> list[str]:
    values = np.asarray(values, dtype=float)
    if values.size and not (
        np.isfinite(values).all() and values.min() >= low and values.max() <= high
    ):
        return [f"{what} not finite or outside {low:g} … {high:g}"]
    return []


# smartLoc


def smartloc_synthetic() -> bytes:
    """Ten epochs of GPS, GLONASS and SBAS rows with every NLOS label and tracking state."""
    epochs = []
    for k in range(10):
        truth = Truth(126641.5 + 0.2 * k, lon=13.37 + 1e-5 * k, heading=1.2 + 0.01 * k)
        epochs.append(
            (
                truth,
                [
                    Measurement("GPS", 12, 222.1658 + k, 0.128, nlos="0"),
                    Measurement("GPS", 19, -2783.8, 0.256, tracking=1, nlos="1"),
                    Measurement("Glonass", 20, 2219.386, 1.024, freq_id=9, tracking=7, nlos="#"),
                    Measurement("SBAS", 120, -10.0, 0.5, tracking=3, nlos="1"),
                ],
            )
        )
    return smartloc_text(epochs).encode()


def smartloc_seeds(seed_cls) -> list:
    seeds = [seed_cls("synthetic smartLoc", smartloc_synthetic, suffix=".csv")]
    if _shared(SMARTLOC).is_file():
        seeds.append(seed_cls("berlin_1_raw.csv", _shared(SMARTLOC).read_bytes, suffix=".csv"))
    return seeds


def make_check_smartloc(check_observations):
    def check_smartloc(recording, path: Path) -> list[str]:
        obs = recording.observations
        bad = check_observations(obs, path)
        for name, values in obs.row_fields.items():
            if len(values) != len(obs):
                bad.append(f"row field {name} not one value per row")
        if bad:
            return bad
        kinds = np.array([c[0] for c in obs.codes])[obs.code]
        doppler = kinds == "D"
        fields = obs.row_fields
        if not np.isin(fields["nlos"], (-1, 0, 1)).all():
            bad.append("NLOS label other than −1, 0, 1")
        wavelength = fields["wavelength_m"][doppler]
        bad += _within(wavelength, 0.18, 0.26, "Doppler wavelength (m)")
        bad += _within(np.abs(fields["range_rate_mps"][doppler]), 0.0, 3.0e4, "|range rate|")
        sigma = fields["range_rate_sigma_mps"][doppler]
        if sigma.size and not (np.isfinite(sigma).all() and (sigma > 0).all()):
            bad.append("Doppler σ not positive and finite")
        if np.isfinite(fields["range_rate_mps"][~doppler]).any():
            bad.append("a range rate on a row that is not a Doppler")
        truth = recording.truth
        bad += _times(truth.t, "ground truth")
        bad += _within(np.degrees(truth.lat_rad), -90.0, 90.0, "latitude")
        bad += _within(np.degrees(truth.lon_rad), -180.0, 180.0, "longitude")
        bad += _within(truth.speed_mps, SPEED.low, SPEED.high, "speed")
        bad += _within(truth.yaw_rate_rad_s, YAW_RATE.low, YAW_RATE.high, "yaw rate")
        channels = recording.glonass_channels
        if any(not -7 <= k <= 6 for k in channels.values()):
            bad.append("GLONASS channel outside −7…6")
        return bad

    return check_smartloc


def make_same_smartloc(same_observations):
    def same_smartloc(recording, original) -> list[str]:
        """Lost lines only lose rows: each value, label and range rate equals the original's."""
        bad = same_observations(recording.observations, original.observations)
        if bad:
            return bad
        ours, theirs = recording.observations, original.observations
        index = {
            key: k
            for k, key in enumerate(
                zip(
                    theirs.time.tolist(),
                    theirs.satellites().tolist(),
                    theirs.code.tolist(),
                    strict=True,
                )
            )
        }
        codes = {c: theirs.codes.index(n) for c, n in enumerate(ours.codes) if n in theirs.codes}
        for k, (t, sat, code) in enumerate(
            zip(ours.time.tolist(), ours.satellites().tolist(), ours.code.tolist(), strict=True)
        ):
            j = index[(t, sat, codes[code])]
            for name, values in ours.row_fields.items():
                a, b = values[k], theirs.row_fields[name][j]
                if not (a == b or (np.isnan(a) and np.isnan(b))):
                    return [f"{name} of {sat} at {t} is {a}, the original's {b}"]
        return []

    return same_smartloc


# KITTI raw drive: a folder, fuzzed as one text of named sections

SECTION = re.compile(rb"^=== ([\w./]+)$")
DRIVE_FILES = (
    "calib_cam_to_cam.txt",
    "calib_imu_to_velo.txt",
    "calib_velo_to_cam.txt",
    f"{KITTI_DRIVE}/image_00/timestamps.txt",
    f"{KITTI_DRIVE}/oxts/timestamps.txt",
)
IMAGE_LIST = f"{KITTI_DRIVE}/image_00/data"
OXTS_DATA = f"{KITTI_DRIVE}/oxts/data"
_SAFE_NAME = re.compile(rb"^\w[\w.]{0,63}$")
MAX_FILES = 2000


def kitti_raw_seed() -> bytes:
    """The kitti_raw_mini drive: the calibration and timestamp files as they are, the image
    file names (their content is replaced by one blank PNG of the calibration's size: the
    importer copies images and checks their size), and one line per OXTS data file."""
    day = _shared(KITTI_DAY)
    parts = []
    for name in DRIVE_FILES:
        parts.append(b"=== " + name.encode() + b"\n" + (day / name).read_bytes().rstrip(b"\n"))
    images = sorted(p.name for p in (day / IMAGE_LIST).iterdir())
    parts.append(b"=== " + IMAGE_LIST.encode() + b"\n" + "\n".join(images).encode())
    oxts = sorted((day / OXTS_DATA).iterdir())
    lines = b"\n".join(p.read_bytes().strip() for p in oxts)
    parts.append(b"=== " + OXTS_DATA.encode() + b"\n" + lines)
    return b"\n".join(parts) + b"\n"


def _blank_png(width: int, height: int) -> bytes:
    """A black grey-scale PNG of ``width`` × ``height`` (no image library needed)."""

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return len(data).to_bytes(4, "big") + body + zlib.crc32(body).to_bytes(4, "big")

    header = width.to_bytes(4, "big") + height.to_bytes(4, "big") + bytes([8, 0, 0, 0, 0])
    pixels = zlib.compress(bytes(height * (width + 1)))
    return (
        b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", pixels) + chunk(b"IEND", b"")
    )


KITTI_SIZE = (1242, 375)
"""The rectified size kitti_raw_mini's calib_cam_to_cam.txt states (S_rect_00)."""
BLANK_PNG = _blank_png(*KITTI_SIZE)


def _unpack_drive(path: Path) -> Path:
    """The one-text drive laid out as ``<path>.d/<day>/``: each ``=== NAME`` section becomes the
    file NAME (the image list: one blank PNG per safe name; the OXTS section: one data file per
    line, numbered from 0). Returns the drive folder."""
    day = Path(f"{path}.d") / "2011_09_26"
    shutil.rmtree(day.parent, ignore_errors=True)
    (day / IMAGE_LIST).mkdir(parents=True)
    (day / OXTS_DATA).mkdir(parents=True)
    sections: dict[str, list[bytes]] = {}
    current = None
    for line in path.read_bytes().split(b"\n"):
        match = SECTION.match(line)
        if match and match.group(1).decode() in (*DRIVE_FILES, IMAGE_LIST, OXTS_DATA):
            current = match.group(1).decode()
            sections.setdefault(current, [])
        elif current is not None:
            sections[current].append(line)
    for name in DRIVE_FILES:
        if name in sections:
            (day / name).write_bytes(b"\n".join(sections[name]) + b"\n")
    for name in sections.get(IMAGE_LIST, [])[:MAX_FILES]:
        if _SAFE_NAME.match(name):
            (day / IMAGE_LIST / name.decode()).write_bytes(BLANK_PNG)
    for k, line in enumerate(sections.get(OXTS_DATA, [])[:MAX_FILES]):
        if line:
            (day / OXTS_DATA / f"{k:010d}.txt").write_bytes(line + b"\n")
    return day / KITTI_DRIVE


def read_kitti_drive(path: Path):
    """Import the unpacked drive into ``<path>.d/seq`` and read the folder back as ``run``
    does: an import that succeeds must leave a sequence the project's own reader accepts."""
    drive = _unpack_drive(path)
    summary = import_kitti_raw(drive, drive.parent.parent / "seq")
    return summary, read_sequence(summary.folder)


def check_kitti_drive(result, path: Path) -> list[str]:
    summary, sequence = result
    bad = _times(sequence.image_times, "image")
    bad += _times(sequence.wheel_speed.t, "speed") + _times(sequence.yaw_rate.t, "yaw rate")
    bad += _within(sequence.wheel_speed.value, SPEED.low, SPEED.high, "speed")
    bad += _within(sequence.yaw_rate.value, YAW_RATE.low, YAW_RATE.high, "yaw rate")
    if len(sequence.image_paths) != summary.images or summary.images > summary.image_timestamps:
        bad.append("image count differs from the summary's or exceeds the timestamps")
    camera = sequence.camera
    if not (camera.fx > 0 and camera.fy > 0 and camera.width > 0 and camera.height > 0):
        bad.append("camera focal length or size not positive")
    T = np.asarray(camera.T_vehicle_camera)
    R = T[:3, :3]
    if not (
        np.isfinite(T).all() and np.allclose(R.T @ R, np.eye(3), atol=1e-3) and np.linalg.det(R) > 0
    ):
        bad.append("extrinsic not a rigid transform")
    truth = sequence.truth
    if truth is not None:
        bad += _times(truth.t, "ground truth")
        if not np.isfinite(truth.positions).all():
            bad.append("ground truth positions not finite")
        elif len(truth) and np.abs(truth.positions).max() > 1.0e7:
            bad.append("ground truth farther than 10,000 km from the origin")
    if not (abs(sequence.enu.lat_rad) <= math.pi / 2 and abs(sequence.enu.lon_rad) <= math.pi):
        bad.append("origin outside latitude ±90°, longitude ±180°")
    return bad


# minimal heading CSV


def minimal_heading_text(column: str = "course_deg", with_valid: bool = True) -> bytes:
    """200 rows at 10 Hz: a turning course with σ, invalid and empty rows among them."""
    header = ["gps_time_s", column, "sigma_deg"] + (["valid"] if with_valid else []) + ["note"]
    rows = [",".join(header)]
    for k in range(200):
        t = 1418912345.0 + 0.1 * k
        angle = f"{(87.25 + 1.7 * k) % 360 - (180 if k % 3 == 0 else 0):.2f}"
        if k % 17 == 0:
            angle = "" if k % 2 else "nan"
        fields = [f"{t:.1f}", angle, f"{0.5 + 0.01 * (k % 50):.2f}"]
        if with_valid:
            fields.append("0" if k % 11 == 0 else "1")
        fields.append(f"row {k}")
        rows.append(",".join(fields))
    return ("\n".join(rows) + "\n").encode()


def minimal_heading_seeds(seed_cls) -> list:
    return [
        seed_cls("course_deg,valid", minimal_heading_text, suffix=".csv"),
        seed_cls(
            "heading_deg, no valid",
            lambda: minimal_heading_text("heading_deg", with_valid=False),
            suffix=".csv",
        ),
    ]


def check_minimal_heading(table, path: Path) -> list[str]:
    bad = _times(table.t, "heading", gps=False)
    valid = np.asarray(table.conv_valid, dtype=bool)
    if not np.isfinite(table.yaw_conv[valid]).all() or np.isfinite(table.yaw_conv[~valid]).any():
        bad.append("a valid heading not finite, or an invalid one given")
    bad += _within(table.sigma_conv[valid], 1e-12, math.pi, "σ of a valid heading (rad)")
    if np.isfinite(table.yaw_tc).any() or np.any(table.tc_reliable):
        bad.append("a tightly coupled heading from a minimal file")
    return bad


def same_minimal_heading(table, original) -> list[str]:
    """Lost lines only lose rows: each row read equals the original row at its time."""
    rows = {
        float(t): (float(y), float(s), bool(v))
        for t, y, s, v in zip(
            original.t, original.yaw_conv, original.sigma_conv, original.conv_valid, strict=True
        )
    }
    for t, y, s, v in zip(table.t, table.yaw_conv, table.sigma_conv, table.conv_valid, strict=True):
        known = rows.get(float(t))
        if (
            known is None
            or known[2] != bool(v)
            or not np.allclose(known[:2], (y, s), equal_nan=True)
        ):
            return [f"the row at {t} differs from the original's"]
    return []


def register_imports(register, family_cls, seed_cls, check_observations, same_observations):
    """Register the three families (KITTI raw only when its seed drive is present)."""
    register(
        family_cls(
            "smartloc",
            lambda: smartloc_seeds(seed_cls),
            read_smartloc,
            make_check_smartloc(check_observations),
            make_same_smartloc(same_observations),
        )
    )
    if _shared(KITTI_DAY).is_dir():
        register(
            family_cls(
                "kitti-raw",
                lambda: [seed_cls("kitti_raw_mini drive", kitti_raw_seed, suffix=".kraw")],
                read_kitti_drive,
                check_kitti_drive,
            )
        )
    register(
        family_cls(
            "heading-minimal",
            lambda: minimal_heading_seeds(seed_cls),
            read_heading_csv,
            check_minimal_heading,
            same_minimal_heading,
        )
    )
