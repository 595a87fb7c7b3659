"""A comma2k19 segment's ``video.hevc`` → the camera of a sequence folder: grey JPEG frames in
``image_0/``, their times on the log clock in ``times.txt`` and ``calib.yaml``.

The frames are decoded through OpenCV's FFmpeg backend. Frame k is taken at
``global_pose/frame_times[k]``, the logger's clock; the manifest's ``camera.time_offset_s`` (the
log clock → GPS time offset) puts it on GPS time. The intrinsics are those comma2k19 publishes
for its EON road camera at 1164 × 874 px (fx = fy = 910, principal point (582, 437), no
distortion model), scaled to the decoded size if the video was resized. The camera looks along
the device's forward axis (device frame: x forward, y right, z down, as ``frame_orientations``
give it), so in the vehicle frame of the imported ground truth (the device's, with y and z
flipped and turned by the device's mounting, :class:`vo_doppler.io.comma2k19.DeviceMount`) the
optical axis is the device's forward axis: the vehicle's x axis turned back by the mounting's
yaw, pitch and roll. The camera's position on the vehicle is not published: the extrinsic has
no translation.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.io.calibration import write_camera_yaml
from vo_doppler.io.comma2k19 import DeviceMount
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD, Camera

log = logging.getLogger(__name__)

VIDEO = "video.hevc"
IMAGES = "image_0"
TIMES = "times.txt"
CALIB = "calib.yaml"
EON_SIZE_PX = (1164, 874)
EON_FOCAL_PX = 910.0
EON_PRINCIPAL_PX = (582.0, 437.0)
JPEG_QUALITY = 90


@dataclass(frozen=True)
class DecodedVideo:
    frames: int
    width: int
    height: int


def eon_camera(width: int, height: int, mount: DeviceMount) -> Camera:
    """The road camera's intrinsics at ``width`` × ``height`` and its mounting on the vehicle."""
    sx, sy = width / EON_SIZE_PX[0], height / EON_SIZE_PX[1]
    turn = np.eye(4)
    turn[:3, :3] = mount.vehicle_to_device.T
    return Camera(
        fx=EON_FOCAL_PX * sx,
        fy=EON_FOCAL_PX * sy,
        cx=EON_PRINCIPAL_PX[0] * sx,
        cy=EON_PRINCIPAL_PX[1] * sy,
        width=width,
        height=height,
        T_vehicle_camera=turn @ CAMERA_TO_VEHICLE_FORWARD,
    )


def decode_video(
    video: str | Path, frame_times: np.ndarray, output: str | Path, mount: DeviceMount
) -> DecodedVideo:
    """Write the camera of ``output`` (images, ``times.txt``, ``calib.yaml``) from ``video``,
    frame k at ``frame_times[k]``; frames beyond either count are dropped with a warning."""
    video, output = Path(video), Path(output)
    capture = cv2.VideoCapture(str(video))
    if not capture.isOpened():
        raise InputError("cannot open the video (OpenCV's FFmpeg backend)", video)
    folder = output / IMAGES
    folder.mkdir(parents=True, exist_ok=True)
    count, size = 0, None
    try:
        while count < len(frame_times):
            ok, frame = capture.read()
            if not ok:
                break
            grey = cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) if frame.ndim == 3 else frame
            if size is None:
                size = grey.shape[::-1]
            elif grey.shape[::-1] != size:
                raise InputError(
                    f"frame {count} is {grey.shape[1]}×{grey.shape[0]} px, the first was "
                    f"{size[0]}×{size[1]}",
                    video,
                )
            cv2.imwrite(
                str(folder / f"{count:06d}.jpg"), grey, [cv2.IMWRITE_JPEG_QUALITY, JPEG_QUALITY]
            )
            count += 1
            if count % 200 == 0:
                log.info("%s: %d of %d frames decoded", video, count, len(frame_times))
        extra = capture.read()[0] if count == len(frame_times) else False
    finally:
        capture.release()
    if size is None:
        raise InputError("no frame could be decoded", video)
    if count < len(frame_times) or extra:
        log.warning(
            "%s: %s frames in the video for %d frame times; the first %d are used",
            video,
            f"{count}" if count < len(frame_times) else "more",
            len(frame_times),
            count,
        )
    np.savetxt(output / TIMES, np.asarray(frame_times[:count], dtype=float), fmt="%.6f")
    write_camera_yaml(output / CALIB, eon_camera(*size, mount))
    return DecodedVideo(count, *size)
