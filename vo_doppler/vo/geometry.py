"""Two- and multi-view geometry for the VO: projection, essential-matrix initialisation,
triangulation with parallax and cheirality checks, and PnP. Poses are world→camera 4×4 (T_cw)."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np


def invert_pose(T: np.ndarray) -> np.ndarray:
    """Inverse of rigid transforms (…, 4, 4)."""
    R = T[..., :3, :3]
    t = T[..., :3, 3]
    out = np.zeros_like(T)
    Rt = np.swapaxes(R, -1, -2)
    out[..., :3, :3] = Rt
    out[..., :3, 3] = -np.einsum("...ij,...j->...i", Rt, t)
    out[..., 3, 3] = 1.0
    return out


def make_pose(R: np.ndarray, t: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = np.ravel(t)
    return T


def camera_center(T_cw: np.ndarray) -> np.ndarray:
    return -np.swapaxes(T_cw[..., :3, :3], -1, -2) @ T_cw[..., :3, 3][..., None]


def transform_points(T: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Apply transforms (4, 4) or (N, 4, 4) to points (N, 3)."""
    return np.einsum("...ij,...j->...i", T[..., :3, :3], points) + T[..., :3, 3]


def project(K: np.ndarray, T_cw: np.ndarray, points_world: np.ndarray) -> np.ndarray:
    """Pinhole projection u = π(K · T_cw · X) for (N, 3) points; poses (4, 4) or (N, 4, 4)."""
    pc = transform_points(T_cw, points_world)
    z = pc[:, 2:3]
    return (pc[:, :2] / z) * np.array([K[0, 0], K[1, 1]]) + np.array([K[0, 2], K[1, 2]])


def depths(T_cw: np.ndarray, points_world: np.ndarray) -> np.ndarray:
    return transform_points(T_cw, points_world)[:, 2]


def parallax(center_a: np.ndarray, center_b: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Angle (rad) at each point between the rays to two camera centres."""
    ra = points - center_a.reshape(1, 3)
    rb = points - center_b.reshape(1, 3)
    cos = np.einsum("ij,ij->i", ra, rb) / (
        np.linalg.norm(ra, axis=1) * np.linalg.norm(rb, axis=1) + 1e-300
    )
    return np.arccos(np.clip(cos, -1.0, 1.0))


@dataclass
class Triangulation:
    points: np.ndarray
    valid: np.ndarray


def triangulate(
    K: np.ndarray,
    T_a: np.ndarray,
    T_b: np.ndarray,
    uv_a: np.ndarray,
    uv_b: np.ndarray,
    max_reprojection_px: float,
    min_parallax: float,
) -> Triangulation:
    """Linear (DLT) triangulation from two views; ``valid`` checks depth, error and parallax."""
    if len(uv_a) == 0:
        return Triangulation(np.zeros((0, 3)), np.zeros(0, bool))
    P_a = K @ T_a[:3, :4]
    P_b = K @ T_b[:3, :4]
    homogeneous = cv2.triangulatePoints(P_a, P_b, uv_a.T.astype(float), uv_b.T.astype(float))
    w = homogeneous[3]
    with np.errstate(divide="ignore", invalid="ignore"):
        points = (homogeneous[:3] / w).T
    finite = np.all(np.isfinite(points), axis=1) & (np.abs(w) > 1e-12)
    points[~finite] = 0.0
    valid = finite & (depths(T_a, points) > 0) & (depths(T_b, points) > 0)
    err_a = np.linalg.norm(project(K, T_a, points) - uv_a, axis=1)
    err_b = np.linalg.norm(project(K, T_b, points) - uv_b, axis=1)
    valid &= (err_a < max_reprojection_px) & (err_b < max_reprojection_px)
    angle = parallax(camera_center(T_a).ravel(), camera_center(T_b).ravel(), points)
    valid &= angle >= min_parallax
    return Triangulation(points, valid)


@dataclass
class TwoViewResult:
    T_ba: np.ndarray
    """Pose of view b relative to view a (a→b), unit-length translation."""
    inliers: np.ndarray
    points_a: np.ndarray
    """Triangulated points in view a's frame (rows of ``inliers``), NaN where invalid."""
    valid: np.ndarray
    median_parallax: float


def two_view_geometry(
    K: np.ndarray,
    uv_a: np.ndarray,
    uv_b: np.ndarray,
    ransac_threshold_px: float,
    max_reprojection_px: float,
    min_parallax: float,
) -> TwoViewResult | None:
    """Five-point essential matrix (RANSAC) + cheirality + triangulation with parallax check."""
    if len(uv_a) < 8:
        return None
    E, mask = cv2.findEssentialMat(
        uv_a, uv_b, K, method=cv2.RANSAC, prob=0.999, threshold=ransac_threshold_px
    )
    if E is None or E.shape != (3, 3):
        return None
    _, R, t, pose_mask = cv2.recoverPose(E, uv_a, uv_b, K, mask=mask.copy())
    inliers = pose_mask.ravel() > 0
    T_ba = make_pose(R, t.ravel() / max(np.linalg.norm(t), 1e-12))
    tri = triangulate(K, np.eye(4), T_ba, uv_a, uv_b, max_reprojection_px, min_parallax=0.0)
    valid = tri.valid & inliers
    angles = parallax(np.zeros(3), camera_center(T_ba).ravel(), tri.points[valid])
    median = float(np.median(angles)) if angles.size else 0.0
    valid &= parallax(np.zeros(3), camera_center(T_ba).ravel(), tri.points) >= min_parallax
    return TwoViewResult(T_ba, inliers, tri.points, valid, median)


@dataclass
class PnpResult:
    T_cw: np.ndarray
    inliers: np.ndarray


def solve_pnp(
    K: np.ndarray,
    points_world: np.ndarray,
    uv: np.ndarray,
    T_guess: np.ndarray | None,
    threshold_px: float,
    min_inliers: int,
) -> PnpResult | None:
    """PnP RANSAC (optionally from a guess), then Levenberg–Marquardt refinement on the inliers."""
    if len(uv) < max(min_inliers, 6):
        return None
    obj = points_world.astype(np.float64).reshape(-1, 1, 3)
    img = uv.astype(np.float64).reshape(-1, 1, 2)
    kwargs = {
        "iterationsCount": 100,
        "reprojectionError": threshold_px,
        "confidence": 0.999,
        "flags": cv2.SOLVEPNP_ITERATIVE,
    }
    if T_guess is not None:
        rvec0, _ = cv2.Rodrigues(T_guess[:3, :3])
        tvec0 = T_guess[:3, 3].reshape(3, 1).copy()
        ok, rvec, tvec, inliers = cv2.solvePnPRansac(
            obj, img, K, None, rvec0, tvec0, useExtrinsicGuess=True, **kwargs
        )
    else:
        ok, rvec, tvec, inliers = cv2.solvePnPRansac(obj, img, K, None, **kwargs)
    if not ok or inliers is None or len(inliers) < min_inliers:
        return None
    idx = inliers.ravel()
    rvec, tvec = cv2.solvePnPRefineLM(obj[idx], img[idx], K, None, rvec, tvec)
    R, _ = cv2.Rodrigues(rvec)
    T = make_pose(R, tvec.ravel())
    errors = np.linalg.norm(project(K, T, points_world) - uv, axis=1)
    mask = errors < threshold_px * 2.0
    if mask.sum() < min_inliers or not np.all(np.isfinite(T)):
        return None
    return PnpResult(T, mask)
