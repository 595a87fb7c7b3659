"""Lens distortion and rectification for the simulated camera (OpenCV's Brown–Conrady model).

A normalised undistorted point (x, y) = (X/Z, Y/Z) maps to the distorted point

    x_d = x·(1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2 x²)
    y_d = y·(1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2 y²) + 2 p2 x y,     r² = x² + y²

(Brown, "Decentering distortion of lenses", Photogrammetric Engineering 32(3), 1966; the
coefficient order k1 k2 p1 p2 k3 is OpenCV's, so :func:`distort` equals ``cv2.projectPoints``).
The inverse has no closed form: :func:`undistort` solves it by Newton's method on the 2×2
Jacobian, to 1e-12 in normalised units.

A real camera pipeline that feeds a pinhole VO (KITTI's, for one) resamples the raw, distorted
frames into a rectified pinhole image using its *calibrated* intrinsics and distortion, which
are never exact. :class:`LensMaps` builds the two static remaps of that chain: from the raw frame
to the pinhole render it is sampled from (true lens), and from the rectified frame to the raw
frame (calibrated lens). With a calibration equal to the truth the chain is the identity.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from vo_doppler.model.camera import Camera


def _coefficients(distortion) -> tuple[float, float, float, float, float]:
    padded = np.zeros(5)
    values = np.asarray(distortion, dtype=float).ravel()
    padded[: len(values)] = values
    k1, k2, p1, p2, k3 = (float(v) for v in padded)
    return k1, k2, p1, p2, k3


def distort(points: np.ndarray, distortion) -> np.ndarray:
    """Distorted normalised points (N, 2) of undistorted normalised points (N, 2)."""
    k1, k2, p1, p2, k3 = _coefficients(distortion)
    x, y = np.asarray(points, dtype=float).reshape(-1, 2).T
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    return np.column_stack(
        [
            x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
            y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
        ]
    )


def _jacobian(x: np.ndarray, y: np.ndarray, distortion) -> np.ndarray:
    """∂(x_d, y_d)/∂(x, y), shape (N, 2, 2)."""
    k1, k2, p1, p2, k3 = _coefficients(distortion)
    r2 = x * x + y * y
    radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
    d_radial = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2)  # ∂radial/∂(r²)
    jac = np.empty((len(x), 2, 2))
    jac[:, 0, 0] = radial + 2.0 * x * x * d_radial + 2.0 * p1 * y + 6.0 * p2 * x
    jac[:, 0, 1] = 2.0 * x * y * d_radial + 2.0 * p1 * x + 2.0 * p2 * y
    jac[:, 1, 0] = 2.0 * x * y * d_radial + 2.0 * p1 * x + 2.0 * p2 * y
    jac[:, 1, 1] = radial + 2.0 * y * y * d_radial + 6.0 * p1 * y + 2.0 * p2 * x
    return jac


def undistort(points: np.ndarray, distortion, iterations: int = 20) -> np.ndarray:
    """Undistorted normalised points (N, 2) whose :func:`distort` is ``points`` (Newton's method
    from the distorted point; raises ValueError where it does not converge, i.e. outside the
    region where the model is one-to-one)."""
    target = np.asarray(points, dtype=float).reshape(-1, 2)
    estimate = target.copy()
    for _ in range(iterations):
        residual = distort(estimate, distortion) - target
        if np.max(np.abs(residual), initial=0.0) < 1e-12:
            return estimate
        step = np.linalg.solve(_jacobian(*estimate.T, distortion), residual[:, :, None])[:, :, 0]
        estimate -= step
    if np.max(np.abs(distort(estimate, distortion) - target), initial=0.0) > 1e-9:
        raise ValueError("lens distortion is not invertible over the image")
    return estimate


def project_distorted(camera: Camera, points_camera: np.ndarray) -> np.ndarray:
    """Pixels (N, 2) of camera-frame points (N, 3) through the camera's intrinsics and
    distortion (``cv2.projectPoints`` with zero pose)."""
    p = np.asarray(points_camera, dtype=float).reshape(-1, 3)
    distorted = distort(p[:, :2] / p[:, 2:3], camera.distortion)
    return distorted * (camera.fx, camera.fy) + (camera.cx, camera.cy)


def _pixel_grid(width: int, height: int) -> np.ndarray:
    u, v = np.meshgrid(np.arange(width, dtype=float), np.arange(height, dtype=float))
    return np.column_stack([u.ravel(), v.ravel()])


@dataclass
class LensMaps:
    """Static remaps of a distorting camera whose frames are rectified with a calibration.

    ``render_camera`` is the pinhole camera to render (the true focal lengths, the image grown by
    ``margin_px`` plus what the distortion pulls in, so every raw pixel has a source);
    ``raw_from_render`` (map_x, map_y for ``cv2.remap``, each height × width of the true camera)
    gives for every raw pixel its position in the render; ``rectified_from_raw`` gives for every
    pixel of the rectified image (the calibration's pinhole camera, no distortion) its position in
    the raw frame.
    """

    true_camera: Camera
    calibration: Camera
    render_camera: Camera
    raw_from_render: tuple[np.ndarray, np.ndarray]
    rectified_from_raw: tuple[np.ndarray, np.ndarray]
    raw_row_of_render: np.ndarray
    """Raw-frame row (float, through the true distortion) of every render pixel."""

    @classmethod
    def build(cls, true_camera: Camera, calibration: Camera, margin_px: int = 3) -> LensMaps:
        """Maps for a camera with ``true_camera``'s intrinsics and distortion, rectified with
        ``calibration``'s (same image size)."""
        w, h = true_camera.width, true_camera.height
        raw = _pixel_grid(w, h)
        focal = np.array([true_camera.fx, true_camera.fy])
        centre = np.array([true_camera.cx, true_camera.cy])
        rays = undistort((raw - centre) / focal, true_camera.distortion)
        pinhole = rays * focal + centre
        low = np.floor(pinhole.min(axis=0)) - margin_px
        high = np.ceil(pinhole.max(axis=0)) + margin_px
        render_camera = replace(
            true_camera,
            cx=true_camera.cx - low[0],
            cy=true_camera.cy - low[1],
            width=int(high[0] - low[0]) + 1,
            height=int(high[1] - low[1]) + 1,
            distortion=np.zeros(5),
        )
        in_render = (pinhole - low).astype(np.float32)
        calibrated_focal = np.array([calibration.fx, calibration.fy])
        calibrated_centre = np.array([calibration.cx, calibration.cy])
        rectified_rays = (raw - calibrated_centre) / calibrated_focal
        in_raw = distort(rectified_rays, calibration.distortion) * calibrated_focal
        in_raw = (in_raw + calibrated_centre).astype(np.float32)
        render_pixels = _pixel_grid(render_camera.width, render_camera.height)
        render_rays = (render_pixels + low - centre) / focal
        raw_rows = distort(render_rays, true_camera.distortion)[:, 1] * focal[1] + centre[1]
        return cls(
            true_camera,
            calibration,
            render_camera,
            (in_render[:, 0].reshape(h, w), in_render[:, 1].reshape(h, w)),
            (in_raw[:, 0].reshape(h, w), in_raw[:, 1].reshape(h, w)),
            raw_rows.reshape(render_camera.height, render_camera.width),
        )

    def render_rows(self, row0: int, row1: int, margin: int = 0) -> tuple[int, int]:
        """Rows [a, b) of the render that raw rows [row0, row1) read from (bilinear support),
        plus ``margin`` rows either side."""
        rows = self.raw_from_render[1][row0:row1]
        a = max(int(np.floor(rows.min())) - 1 - margin, 0)
        b = min(int(np.ceil(rows.max())) + 2 + margin, self.render_camera.height)
        return a, b
