"""Pinhole camera with OpenCV distortion, read from KITTI ``calib.txt`` or an OpenCV/Kalibr YAML.

Camera frame: OpenCV (x right, y down, z forward). ``T_vehicle_camera`` maps camera
coordinates to vehicle coordinates (vehicle: x forward, y left, z up).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml

from vo_doppler.errors import InputError

CAMERA_TO_VEHICLE_FORWARD = np.array(
    [
        [0.0, 0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0, 0.0],
        [0.0, -1.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
)
"""Default extrinsic of a forward-looking camera: camera z → vehicle x, x → −y, y → −z."""


@dataclass
class Camera:
    fx: float
    fy: float
    cx: float
    cy: float
    width: int = 0
    height: int = 0
    distortion: np.ndarray = field(default_factory=lambda: np.zeros(5))
    T_vehicle_camera: np.ndarray = field(default_factory=lambda: CAMERA_TO_VEHICLE_FORWARD.copy())

    @property
    def K(self) -> np.ndarray:
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def has_distortion(self) -> bool:
        return bool(np.any(np.asarray(self.distortion) != 0.0))

    def project(self, points_camera: np.ndarray) -> np.ndarray:
        """Project camera-frame points (N, 3) to pixels (N, 2), ignoring distortion."""
        p = np.asarray(points_camera, dtype=float)
        return np.column_stack(
            [self.fx * p[:, 0] / p[:, 2] + self.cx, self.fy * p[:, 1] / p[:, 2] + self.cy]
        )

    def to_yaml(self, path: str | Path) -> None:
        data = {
            "model": "pinhole",
            "fx": self.fx,
            "fy": self.fy,
            "cx": self.cx,
            "cy": self.cy,
            "width": self.width,
            "height": self.height,
            "distortion": [float(v) for v in np.asarray(self.distortion).ravel()],
            "T_vehicle_camera": np.asarray(self.T_vehicle_camera).tolist(),
        }
        Path(path).write_text(yaml.safe_dump(data, sort_keys=False))


def read_kitti_calib(path: str | Path, row: str = "P0", width: int = 0, height: int = 0) -> Camera:
    """Camera from a KITTI ``calib.txt`` projection row (``P0:`` by default)."""
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
    except OSError as exc:
        raise InputError(f"cannot read calibration: {exc.strerror or exc}", path) from exc
    for number, line in enumerate(lines, start=1):
        if line.startswith(row + ":"):
            try:
                values = [float(v) for v in line.split(":", 1)[1].split()]
            except ValueError as exc:
                raise InputError(f"{row} row has a non-numeric value", path, number) from exc
            if len(values) != 12:
                raise InputError(f"{row} row has {len(values)} values, expected 12", path, number)
            P = np.array(values).reshape(3, 4)
            return Camera(P[0, 0], P[1, 1], P[0, 2], P[1, 2], width, height)
    raise InputError(f"no {row}: row in KITTI calibration", path)


def read_yaml_calib(path: str | Path) -> Camera:
    """Camera from an OpenCV/Kalibr-style YAML.

    Accepted keys: ``fx fy cx cy`` (or Kalibr ``intrinsics: [fx, fy, cx, cy]``), ``width height``
    (or ``resolution: [w, h]``), ``distortion`` / ``distortion_coeffs`` (k1 k2 p1 p2 [k3]), and
    ``T_vehicle_camera`` (4×4, camera→vehicle) or Kalibr ``T_cam_imu`` (inverted here).
    """
    path = Path(path)
    try:
        data = yaml.safe_load(path.read_text())
    except OSError as exc:
        raise InputError(f"cannot read calibration: {exc.strerror or exc}", path) from exc
    except yaml.YAMLError as exc:
        raise InputError(f"not valid YAML: {exc}", path) from exc
    if isinstance(data, dict) and "cam0" in data:
        data = data["cam0"]
    if not isinstance(data, dict):
        raise InputError("calibration YAML must be a mapping", path)
    try:
        if "intrinsics" in data:
            fx, fy, cx, cy = (float(v) for v in data["intrinsics"])
        else:
            fx, fy, cx, cy = (float(data[k]) for k in ("fx", "fy", "cx", "cy"))
        if "resolution" in data:
            width, height = (int(v) for v in data["resolution"])
        else:
            width, height = int(data.get("width", 0)), int(data.get("height", 0))
        dist = np.zeros(5)
        coeffs = [float(v) for v in data.get("distortion", data.get("distortion_coeffs", []))]
        if len(coeffs) > 5:
            raise InputError(
                f"{len(coeffs)} distortion coefficients; at most 5 (k1 k2 p1 p2 k3)", path
            )
        dist[: len(coeffs)] = coeffs
        if "T_vehicle_camera" in data:
            extrinsic = np.array(data["T_vehicle_camera"], dtype=float)
        elif "T_cam_imu" in data:
            extrinsic = np.linalg.inv(np.array(data["T_cam_imu"], dtype=float))
        else:
            extrinsic = CAMERA_TO_VEHICLE_FORWARD.copy()
    except KeyError as exc:
        raise InputError(f"calibration YAML lacks the key {exc}", path) from exc
    except (TypeError, ValueError) as exc:
        raise InputError(f"calibration YAML has a malformed value: {exc}", path) from exc
    if extrinsic.shape != (4, 4):
        raise InputError(f"extrinsic must be 4x4, got {extrinsic.shape}", path)
    return Camera(fx, fy, cx, cy, width, height, dist, extrinsic)


def read_camera(path: str | Path) -> Camera:
    """Camera from a KITTI ``calib.txt`` (has a ``P0:`` row) or a YAML file."""
    path = Path(path)
    if path.suffix.lower() in {".yaml", ".yml"}:
        return read_yaml_calib(path)
    return read_kitti_calib(path)
