"""Read a sequence folder described by ``sequence.yaml`` (format ``vo-doppler-sequence/1``,
written by ``vo-doppler simulate``; any recording laid out the same way works) into the
recording model :class:`~vo_doppler.model.sequence.Sequence`.

Paths in the manifest are relative to its folder and must stay inside it (no ``../`` out of
it, no absolute paths) unless paths outside are explicitly allowed; every file must be a regular
file. Every value is checked for its type and range and a bad one names its key. Every sensor
clock is mapped to GPS time by ``gps = sensor time + time_offset_s`` of that sensor.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from vo_doppler.bounds import TIME_OFFSET, lever_arm_problem
from vo_doppler.choices import allowed, values
from vo_doppler.errors import InputError, ManifestError, shown
from vo_doppler.geo import EnuFrame
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.can_report import CanDecodeReport, ShortFrames
from vo_doppler.io.doppler_sigma import read_doppler_sigma
from vo_doppler.io.images import check_image_size, list_images, read_times
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.satellite_states import read_satellite_states
from vo_doppler.io.sensor_csv import (
    FORWARD_ACCELERATION_COLUMN,
    SPEED_COLUMN,
    YAW_RATE_COLUMN,
    read_sensor_csv_with_report,
)
from vo_doppler.io.textfile import regular_file
from vo_doppler.io.time_order import TimeOrderReport
from vo_doppler.io.trajectory import read_tum
from vo_doppler.io.yaml_file import load_yaml
from vo_doppler.memory import release_free_heap
from vo_doppler.model.image_files import ImageFiles
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.model.vehicle_source import VehicleSignalSource

log = logging.getLogger(__name__)

MANIFEST = "sequence.yaml"
FORMAT = "vo-doppler-sequence/1"
MANIFEST_MAX_BYTES = 1 << 20
MANIFEST_OFFSET = "the manifest's time_offset_s"
"""The vehicle signals' clock setting, as the clock checks name it."""
_REQUIRED = object()


@dataclass
class InputReport:
    """What reading a sequence found besides the data: per-sensor time order, the CAN decoding,
    the DBC unit of the yaw-rate signal and the manifest's clock offset of the vehicle
    signals."""

    time_order: list[TimeOrderReport] = field(default_factory=list)
    can: CanDecodeReport | None = None
    yaw_rate_dbc_unit: str = ""
    vehicle_time_offset_s: float = 0.0
    """The clock offset of the yaw rate and wheel speed, from ``can`` or ``vehicle`` (``can``
    None: they came from the ``vehicle`` section's CSVs)."""
    skipped: list[str] = field(default_factory=list)
    """Sensor samples the readers skipped (unreadable, non-finite, beyond a vehicle's range),
    one sentence per file or CAN signal."""

    def warnings(self) -> list[str]:
        order = [text for report in self.time_order for text in report.problems()]
        return self.skipped + order


def origin_entry(frame: EnuFrame) -> dict[str, float]:
    """The manifest's ``origin`` entry (degrees, metres) of an ENU frame: what
    :func:`read_sequence` reads back into the frame."""
    return {
        "lat_deg": float(np.degrees(frame.lat_rad)),
        "lon_deg": float(np.degrees(frame.lon_rad)),
        "height_m": float(frame.height_m),
    }


def read_manifest(folder: str | Path) -> dict[str, Any]:
    """The parsed ``sequence.yaml`` of a folder (or the file itself), checked for its format."""
    path = Path(folder)
    if path.is_dir():
        path = path / MANIFEST
    manifest = load_yaml(path, "the sequence manifest", MANIFEST_MAX_BYTES)
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        found = manifest.get("format") if isinstance(manifest, dict) else type(manifest).__name__
        raise InputError(f"not a {FORMAT} manifest (format: {found!r})", path)
    manifest["_path"] = path
    return manifest


