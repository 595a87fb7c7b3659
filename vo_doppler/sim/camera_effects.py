"""A camera whose frames carry the errors of a real one, for the simulator's VO input.

Per frame, in the order light goes through a real camera and its driver:

1. **Rolling shutter and motion blur.** Row v of the raw frame is exposed for ``exposure_s``
   centred on ``t + (v − v_mid)·readout/H`` (v_mid the middle row, so the frame's time stamp is
   the middle row's). The raw rows are grouped into bands of ``band_rows``; each band is
   rendered at the camera pose and with the moving vehicles of its mid-row time, then every
   pixel is moved to its own row's time and blurred over its exposure from its depth and the
   camera motion (``vo_doppler.sim.motion_blur``), so the readout is continuous across bands.
2. **Lens.** The scene is rendered through a pinhole with the true focal lengths
   (``LensMaps.render_camera``) and resampled into the raw frame through the true distortion.
3. **Sensor** (``vo_doppler.sim.sensor``): vignetting, ambient light, auto exposure, shot and
   read noise, saturation.
4. **Rectification** with the calibration (intrinsics and distortion estimated with an error):
   the frame written is the calibration's pinhole image, and ``calib.yaml`` holds that pinhole
   (no distortion), as a KITTI-style rectified sequence does. With an exact calibration the
   residual is only resampling; with an error, straight lines bend slightly and angles are
   scaled, as with a real calibration.

Every effect can be switched off (``distortion`` zeros, ``readout_s`` 0, ``exposure_s`` 0,
``sensor`` None, ``noise`` False); moving
vehicles (``vo_doppler.sim.traffic``) are drawn in whichever band they are seen.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import cv2
import numpy as np

from vo_doppler.model.camera import Camera
from vo_doppler.sim.lens import LensMaps
from vo_doppler.sim.motion_blur import expose
from vo_doppler.sim.render import Renderer
from vo_doppler.sim.scene import Scene
from vo_doppler.sim.sensor import Sensor, SensorConfig
from vo_doppler.sim.traffic import FACES, Vehicle, displacement

BLUR_MARGIN_ROWS = 8
"""Rows rendered beyond a band's own, for the blur paths that reach out of it."""
TRAFFIC_RADIUS_M = 150.0
"""Vehicles farther than this from the camera are not drawn (a few pixels at most)."""


@dataclass(frozen=True)
class CameraEffects:
    """The true lens, the calibration's error on it, the rolling shutter and the sensor.

    Defaults: a wide-angle automotive lens with 18 % barrel distortion in the image corners
    (k1 = −0.30, k2 = 0.10 at fx = 0.625·width), calibrated with k1 off by +0.006 (about one
    pixel at the image's left and right edges); a 25 ms rolling-shutter readout (a 1080p
    automotive sensor reads out in 15–30 ms); the sensor of :class:`SensorConfig`.
    """

    distortion: tuple[float, float, float, float, float] = (-0.30, 0.10, 0.0, 0.0, 0.0)
    distortion_error: tuple[float, float, float, float, float] = (0.006, 0.0, 0.0, 0.0, 0.0)
    readout_s: float = 0.025
    exposure_s: float = 0.004
    band_rows: int = 180
    sensor: SensorConfig | None = field(default_factory=SensorConfig)
    noise: bool = True


def true_and_calibrated(
    pinhole: Camera, calibration: Camera, effects: CameraEffects
) -> tuple[Camera, Camera]:
    """The camera as it is (pinhole intrinsics + the true distortion) and as calibrated
    (``calibration``'s intrinsics + the true distortion + its error)."""
    true = np.asarray(effects.distortion, dtype=float)
    calibrated = true + np.asarray(effects.distortion_error, dtype=float)
    return replace(pinhole, distortion=true), replace(calibration, distortion=calibrated)


