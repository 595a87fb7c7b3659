"""Metric scale for monocular VO from a speed signal (wheel speed or GNSS Doppler speed).

Each output step keeps the VO's direction of motion and takes its length from the distance
travelled between the two image times, the integral of speed (trapezoidal rule). Where the VO
saw no motion but the speed says the vehicle moved, the step follows the camera's optical axis.
"""

from __future__ import annotations

import logging

import numpy as np

log = logging.getLogger(__name__)


def travelled_distance(speed_t: np.ndarray, speed: np.ndarray, query_t: np.ndarray) -> np.ndarray:
    """Distance travelled since ``speed_t[0]`` at each query time (speed held beyond the ends)."""
    speed_t = np.asarray(speed_t, dtype=float)
    speed = np.asarray(speed, dtype=float)
    cumulative = np.concatenate(
        [[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * np.diff(speed_t))]
    )
    query_t = np.asarray(query_t, dtype=float)
    inside = np.interp(query_t, speed_t, cumulative)
    before = query_t < speed_t[0]
    after = query_t > speed_t[-1]
    inside[before] = (query_t[before] - speed_t[0]) * speed[0]
    inside[after] = cumulative[-1] + (query_t[after] - speed_t[-1]) * speed[-1]
    return inside


def metric_positions(
    poses_wc: np.ndarray,
    frame_t: np.ndarray,
    speed_t: np.ndarray,
    speed: np.ndarray,
    min_relative_step: float = 0.05,
) -> np.ndarray:
    """Camera positions (N, 3) with step lengths from the speed signal, directions from the VO.

    A VO step shorter than ``min_relative_step`` × the median step counts as "no motion seen";
    its direction then comes from the camera's optical axis (z of the camera→world rotation).
    """
    uncovered = (frame_t < speed_t[0] - 0.5) | (frame_t > speed_t[-1] + 0.5)
    if np.any(uncovered):
        log.warning(
            "%d image times lie outside the speed record (%.3f..%.3f s); speed is held there",
            int(uncovered.sum()),
            speed_t[0],
            speed_t[-1],
        )
    distance = np.diff(travelled_distance(speed_t, speed, frame_t))
    centres = poses_wc[:, :3, 3]
    steps = np.diff(centres, axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    moving = lengths[lengths > 0]
    reference = float(np.median(moving)) if moving.size else 0.0
    seen = lengths > min_relative_step * reference
    directions = np.where(
        seen[:, None], steps / np.where(seen, lengths, 1.0)[:, None], poses_wc[1:, :3, 2]
    )
    positions = np.zeros_like(centres)
    positions[1:] = np.cumsum(directions * distance[:, None], axis=0)
    return positions + centres[0]