def manifest_inputs(folder: str | Path) -> list[Path]:
    """The sequence folder, its manifest and every existing file or folder a string of the
    manifest names (relative to the folder, or absolute): what an output must never replace.
    Strings that are not paths name nothing that exists and drop out."""
    manifest = read_manifest(folder)
    root = manifest["_path"].parent
    found = [root, manifest["_path"]]
    pending = [manifest]
    while pending:  # depth first, in the manifest's order
        value = pending.pop()
        if isinstance(value, dict):
            pending += reversed(value.values())
        elif isinstance(value, list):
            pending += reversed(value)
        elif isinstance(value, str) and value.strip():
            try:
                path = root / value
                if path.exists():
                    found.append(path)
            except (OSError, ValueError):  # a name too long or with a NUL names no input
                continue
    return found


class Manifest:
    """Typed access to a parsed manifest: every value is checked for its type and range, and
    every path for staying inside the sequence folder (unless ``allow_outside``); a bad value is
    a :class:`ManifestError` naming the key, never the content of a file."""

    def __init__(self, manifest: dict[str, Any], allow_outside: bool = False):
        self.data = manifest
        self.path: Path = manifest["_path"]
        self.root = self.path.parent
        self.allow_outside = allow_outside

    def error(self, key: str, message: str) -> ManifestError:
        return ManifestError(key, message, self.path)

    def section(self, name: str) -> dict[str, Any]:
        section = self.data.get(name)
        if not isinstance(section, dict):
            raise InputError(f"manifest has no '{name}' section", self.path)
        return section

    def value(self, section: str, key: str, default: Any = _REQUIRED) -> Any:
        values = self.section(section)
        if key not in values:
            if default is _REQUIRED:
                raise InputError(f"manifest section '{section}' lacks '{key}'", self.path)
            return default
        return values[key]

    def number(
        self,
        section: str,
        key: str,
        default: Any = _REQUIRED,
        low: float = -math.inf,
        high: float = math.inf,
    ) -> float:
        """A finite number in [low, high] (YAML booleans and strings are refused)."""
        value = self.value(section, key, default)
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(f"{section}.{key}", f"{value!r} is not a number")
        value = float(value)
        if not math.isfinite(value):
            raise self.error(f"{section}.{key}", f"{value} is not a finite number")
        if not low <= value <= high:
            raise self.error(f"{section}.{key}", f"{value:g} is outside [{low:g}, {high:g}]")
        return value

    def time_offset(self, section: str) -> float:
        """The section's ``time_offset_s`` (0 when absent), within ``TIME_OFFSET``: an offset to
        GPS time beyond every GPS time up to 2100 is a wrong value, not a clock."""
        return self.number(section, "time_offset_s", 0.0, TIME_OFFSET.low, TIME_OFFSET.high)

    def string(self, section: str, key: str, default: Any = _REQUIRED) -> str:
        value = self.value(section, key, default)
        if not isinstance(value, str) or not value.strip():
            raise self.error(f"{section}.{key}", f"{value!r} is not a non-empty string")
        return value

    def resolve(self, key: str, relative: Any) -> Path:
        """``relative`` (a string) as a path inside the sequence folder."""
        if not isinstance(relative, str) or not relative.strip():
            raise self.error(key, f"{relative!r} is not a path string")
        path = Path(relative)
        if not self.allow_outside:
            if path.is_absolute():
                raise self.error(
                    key,
                    "absolute paths are refused; give a path relative to the sequence "
                    "folder (or allow paths outside it: vo-doppler run --allow-outside-paths, "
                    "read_sequence(..., allow_outside=True))",
                )
            inside = (self.root / path).resolve()
            if not inside.is_relative_to(self.root.resolve()):
                raise self.error(
                    key,
                    "the path leaves the sequence folder (to use it, allow paths outside it: "
                    "vo-doppler run --allow-outside-paths, read_sequence(..., allow_outside=True))",
                )
        return self.root / path

    def file(self, section: str, key: str) -> Path:
        """A regular file inside the sequence folder (devices and folders refused)."""
        path = self.resolve(f"{section}.{key}", self.value(section, key))
        try:
            regular_file(path, f"{section}.{key}")
        except InputError as exc:
            raise self.error(f"{section}.{key}", str(exc)) from exc
        return path

    def files(self, section: str, key: str) -> list[Path]:
        """One path string or a non-empty list of them."""
        value = self.value(section, key)
        items = value if isinstance(value, list) else [value]
        if not items:
            raise self.error(f"{section}.{key}", "is an empty list; give at least one file")
        out = []
        for item in items:
            path = self.resolve(f"{section}.{key}", item)
            try:
                regular_file(path, f"{section}.{key}")
            except InputError as exc:
                raise self.error(f"{section}.{key}", str(exc)) from exc
            out.append(path)
        return out

    def folder(self, section: str, key: str) -> Path:
        path = self.resolve(f"{section}.{key}", self.value(section, key))
        if not path.is_dir():
            raise self.error(f"{section}.{key}", f"{path} is not a folder")
        return path

    def images(self, section: str, key: str) -> ImageFiles:
        """The image files of the folder the key names (an empty folder names the key)."""
        folder = self.folder(section, key)
        try:
            return list_images(folder)
        except InputError as exc:
            raise self.error(f"{section}.{key}", str(exc)) from exc


