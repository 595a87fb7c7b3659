"""The classic frame-to-frame monocular VO used as a baseline: FAST corners, KLT, five-point
essential matrix (RANSAC) and ``recoverPose`` on every consecutive image pair, no map, no
bundle adjustment. Step lengths come from a metric source, exactly as for the main pipeline."""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from vo_doppler.vo.geometry import invert_pose, make_pose


@dataclass
class BaselineConfig:
    fast_threshold_grey: int = 20
    min_features: int = 1500
    ransac_threshold_px: float = 1.0


class FrameToFrameVO:
    """``process(image)`` returns the camera→world pose with a unit step per moving frame."""

    def __init__(self, K: np.ndarray, config: BaselineConfig | None = None):
        self.K = K
        self.config = config or BaselineConfig()
        self._detector = cv2.FastFeatureDetector_create(self.config.fast_threshold_grey, True)
        self._previous: np.ndarray | None = None
        self._points = np.zeros((0, 1, 2), np.float32)
        self._T_wc = np.eye(4)

    def _detect(self, image: np.ndarray) -> np.ndarray:
        keypoints = self._detector.detect(image)
        return np.array([k.pt for k in keypoints], np.float32).reshape(-1, 1, 2)

    def process(self, image: np.ndarray) -> np.ndarray:
        if self._previous is None or len(self._points) < 8:
            self._previous = image
            self._points = self._detect(image)
            return self._T_wc.copy()
        moved, status, _ = cv2.calcOpticalFlowPyrLK(self._previous, image, self._points, None)
        good = status.ravel() == 1
        p0, p1 = self._points[good].reshape(-1, 2), moved[good].reshape(-1, 2)
        if len(p0) >= 8:
            E, mask = cv2.findEssentialMat(
                p0, p1, self.K, cv2.RANSAC, 0.999, self.config.ransac_threshold_px
            )
            if E is not None and E.shape == (3, 3):
                _, R, t, _ = cv2.recoverPose(E, p0, p1, self.K, mask=mask)
                T_cur_prev = make_pose(R, t.ravel())
                self._T_wc = self._T_wc @ invert_pose(T_cur_prev)
        self._previous = image
        self._points = p1.reshape(-1, 1, 2)
        if len(self._points) < self.config.min_features:
            self._points = self._detect(image)
        return self._T_wc.copy()
