"""Camera calibration files: KITTI ``calib.txt`` rows and OpenCV/Kalibr-style YAML.

Every camera read is checked: focal lengths positive and finite, principal point and distortion
finite, image size non-negative, and the extrinsic a rigid transform (rotation orthonormal
within 1e-4 with determinant +1, finite translation, last row 0 0 0 1).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from vo_doppler.errors import InputError
from vo_doppler.io.textfile import SMALL_MAX_BYTES, read_text
from vo_doppler.io.yaml_file import load_yaml
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD, Camera


def read_kitti_calib(path: str | Path, row: str = "P0", width: int = 0, height: int = 0) -> Camera:
    """Camera from a KITTI ``calib.txt`` projection row (``P0:`` by default)."""
    path = Path(path)
    lines = read_text(path, "calibration", SMALL_MAX_BYTES).splitlines()
    for number, line in enumerate(lines, start=1):
        if line.startswith(row + ":"):
            try:
                values = [float(v) for v in line.split(":", 1)[1].split()]
            except ValueError as exc:
                raise InputError(f"{row} row has a non-numeric value", path, number) from exc
            if len(values) != 12:
                raise InputError(f"{row} row has {len(values)} values, expected 12", path, number)
            P = np.array(values).reshape(3, 4)
            return checked_camera(Camera(P[0, 0], P[1, 1], P[0, 2], P[1, 2], width, height), path)
    raise InputError(f"no {row}: row in KITTI calibration", path)


def read_yaml_calib(path: str | Path) -> Camera:
    """Camera from an OpenCV/Kalibr-style YAML.

    Accepted keys: ``fx fy cx cy`` (or Kalibr ``intrinsics: [fx, fy, cx, cy]``), ``width height``
    (or ``resolution: [w, h]``), ``distortion`` / ``distortion_coeffs`` (k1 k2 p1 p2 [k3]), and
    ``T_vehicle_camera`` (4×4, camera→vehicle) or Kalibr ``T_cam_imu`` (inverted here).
    """
    path = Path(path)
    data = load_yaml(path, "calibration")
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
    except (TypeError, ValueError, OverflowError) as exc:
        raise InputError(f"calibration YAML has a malformed value: {exc}", path) from exc
    if extrinsic.shape != (4, 4):
        raise InputError(f"extrinsic must be 4x4, got {extrinsic.shape}", path)
    return checked_camera(Camera(fx, fy, cx, cy, width, height, dist, extrinsic), path)


def checked_camera(camera: Camera, path: str | Path) -> Camera:
    """``camera`` when its values are physically possible (module docstring), else an
    :class:`InputError` naming the value."""
    if not (np.isfinite(camera.fx) and np.isfinite(camera.fy) and camera.fx > 0 and camera.fy > 0):
        raise InputError(
            f"focal lengths must be positive, got fx {camera.fx}, fy {camera.fy}", path
        )
    if not (np.isfinite(camera.cx) and np.isfinite(camera.cy)):
        raise InputError(f"principal point is not finite: cx {camera.cx}, cy {camera.cy}", path)
    if camera.width < 0 or camera.height < 0:
        raise InputError(f"image size {camera.width}x{camera.height} is negative", path)
    if not np.all(np.isfinite(camera.distortion)):
        raise InputError("distortion coefficients are not finite", path)
    T = np.asarray(camera.T_vehicle_camera, dtype=float)
    R = T[:3, :3]
    rigid = (
        np.all(np.isfinite(T))
        and np.allclose(T[3], [0.0, 0.0, 0.0, 1.0])
        and np.allclose(R.T @ R, np.eye(3), atol=1e-4)
        and np.linalg.det(R) > 0
    )
    if not rigid:
        raise InputError(
            "the camera extrinsic is not a rigid transform (rotation not orthonormal with "
            "determinant +1, or last row not 0 0 0 1)",
            path,
        )
    return camera


def read_camera(path: str | Path) -> Camera:
    """Camera from a KITTI ``calib.txt`` (has a ``P0:`` row) or a YAML file."""
    path = Path(path)
    if path.suffix.lower() in {".yaml", ".yml"}:
        return read_yaml_calib(path)
    return read_kitti_calib(path)


def write_camera_yaml(path: str | Path, camera: Camera) -> None:
    """Write the YAML that :func:`read_yaml_calib` reads back."""
    data = {
        "model": "pinhole",
        "fx": camera.fx,
        "fy": camera.fy,
        "cx": camera.cx,
        "cy": camera.cy,
        "width": camera.width,
        "height": camera.height,
        "distortion": [float(v) for v in np.asarray(camera.distortion).ravel()],
        "T_vehicle_camera": np.asarray(camera.T_vehicle_camera).tolist(),
    }
    Path(path).write_text(yaml.safe_dump(data, sort_keys=False))