def read_sequence(folder: str | Path, allow_outside: bool = False) -> Sequence:
    """All inputs of a sequence folder, on GPS time; ground truth when the folder has one."""
    return read_sequence_with_report(folder, allow_outside)[0]


def read_sequence_with_report(
    folder: str | Path, allow_outside: bool = False
) -> tuple[Sequence, InputReport]:
    """:func:`read_sequence` and what reading found (time order per sensor, CAN decoding)."""
    m = Manifest(read_manifest(folder), allow_outside)
    m.section("origin")
    report = InputReport()
    images, times, camera, camera_offset = [], np.zeros(0), None, 0.0
    if "camera" in m.data:  # a recording without video has no camera section
        images = m.images("camera", "images")
        camera_offset = m.time_offset("camera")
        times = read_times(m.file("camera", "times"), len(images))
        if np.any(np.diff(times + camera_offset) <= 0):
            raise m.error(
                "camera.time_offset_s",
                f"{camera_offset:g} s added to the image times makes them stop increasing "
                "(the sum loses their spacing to rounding)",
            )
        camera = read_camera(m.file("camera", "calib"))
        check_image_size(camera, images, m.file("camera", "calib"))
    obs, nav, sigma, lever_arm = None, None, None, (0.0, 0.0, 0.0)
    if "gnss" in m.data:  # a recording without GNSS (a KITTI raw drive) runs VO and DR only
        obs, nav, sigma = _gnss(m)
        lever_arm = _lever_arm(m.value("gnss", "antenna_lever_arm_m", (0.0, 0.0, 0.0)), m.path)
    motion = _vehicle_motion(m, report)
    enu = EnuFrame(
        np.radians(m.number("origin", "lat_deg", low=-90.0, high=90.0)),
        np.radians(m.number("origin", "lon_deg", low=-180.0, high=180.0)),
        m.number("origin", "height_m", 0.0, low=-1.0e3, high=1.0e4),
    )
    truth = _ground_truth(m)
    forward_acceleration = motion.forward_acceleration
    imu = m.data.get("imu")
    if isinstance(imu, dict) and "forward_acceleration" in imu:
        forward_acceleration = _sensor_csv(
            m, "imu", "forward_acceleration", FORWARD_ACCELERATION_COLUMN, report
        )
    name = m.data.get("name", shown(m.root.name))
    if not isinstance(name, str | int | float) or isinstance(name, bool):
        raise m.error("name", f"{name!r} is not a name")
    sequence = Sequence(
        name=str(name),
        image_paths=images,
        image_times=times + camera_offset,
        camera=camera,
        observations=obs,
        navigation=nav,
        doppler_sigma=sigma,
        forward_acceleration=forward_acceleration,
        yaw_rate=motion.yaw_rate,
        wheel_speed=motion.speed,
        enu=enu,
        truth=truth,
        antenna_lever_arm_m=lever_arm,
        clock_offsets_s={"camera": camera_offset, motion.source: motion.offset_s, "gnss": 0.0},
        vehicle_source=motion.names,
    )
    release_free_heap()  # the readers' temporaries: 50 MiB resident on a 30-min drive else
    return sequence, report


