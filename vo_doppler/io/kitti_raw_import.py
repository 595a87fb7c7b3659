"""A KITTI raw drive → a standard sequence folder (``sequence.yaml``, format
``vo-doppler-sequence/1``, docs/sequence_format.md) that ``vo-doppler run`` reads.

A drive folder (``YYYY_MM_DD_drive_NNNN_sync`` or ``_extract``; Geiger et al., "Vision meets
robotics: the KITTI dataset", IJRR 2013, sec. IV and the raw-data devkit's readme) holds
``image_00`` … ``image_03`` (``data/NNNNNNNNNN.png`` + ``timestamps.txt``) and ``oxts/``
(:mod:`vo_doppler.io.kitti_oxts`); the day's calibration files sit in its parent (or in the
drive folder itself).

Written:

- ``image_0N/``: the chosen camera's images that exist (copied), ``times.txt``: the GPS time
  (s) of each, from the line of its frame number in the camera's ``timestamps.txt`` (UTC,
  converted with the date's leap seconds; a subsampled drive lists more lines than it has
  images: the images that exist are used, with a warning naming both counts);
- ``calib.yaml`` (:func:`vo_doppler.io.calibration.write_camera_yaml`): from
  ``calib_cam_to_cam.txt``, for a ``_sync`` drive (rectified images) the intrinsics of
  ``P_rect_0N`` with the size ``S_rect_0N`` and no distortion, for an ``_extract`` drive
  (raw images) ``K_0N``, ``D_0N`` (k1 k2 p1 p2 k3, OpenCV's order) and ``S_0N``. The extrinsic
  ``T_vehicle_camera`` is the camera in the OXTS unit's frame (x forward, y left, z up: the
  vehicle frame of the ground truth) from ``calib_imu_to_velo.txt`` and
  ``calib_velo_to_cam.txt`` (camera 0), then ``R_rect_00`` and ``P_rect_0N``'s translation
  K⁻¹·P[:, 3] for a rectified camera, or ``R_0N``, ``T_0N`` for a raw one; without those two
  files, a forward-looking camera at the vehicle origin (logged);
- ``vehicle/yaw_rate.csv`` (OXTS ``wz``, rad/s, counter-clockwise positive) and
  ``vehicle/wheel_speed.csv`` (OXTS ``vf``, m/s) on GPS time: the ``vehicle:`` section. The
  OXTS speed is the GNSS/IMU unit's, not an odometer's: it has no wheel-scale error to
  calibrate;
- ``ground_truth.tum``: the OXTS fixes as vehicle poses in the ENU frame whose origin is the
  first fix (:meth:`~vo_doppler.io.kitti_oxts.OxtsRecord.enu_trajectory`; not the devkit's
  Mercator poses: the difference is in :mod:`vo_doppler.io.kitti_oxts`);
- ``sequence.yaml`` with that origin and no ``gnss`` section: a KITTI raw drive has no raw
  GNSS measurements, so ``run`` runs the VO and dead reckoning without the GNSS pipelines.
  What the import found (the subsampling warnings, the calibration used) is recorded under
  ``kitti:`` (for people; not read).
"""

from __future__ import annotations

import logging
import re
import shutil
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

import numpy as np
import yaml

from vo_doppler.choices import checked
from vo_doppler.errors import InputError
from vo_doppler.io.calibration import checked_camera, write_camera_yaml
from vo_doppler.io.kitti_oxts import match_frame_files, read_oxts, read_timestamps
from vo_doppler.io.output_folder import check_output_folder, open_output_folder
from vo_doppler.io.sensor_csv import SPEED_COLUMN, YAW_RATE_COLUMN, write_sensor_csv
from vo_doppler.io.sequence import FORMAT, MANIFEST, origin_entry
from vo_doppler.io.textfile import SMALL_MAX_BYTES, read_text
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD, Camera

log = logging.getLogger(__name__)

CAM_TO_CAM = "calib_cam_to_cam.txt"
IMU_TO_VELO = "calib_imu_to_velo.txt"
VELO_TO_CAM = "calib_velo_to_cam.txt"
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg")
TIMES = "times.txt"
CALIB = "calib.yaml"
YAW_RATE_CSV = "vehicle/yaw_rate.csv"
SPEED_CSV = "vehicle/wheel_speed.csv"
GROUND_TRUTH = "ground_truth.tum"
MAX_CONDITION = 1e12
"""Largest condition number of a projection matrix's left 3×3 part (K: about fx/1 ≈ 1e3)."""
_KEY = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*):(.*)$")


class KittiCamera(StrEnum):
    """A KITTI raw drive's camera folder: two grey cameras, then two colour ones."""

    IMAGE_00 = "image_00"
    IMAGE_01 = "image_01"
    IMAGE_02 = "image_02"
    IMAGE_03 = "image_03"


