"""Trajectory alignment: none, first pose, SE(2) about the up axis, Sim(3) (Umeyama 1991)."""

from __future__ import annotations

from enum import StrEnum

import numpy as np

from vo_doppler.choices import checked
from vo_doppler.model.trajectory import Trajectory


class Alignment(StrEnum):
    """How an estimate is aligned to the ground truth before its errors are taken
    (:func:`align`)."""

    NONE = "none"
    START = "start"
    SE2 = "se2"
    SIM3 = "sim3"


def umeyama(source: np.ndarray, target: np.ndarray, with_scale: bool) -> tuple:
    """Similarity (R, t, s) minimising |target − (s·R·source + t)|² (Umeyama 1991, Eq. 40–42)."""
    mu_s, mu_t = source.mean(axis=0), target.mean(axis=0)
    xs, xt = source - mu_s, target - mu_t
    cov = xt.T @ xs / len(source)
    u, d, vt = np.linalg.svd(cov)
    sign = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        sign[2, 2] = -1.0
    rotation = u @ sign @ vt
    scale = 1.0
    if with_scale:
        var_s = np.sum(xs**2) / len(source)
        scale = float(np.trace(np.diag(d) @ sign) / var_s) if var_s > 0 else 1.0
    translation = mu_t - scale * rotation @ mu_s
    return rotation, translation, scale


def rotation_about(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues rotation matrix for a unit axis and an angle (rad)."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


def se2_about_up(source: np.ndarray, target: np.ndarray, up: np.ndarray) -> tuple:
    """Rotation about ``up`` plus translation minimising position error (closed form)."""
    up = np.asarray(up, dtype=float) / np.linalg.norm(up)
    mu_s, mu_t = source.mean(axis=0), target.mean(axis=0)
    xs, xt = source - mu_s, target - mu_t
    xs_h = xs - np.outer(xs @ up, up)
    xt_h = xt - np.outer(xt @ up, up)
    sin_sum = np.sum(np.cross(xs_h, xt_h) @ up)
    cos_sum = np.sum(np.einsum("ij,ij->i", xs_h, xt_h))
    rotation = rotation_about(up, float(np.arctan2(sin_sum, cos_sum)))
    return rotation, mu_t - rotation @ mu_s, 1.0


def align(estimate: Trajectory, truth: Trajectory, method: Alignment, up: np.ndarray) -> Trajectory:
    """Return ``estimate`` aligned to ``truth`` (same length, matched rows) by ``method`` (a
    :class:`~vo_doppler.choices.ChoiceError` when it names no :class:`Alignment`)."""
    method = checked(Alignment, method, "alignment")
    if method is Alignment.NONE:
        return estimate
    if method is Alignment.START:
        rel = truth.matrices[0] @ np.linalg.inv(estimate.matrices[0])
        return estimate.transformed(rel[:3, :3], rel[:3, 3])
    if method is Alignment.SE2:
        return estimate.transformed(*se2_about_up(estimate.positions, truth.positions, up))
    return estimate.transformed(*umeyama(estimate.positions, truth.positions, True))
