"""Metric scale for monocular VO from a speed signal (wheel speed or GNSS Doppler speed).

Each output step keeps the VO's direction of motion and takes its length from the distance
travelled between the two image times, the integral of speed (trapezoidal rule). Where the VO
saw no motion but the speed says the vehicle moved, the step follows the camera's optical axis.
Steps outside the speed record keep the VO's own step lengths, at the metric scale of the
nearest covered steps: the VO's map carries its scale across a gap in the speed signal, where
holding the last speed would invent a motion.
"""

from __future__ import annotations

import logging

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.model.timeseries import travelled_distance

log = logging.getLogger(__name__)


SCALE_FROM_STEPS = 30


def _nearest_scale(index: int, covered: np.ndarray, moving: np.ndarray, ratio: np.ndarray) -> float:
    """Metric/VO length ratio over the ``SCALE_FROM_STEPS`` covered, moving steps nearest to
    ``index`` (NaN when there are none)."""
    candidates = np.flatnonzero(covered & moving)
    if candidates.size == 0:
        return float("nan")
    nearest = candidates[np.argsort(np.abs(candidates - index), kind="stable")[:SCALE_FROM_STEPS]]
    return float(np.median(ratio[nearest]))


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
    A step with an end outside the speed record keeps its VO length times the scale of the
    nearest covered steps (a warning when an image lies more than 0.5 s outside).
    """
    frame_t = np.asarray(frame_t, dtype=float)
    outside = (frame_t < speed_t[0]) | (frame_t > speed_t[-1])
    distance = np.diff(travelled_distance(speed_t, speed, frame_t, outside="extend"))
    centres = poses_wc[:, :3, 3]
    steps = np.diff(centres, axis=0)
    lengths = np.linalg.norm(steps, axis=1)
    moving_lengths = lengths[lengths > 0]
    reference = float(np.median(moving_lengths)) if moving_lengths.size else 0.0
    seen = lengths > min_relative_step * reference
    directions = np.where(
        seen[:, None], steps / np.where(seen, lengths, 1.0)[:, None], poses_wc[1:, :3, 2]
    )
    covered = ~(outside[:-1] | outside[1:])
    if np.any(~covered):
        if not np.any(covered):
            raise InputError(
                f"the speed record ({speed_t[0]:.3f}..{speed_t[-1]:.3f} s) does not cover any "
                f"step between the image times ({frame_t[0]:.3f}..{frame_t[-1]:.3f} s)"
            )
        ratio = distance / np.where(seen, lengths, 1.0)
        for i in np.flatnonzero(~covered):
            scale = _nearest_scale(i, covered, seen, ratio)
            distance[i] = lengths[i] * scale if np.isfinite(scale) and seen[i] else 0.0
        far = (frame_t < speed_t[0] - 0.5) | (frame_t > speed_t[-1] + 0.5)
        log.log(
            logging.WARNING if np.any(far) else logging.INFO,
            "%d image times lie outside the speed record (%.3f..%.3f s); their steps keep the "
            "VO's own lengths at the scale of the nearest covered steps",
            int(outside.sum()),
            speed_t[0],
            speed_t[-1],
        )
    positions = np.zeros_like(centres)
    positions[1:] = np.cumsum(directions * distance[:, None], axis=0)
    return positions + centres[0]