@dataclass(frozen=True)
class KittiImportSummary:
    folder: Path
    camera: KittiCamera
    images: int
    image_timestamps: int
    oxts_rows: int
    oxts_timestamps: int
    rectified: bool
    extrinsic_from: str
    """The calibration files the camera→vehicle extrinsic came from, or why it is assumed."""
    warnings: tuple[str, ...]


def import_kitti_raw(
    drive: str | Path, output: str | Path, camera: KittiCamera | str = KittiCamera.IMAGE_00
) -> KittiImportSummary:
    """Write the sequence folder ``output`` from the KITTI raw drive folder ``drive`` (module
    docstring). ``output`` is checked first (new, empty or an earlier import's, not holding the
    drive), and every input is read before anything is written."""
    drive, output = Path(drive), Path(output)
    camera = checked(KittiCamera, camera, "camera")
    if not drive.is_dir():
        raise InputError("the KITTI raw drive is not a folder", drive)
    for folder in (camera, "oxts"):
        if not (drive / folder).is_dir():
            raise InputError(f"no {folder} folder in the drive", drive)
    calib_folder = _calibration_folder(drive)
    check_output_folder(output, "import", [drive, calib_folder / CAM_TO_CAM])
    rectified = not drive.name.endswith("_extract")
    intrinsics = _camera(calib_folder / CAM_TO_CAM, camera, rectified)
    extrinsic, extrinsic_from = _extrinsic(calib_folder, camera, rectified)
    calib = checked_camera(
        Camera(
            intrinsics.fx,
            intrinsics.fy,
            intrinsics.cx,
            intrinsics.cy,
            intrinsics.width,
            intrinsics.height,
            intrinsics.distortion,
            extrinsic,
        ),
        calib_folder / CAM_TO_CAM,
    )
    stamps = drive / camera / "timestamps.txt"
    all_times = read_timestamps(stamps)
    frames, images, image_warning = match_frame_files(
        drive / camera / "data", IMAGE_SUFFIXES, all_times.size, stamps
    )
    oxts = read_oxts(drive / "oxts")
    warnings = tuple(w for w in (image_warning, *oxts.warnings) if w)

    open_output_folder(output, "import")
    (output / camera).mkdir(exist_ok=True)
    (output / "vehicle").mkdir(exist_ok=True)
    for path in images:
        shutil.copyfile(path, output / camera / path.name)
    np.savetxt(output / TIMES, all_times[frames], fmt="%.9f")
    write_camera_yaml(output / CALIB, calib)
    write_sensor_csv(output / YAW_RATE_CSV, oxts.yaw_rate, YAW_RATE_COLUMN)
    write_sensor_csv(output / SPEED_CSV, oxts.speed, SPEED_COLUMN)
    origin = oxts.origin()
    write_tum(output / GROUND_TRUTH, oxts.enu_trajectory(origin))
    manifest = {
        "format": FORMAT,
        "name": drive.name,
        "source": f"KITTI raw drive {drive} (vo-doppler import kitti-raw)",
        "origin": origin_entry(origin),
        "camera": {"images": camera.value, "times": TIMES, "calib": CALIB, "time_offset_s": 0.0},
        "vehicle": {"yaw_rate": YAW_RATE_CSV, "wheel_speed": SPEED_CSV, "time_offset_s": 0.0},
        "ground_truth": {"trajectory": GROUND_TRUTH},
        "kitti": {
            "camera": camera.value,
            "rectified": rectified,
            "intrinsics_from": f"{CAM_TO_CAM}: "
            + (f"P_rect_{camera[-2:]}" if rectified else f"K_{camera[-2:]}, D_{camera[-2:]}"),
            "extrinsic_from": extrinsic_from,
            "timestamps": "read as UTC, converted to GPS time (KITTI does not name the scale)",
            "ground_truth": "OXTS fixes in the ENU frame of the first fix (origin); "
            "yaw rate = OXTS wz, wheel speed = OXTS vf",
            "warnings": list(warnings),
        },
    }
    (output / MANIFEST).write_text(yaml.safe_dump(manifest, sort_keys=False))
    return KittiImportSummary(
        output,
        camera,
        len(images),
        int(all_times.size),
        len(oxts.t),
        oxts.n_timestamps,
        rectified,
        extrinsic_from,
        warnings,
    )


def _calibration_folder(drive: Path) -> Path:
    """The folder of the day's ``calib_cam_to_cam.txt``: the drive's parent, or the drive."""
    for folder in (drive.parent, drive):
        if (folder / CAM_TO_CAM).is_file():
            return folder
    raise InputError(
        f"no {CAM_TO_CAM} beside the drive ({drive.parent}) or in it: copy the day's "
        "calibration files (the KITTI raw 'calibration' download) there",
        drive,
    )