def read_ground_truth(folder: str | Path, allow_outside: bool = False) -> Trajectory | None:
    """The sequence's ground truth as :func:`read_sequence` reads it; None when it has none."""
    return _ground_truth(Manifest(read_manifest(folder), allow_outside))


def _ground_truth(m: Manifest) -> Trajectory | None:
    if "ground_truth" not in m.data:  # optional, but a named file must be there, as every input
        return None
    return read_tum(m.file("ground_truth", "trajectory"))


def _gnss(m: Manifest):
    """The ``gnss`` section: observations, navigation or precise orbits, the Doppler σ."""
    obs = read_obs(m.file("gnss", "obs"))
    if "orbits" in m.section("gnss"):
        clocks = m.file("gnss", "clocks") if "clocks" in m.section("gnss") else None
        nav = read_satellite_states(orbits=m.file("gnss", "orbits"), clocks=clocks)
    else:
        nav = read_satellite_states(m.files("gnss", "nav"))
    sigma = None
    if "doppler_sigma" in m.section("gnss"):
        sigma = read_doppler_sigma(m.file("gnss", "doppler_sigma"))
    if m.number("gnss", "time_offset_s", 0.0) != 0.0:
        raise m.error("gnss.time_offset_s", "GNSS observations must be on GPS time (0)")
    return obs, nav, sigma


@dataclass(frozen=True)
class _VehicleMotion:
    yaw_rate: SensorSeries
    speed: SensorSeries
    forward_acceleration: SensorSeries | None
    source: str
    offset_s: float
    names: VehicleSignalSource


def _vehicle_motion(m: Manifest, report: InputReport) -> _VehicleMotion:
    """The yaw rate and wheel speed (and a forward acceleration on the bus) from the ``can``
    section, or from the sensor CSVs of the ``vehicle`` section: exactly one of the two."""
    has = {name: isinstance(m.data.get(name), dict) for name in ("can", "vehicle")}
    if has["can"] and has["vehicle"]:
        raise m.error(
            "can / vehicle",
            "the yaw rate and wheel speed are given twice (can and vehicle): keep one",
        )
    if not has["can"] and not has["vehicle"]:
        raise InputError(
            "manifest has neither a 'can' nor a 'vehicle' section (the yaw rate and wheel speed)",
            m.path,
        )
    if has["can"]:
        return _can_motion(m, report)
    offset = m.time_offset("vehicle")
    yaw_rate = _sensor_csv(m, "vehicle", "yaw_rate", YAW_RATE_COLUMN, report)
    speed = _sensor_csv(m, "vehicle", "wheel_speed", SPEED_COLUMN, report)
    report.yaw_rate_dbc_unit = "rad/s"
    report.vehicle_time_offset_s = offset
    yaw_file = m.file("vehicle", "yaw_rate")
    names = VehicleSignalSource(
        sensor="vehicle signals",
        offset_s=offset,
        offset_name=MANIFEST_OFFSET,
        yaw_rate=f"{yaw_file} (the yaw rate, vehicle.yaw_rate)",
        yaw_rate_unit_fix=f"the {YAW_RATE_COLUMN} column must be in rad/s: convert it (× π/180)",
        yaw_rate_sign_fix=f"the {YAW_RATE_COLUMN} column must be counter-clockwise positive (a "
        "left turn > 0): negate it",
    )
    return _VehicleMotion(yaw_rate, speed, None, "vehicle", offset, names)


