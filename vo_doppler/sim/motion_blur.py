"""Motion blur and rolling shutter: each pixel integrates the light of its own exposure interval
while the camera moves.

For a static scene seen from a camera that moves from pose T₋ (time −Δ) through T₀ (time 0) to
T₊ (time +Δ), the point seen at pixel p at time 0, at depth Z along the optical axis, projects
at time o to p(o) = π(T(o)⁻¹ T₀ [Z·K⁻¹p, 1]). With the motion linear over a few milliseconds,
p(o) ≈ p + f(o), f(o) = ((Δ − o)·f₋(p) + (Δ + o)·f₊(p)) / 2Δ, f± = p(±Δ) − p. A pixel whose
exposure is centred at ``row_offset`` (rolling shutter: its row is read later or earlier than
the band's middle) and lasts τ collects the mean of the sharp image along the opposite path:

    B(p) = (1/τ) ∫ I₀(p − f(o)) do,   o ∈ [δ(p) − τ/2, δ(p) + τ/2],

evaluated with one bilinear read (``cv2.remap``) per sample at the middles of equal parts of
the exposure. The homogeneous form [K⁻¹p, 1/Z]
keeps the sky (Z = ∞) exact: it moves with the rotation only. Moving vehicles move with the
camera's motion here, not their own, and a path crossing an occlusion edge reads the occluder:
the usual image-space post-process (Potmesil & Chakravarty, "Modeling motion blur in
computer-generated images", SIGGRAPH 1983).
"""

from __future__ import annotations

import cv2
import numpy as np

from vo_doppler.model.camera import Camera


def image_motion(
    depth: np.ndarray, camera: Camera, T_mid: np.ndarray, T_other: np.ndarray
) -> np.ndarray:
    """Image motion (height × width × 2, pixels) of the point seen at every pixel from the pose
    ``T_mid`` to the pose ``T_other`` (camera → world 4×4, pinhole ``camera``)."""
    h, w = depth.shape
    u, v = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))
    x, y = (u - np.float32(camera.cx)) / camera.fx, (v - np.float32(camera.cy)) / camera.fy
    inverse_depth = np.where(np.isfinite(depth), 1.0 / np.maximum(depth, 1e-6), 0.0)
    M = (np.linalg.inv(T_other) @ T_mid).astype(np.float32)
    moved = [M[i, 0] * x + M[i, 1] * y + M[i, 2] + M[i, 3] * inverse_depth for i in range(3)]
    z = np.maximum(moved[2], np.float32(1e-9))
    return np.stack(
        [camera.fx * moved[0] / z + camera.cx - u, camera.fy * moved[1] / z + camera.cy - v],
        axis=-1,
    )


def expose(
    image: np.ndarray,
    depth: np.ndarray,
    camera: Camera,
    poses: np.ndarray,
    half_span_s: float,
    row_offset_s: np.ndarray,
    exposure_s: float,
    max_samples: int = 6,
) -> np.ndarray:
    """The image as exposed (float32; module docstring): ``image`` and ``depth`` rendered at
    ``poses[1]``, ``poses[0]`` and ``poses[2]`` the poses ``half_span_s`` before and after,
    ``row_offset_s`` (height × width) the centre of each pixel's exposure relative to the
    render's time, ``exposure_s`` its length. One sample per pixel of the longest blur path
    (1 to ``max_samples``)."""
    before = image_motion(depth, camera, poses[1], poses[0])
    after = image_motion(depth, camera, poses[1], poses[2])
    span = 2.0 * half_span_s
    longest = exposure_s / span * float(np.max(np.linalg.norm(after - before, axis=-1)))
    samples = int(np.clip(np.ceil(longest) + 1, 1, max_samples)) if longest >= 0.25 else 1
    h, w = depth.shape
    u, v = np.meshgrid(np.arange(w, dtype=np.float32), np.arange(h, dtype=np.float32))
    source = image.astype(np.float32)
    total = np.zeros((h, w), dtype=np.float32)
    spread = ((np.arange(samples) + 0.5) / samples - 0.5) * exposure_s
    for extra in spread:
        o = (row_offset_s + extra)[..., None]
        shift = (((half_span_s - o) * before + (half_span_s + o) * after) / span).astype(np.float32)
        total += cv2.remap(
            source,
            u - shift[..., 0],
            v - shift[..., 1],
            cv2.INTER_LINEAR,
            borderMode=cv2.BORDER_REPLICATE,
        )
    return total / np.float32(samples)