def read_calib_rows(path: Path) -> dict[str, tuple[int, np.ndarray]]:
    """The numeric rows ``NAME: v1 v2 …`` of a KITTI calibration file by name, with their line
    numbers; ``calib_time`` (a date) is skipped. A malformed or repeated row is an
    :class:`InputError` naming the file and line."""
    rows: dict[str, tuple[int, np.ndarray]] = {}
    for number, line in enumerate(read_text(path, "calibration", SMALL_MAX_BYTES).splitlines(), 1):
        if not line.strip():
            continue
        match = _KEY.match(line.strip())
        if match is None:
            raise InputError(f"not a 'NAME: values' row: {line.strip()[:40]!r}", path, number)
        name, text = match.groups()
        if name == "calib_time":
            continue
        try:
            values = np.array([float(v) for v in text.split()])
        except ValueError as exc:
            raise InputError(
                f"{name} has a value that is not a number: {exc}", path, number
            ) from exc
        if not np.all(np.isfinite(values)):
            raise InputError(f"{name} has a value that is not finite", path, number)
        if name in rows:
            raise InputError(f"{name} is given twice (line {rows[name][0]})", path, number)
        rows[name] = (number, values)
    return rows


def _row(rows: dict[str, tuple[int, np.ndarray]], name: str, size: int, path: Path) -> np.ndarray:
    if name not in rows:
        raise InputError(f"no {name}: row", path)
    number, values = rows[name]
    if values.size != size:
        raise InputError(f"{name} has {values.size} values, expected {size}", path, number)
    return values


def _camera(path: Path, camera: str, rectified: bool) -> Camera:
    """Intrinsics (and size, distortion) of ``camera`` from ``calib_cam_to_cam.txt``."""
    rows = read_calib_rows(path)
    n = camera[-2:]
    if rectified:
        P = _row(rows, f"P_rect_{n}", 12, path).reshape(3, 4)
        width, height = _row(rows, f"S_rect_{n}", 2, path)
        distortion = np.zeros(5)
        fx, fy, cx, cy = P[0, 0], P[1, 1], P[0, 2], P[1, 2]
    else:
        K = _row(rows, f"K_{n}", 9, path).reshape(3, 3)
        width, height = _row(rows, f"S_{n}", 2, path)
        distortion = _row(rows, f"D_{n}", 5, path)
        fx, fy, cx, cy = K[0, 0], K[1, 1], K[0, 2], K[1, 2]
    size = [int(v) for v in np.rint([width, height])]
    camera_model = Camera(float(fx), float(fy), float(cx), float(cy), size[0], size[1], distortion)
    return checked_camera(camera_model, path)


def _rigid(rows: dict[str, tuple[int, np.ndarray]], r: str, t: str, path: Path) -> np.ndarray:
    """The 4×4 transform of a rotation row ``r`` (3×3, row-major) and translation row ``t``."""
    T = np.eye(4)
    T[:3, :3] = _row(rows, r, 9, path).reshape(3, 3)
    T[:3, 3] = _row(rows, t, 3, path)
    return T


def _extrinsic(folder: Path, camera: str, rectified: bool) -> tuple[np.ndarray, str]:
    """``T_vehicle_camera`` (camera → OXTS frame) and where it came from (module docstring)."""
    if not ((folder / IMU_TO_VELO).is_file() and (folder / VELO_TO_CAM).is_file()):
        log.warning(
            "%s: no %s and %s: the camera is taken as looking forward from the vehicle origin",
            folder,
            IMU_TO_VELO,
            VELO_TO_CAM,
        )
        return CAMERA_TO_VEHICLE_FORWARD.copy(), "assumed: a forward camera at the OXTS unit"
    velo_imu = _rigid(read_calib_rows(folder / IMU_TO_VELO), "R", "T", folder / IMU_TO_VELO)
    cam0_velo = _rigid(read_calib_rows(folder / VELO_TO_CAM), "R", "T", folder / VELO_TO_CAM)
    path = folder / CAM_TO_CAM
    rows = read_calib_rows(path)
    n = camera[-2:]
    if rectified:
        rect = np.eye(4)
        rect[:3, :3] = _row(rows, "R_rect_00", 9, path).reshape(3, 3)
        P = _row(rows, f"P_rect_{n}", 12, path).reshape(3, 4)
        if not np.linalg.cond(P[:, :3]) < MAX_CONDITION:
            raise InputError(
                f"P_rect_{n}'s left 3×3 part is not a camera matrix (singular): the camera's "
                "offset K⁻¹·P[:, 3] cannot be computed",
                path,
                rows[f"P_rect_{n}"][0],
            )
        shift = np.eye(4)
        shift[:3, 3] = np.linalg.solve(P[:, :3], P[:, 3])
        camera_cam0 = shift @ rect
        used = f"R_rect_00, P_rect_{n}"
    else:
        camera_cam0 = _rigid(rows, f"R_{n}", f"T_{n}", path)
        used = f"R_{n}, T_{n}"
    camera_imu = camera_cam0 @ cam0_velo @ velo_imu
    return np.linalg.inv(camera_imu), f"{IMU_TO_VELO}, {VELO_TO_CAM}, {CAM_TO_CAM} ({used})"
