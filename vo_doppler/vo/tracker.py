"""Feature front end: bucketed corners, pyramidal KLT with a forward–backward check, track ids."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from vo_doppler.vo.config import VoConfig


@dataclass
class TrackedFeatures:
    """Features of one image: pixel positions (N, 2) float64 and their track ids (N,) int64."""

    points: np.ndarray
    ids: np.ndarray

    @classmethod
    def empty(cls) -> TrackedFeatures:
        return cls(np.zeros((0, 2)), np.zeros(0, dtype=np.int64))

    def __len__(self) -> int:
        return len(self.ids)


@dataclass
class TrackResult:
    features: TrackedFeatures
    n_tracked: int
    n_new: int
    median_flow_px: float


class FeatureTracker:
    """Tracks corners from one image to the next and replenishes them on a spatial grid."""

    def __init__(self, config: VoConfig):
        self.config = config
        self._next_id = 0
        self._lk_params = {
            "winSize": (config.klt_window_px, config.klt_window_px),
            "maxLevel": config.klt_levels,
            "criteria": (
                cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT,
                30,
                config.klt_epsilon_px,
            ),
        }

    def detect(self, image: np.ndarray, existing: TrackedFeatures) -> TrackedFeatures:
        """Add corners in grid cells that hold fewer than their share of features."""
        cfg = self.config
        height, width = image.shape
        per_cell = max(1, cfg.max_features // (cfg.grid_rows * cfg.grid_cols))
        mask = np.full((height, width), 255, np.uint8)
        for x, y in existing.points.astype(int).tolist():
            cv2.circle(mask, (x, y), cfg.min_corner_distance_px, 0, -1)
        cell_rows = np.linspace(0, height, cfg.grid_rows + 1).astype(int)
        cell_cols = np.linspace(0, width, cfg.grid_cols + 1).astype(int)
        counts = np.zeros((cfg.grid_rows, cfg.grid_cols), int)
        if len(existing):
            r = np.clip(np.searchsorted(cell_rows, existing.points[:, 1], "right") - 1, 0, None)
            c = np.clip(np.searchsorted(cell_cols, existing.points[:, 0], "right") - 1, 0, None)
            np.add.at(
                counts, (np.minimum(r, cfg.grid_rows - 1), np.minimum(c, cfg.grid_cols - 1)), 1
            )
        new_points = []
        for i in range(cfg.grid_rows):
            for j in range(cfg.grid_cols):
                wanted = per_cell - counts[i, j]
                if wanted <= 0:
                    continue
                y0, y1, x0, x1 = cell_rows[i], cell_rows[i + 1], cell_cols[j], cell_cols[j + 1]
                corners = cv2.goodFeaturesToTrack(
                    image[y0:y1, x0:x1],
                    maxCorners=int(wanted),
                    qualityLevel=cfg.corner_quality,
                    minDistance=cfg.min_corner_distance_px,
                    mask=mask[y0:y1, x0:x1],
                    blockSize=5,
                )
                if corners is not None:
                    new_points.append(corners.reshape(-1, 2) + np.array([x0, y0], np.float32))
        if not new_points:
            return existing
        points = np.concatenate(new_points).astype(np.float64)
        ids = np.arange(self._next_id, self._next_id + len(points), dtype=np.int64)
        self._next_id += len(points)
        return TrackedFeatures(
            np.vstack([existing.points, points]), np.concatenate([existing.ids, ids])
        )

    def track(
        self,
        previous_image: np.ndarray,
        image: np.ndarray,
        previous: TrackedFeatures,
        guess: np.ndarray | None = None,
    ) -> TrackResult:
        """KLT from ``previous_image`` to ``image`` with a forward–backward consistency check.

        ``guess`` (N, 2), if given, holds predicted positions in ``image`` where the search starts.
        """
        if len(previous) == 0:
            return TrackResult(TrackedFeatures.empty(), 0, 0, float("nan"))
        p0 = previous.points.astype(np.float32).reshape(-1, 1, 2)
        if guess is None:
            p1, status, _ = cv2.calcOpticalFlowPyrLK(
                previous_image, image, p0, None, **self._lk_params
            )
        else:
            p1, status, _ = cv2.calcOpticalFlowPyrLK(
                previous_image,
                image,
                p0,
                guess.astype(np.float32).reshape(-1, 1, 2),
                flags=cv2.OPTFLOW_USE_INITIAL_FLOW,
                **self._lk_params,
            )
        p1 = p1.reshape(-1, 2)
        height, width = image.shape
        inside = (
            (p1[:, 0] >= 0) & (p1[:, 0] < width - 1) & (p1[:, 1] >= 0) & (p1[:, 1] < height - 1)
        )
        good = (status.ravel() == 1) & inside
        if good.any():
            # Only forward survivors are tracked back (KLT treats every point independently).
            p0_back, status_back, _ = cv2.calcOpticalFlowPyrLK(
                image, previous_image, p1[good].reshape(-1, 1, 2), None, **self._lk_params
            )
            fb_error = np.linalg.norm(p0_back.reshape(-1, 2) - p0.reshape(-1, 2)[good], axis=1)
            good[good] = (status_back.ravel() == 1) & (
                fb_error < self.config.forward_backward_max_px
            )
        flow = np.linalg.norm(p1[good] - previous.points[good], axis=1)
        median_flow = float(np.median(flow)) if flow.size else float("nan")
        tracked = TrackedFeatures(p1[good].astype(np.float64), previous.ids[good])
        return TrackResult(tracked, int(good.sum()), 0, median_flow)

    def replenish(
        self, image: np.ndarray, features: TrackedFeatures
    ) -> tuple[TrackedFeatures, int]:
        """Detect new corners when the tracked count fell below the configured fraction."""
        if len(features) >= self.config.replenish_below * self.config.max_features:
            return features, 0
        replenished = self.detect(image, features)
        return replenished, len(replenished) - len(features)