def _sensor_csv(
    m: Manifest, section: str, key: str, column: str, report: InputReport
) -> SensorSeries:
    """The ``t,<column>`` CSV named by ``section.key`` on GPS time (the section's
    ``time_offset_s``); the rows it skipped go to the report's warnings."""
    series, csv_report = read_sensor_csv_with_report(
        m.file(section, key), column, m.time_offset(section)
    )
    report.skipped.extend(csv_report.problems())
    return series


def _can_motion(m: Manifest, report: InputReport) -> _VehicleMotion:
    """The ``can`` section: the log decoded with its DBC."""
    # python-can and cantools load here, not with the module: a process that receives a
    # sequence read elsewhere (vo_doppler.job) need not hold them.
    from vo_doppler.io.can import SignalError, read_can_motion

    can_offset = m.time_offset("can")
    short_frames = m.string("can", "short_frames", ShortFrames.SKIP.value)
    if short_frames not in values(ShortFrames):
        raise m.error(
            "can.short_frames",
            f"can.short_frames is {short_frames!r}, not one of {allowed(ShortFrames)}",
        )
    sign = m.number("can", "yaw_rate_sign", 1.0)
    if sign not in (1.0, -1.0):
        raise m.error("can.yaw_rate_sign", f"{sign:g} is not +1 or -1")
    log_path = m.file("can", "log")
    dbc_path = m.file("can", "dbc")
    yaw_name = m.string("can", "yaw_rate")
    can_acceleration = (
        m.string("can", "forward_acceleration")
        if "forward_acceleration" in m.section("can")
        else None
    )
    imu = m.data.get("imu")
    if can_acceleration and isinstance(imu, dict) and "forward_acceleration" in imu:
        raise m.error(
            "can.forward_acceleration",
            "the forward acceleration is given twice (can. and imu.): keep one",
        )
    try:
        motion = read_can_motion(
            log_path,
            dbc_path,
            yaw_name,
            m.string("can", "wheel_speed"),
            sign,
            can_offset,
            can_offset,
            short_frames=short_frames,
            forward_acceleration=can_acceleration,
        )
    except SignalError as exc:
        raise m.error(
            "can.yaw_rate / can.wheel_speed / can.forward_acceleration", str(exc)
        ) from exc
    if motion.yaw_rate is None or motion.speed is None or not len(motion.speed):
        raise InputError("CAN log gave no yaw rate or wheel speed", log_path)
    report.can = motion.report
    report.time_order.extend(motion.report.time_order.values())
    report.yaw_rate_dbc_unit = motion.report.dbc_units.get(yaw_name.strip(), "")
    report.vehicle_time_offset_s = can_offset
    names = VehicleSignalSource(
        sensor="CAN",
        offset_s=can_offset,
        offset_name=MANIFEST_OFFSET,
        yaw_rate=f"{dbc_path}: the yaw rate, CAN signal {yaw_name.strip()} (can.yaw_rate)",
        yaw_rate_unit=report.yaw_rate_dbc_unit,
        yaw_rate_unit_fix="the DBC declares the signal in rad/s: fix the unit (or factor) in the "
        "DBC",
        yaw_rate_sign_fix=f"set can.yaw_rate_sign in {m.path} to {-sign:g} (it is {sign:g})",
    )
    return _VehicleMotion(
        motion.yaw_rate, motion.speed, motion.forward_acceleration, "can", can_offset, names
    )


def _lever_arm(value, path: Path) -> tuple[float, float, float]:
    """``gnss.antenna_lever_arm_m``: three numbers (x forward, y left, z up, m)."""
    try:
        arm = tuple(float(v) for v in value) if isinstance(value, list | tuple) else ()
    except (TypeError, ValueError, OverflowError):
        arm = ()
    if len(arm) != 3 or not all(np.isfinite(arm)):
        raise ManifestError(
            "gnss.antenna_lever_arm_m",
            f"gnss.antenna_lever_arm_m is {value!r}, not three numbers (m)",
            path,
        )
    problem = lever_arm_problem(arm)
    if problem:
        raise ManifestError("gnss.antenna_lever_arm_m", f"{list(arm)}: {problem}", path)
    return arm