class EffectsCamera:
    """Renders the frames of one drive; build once, then call :meth:`frame` for k = 0, 1, …

    ``pinhole`` is the true camera without distortion, ``calibration`` the intrinsics written
    (the same image size), ``frame_times`` the frames' (middle-row) times in the vehicles' clock.
    Poses for :meth:`frame` come from :meth:`band_times`: one camera → world pose per band.
    """

    def __init__(
        self,
        scene: Scene,
        pinhole: Camera,
        calibration: Camera,
        effects: CameraEffects,
        frame_times: np.ndarray,
        seed: int,
        vehicles: list[Vehicle] = (),
    ):
        self.effects = effects
        true, calibrated = true_and_calibrated(pinhole, calibration, effects)
        self.maps = LensMaps.build(true, calibrated)
        self.vehicles = list(vehicles)
        full = Renderer(scene, self.maps.render_camera)
        height = pinhole.height
        step = height if effects.readout_s == 0.0 else max(1, effects.band_rows)
        self.half_span_s = max(
            effects.exposure_s / 2.0, effects.readout_s * step / height / 2, 1e-3
        )
        self._moving = full.plane_tables([p for v in self.vehicles for p in v.planes(0.0)])
        self._start_xy = np.array([v.centre(np.zeros(1))[0] for v in self.vehicles])
        self.bands = []
        for row0 in range(0, height, step):
            row1 = min(row0 + step, height)
            a, b = self.maps.render_rows(row0, row1, BLUR_MARGIN_ROWS)
            middle = (row0 + row1 - 1) / 2.0
            offset = (self.maps.raw_row_of_render[a:b] - middle) * effects.readout_s / height
            self.bands.append((row0, row1, a, full.window(a, b), offset))
        self.sensor = (
            None
            if effects.sensor is None
            else Sensor(
                effects.sensor, frame_times, pinhole.width, height, seed, noise=effects.noise
            )
        )

    def band_times(self, frame_times: np.ndarray) -> np.ndarray:
        """Exposure start, middle and end time of the mid row of every band of every frame
        (N, bands, 3)."""
        height = self.maps.true_camera.height
        middle = np.array([(band[0] + band[1] - 1) / 2.0 for band in self.bands])
        offsets = (middle - (height - 1) / 2.0) * self.effects.readout_s / height
        mid = np.asarray(frame_times, dtype=float)[:, None] + offsets[None, :]
        half = self.half_span_s
        return mid[:, :, None] + np.array([-half, 0.0, half])

    def traffic_tables(self, t: float, centre: np.ndarray) -> dict[str, np.ndarray]:
        """Plane tables of the vehicles within ``TRAFFIC_RADIUS_M`` of ``centre`` at time t."""
        shift = displacement(self.vehicles, t)
        position = self._start_xy.reshape(-1, 2) + shift
        near = np.linalg.norm(position - centre[:2], axis=1) <= TRAFFIC_RADIUS_M
        rows = (np.flatnonzero(near)[:, None] * FACES + np.arange(FACES)).ravel()
        tables = {k: v[rows] for k, v in self._moving.items()}
        offset = np.zeros((len(rows), 3))
        offset[:, :2] = np.repeat(shift[near], FACES, axis=0)
        tables["origin"] = tables["origin"] + offset
        tables["corners"] = tables["corners"] + offset[:, None, :]
        return tables

    def radiance(self, band_poses: np.ndarray, band_times: np.ndarray) -> np.ndarray:
        """The raw frame before the sensor (float32 grey levels) from the camera → world poses
        (bands, 3, 4, 4) at the times (bands, 3) of :meth:`band_times` for one frame."""
        map_x, map_y = self.maps.raw_from_render
        raw = np.empty(map_x.shape, dtype=np.float32)
        effects = self.effects
        for (row0, row1, a, renderer, offset), poses, t in zip(
            self.bands, band_poses, band_times[:, 1], strict=True
        ):
            T = poses[1]
            scene = renderer.with_moving(self.traffic_tables(float(t), T[:3, 3])).render_full(T)
            image = scene.image.astype(np.float32)
            if effects.readout_s > 0.0 or effects.exposure_s > 0.0:
                image = expose(
                    image,
                    scene.depth,
                    renderer.camera,
                    poses,
                    self.half_span_s,
                    offset,
                    effects.exposure_s,
                )
            raw[row0:row1] = cv2.remap(
                image,
                map_x[row0:row1],
                map_y[row0:row1] - np.float32(a),
                cv2.INTER_LINEAR,
                borderMode=cv2.BORDER_REPLICATE,
            )
        return raw

    def frame(self, k: int, band_poses: np.ndarray, band_times: np.ndarray) -> np.ndarray:
        """Frame k as written (rectified, uint8)."""
        raw = self.radiance(band_poses, band_times)
        if self.sensor is not None:
            raw = self.sensor.frame(raw, k)
        rect_x, rect_y = self.maps.rectified_from_raw
        rectified = cv2.remap(
            raw, rect_x, rect_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
        )
        return np.clip(rectified, 0, 255).round().astype(np.uint8)
