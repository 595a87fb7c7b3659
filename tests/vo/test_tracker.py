"""Feature front end: bucketed corners and KLT with the forward–backward check, on images with a
known motion."""

from __future__ import annotations

import cv2
import numpy as np

from vo_doppler.vo.config import VoConfig
from vo_doppler.vo.tracker import FeatureTracker, TrackedFeatures

SIZE = (240, 320)


def _texture(seed: int = 0) -> np.ndarray:
    """Blurred random blobs: corners everywhere, smooth enough for sub-pixel KLT."""
    rng = np.random.default_rng(seed)
    noise = rng.uniform(0, 255, (SIZE[0] // 4, SIZE[1] // 4)).astype(np.float32)
    image = cv2.resize(noise, (SIZE[1], SIZE[0]), interpolation=cv2.INTER_CUBIC)
    return np.clip(cv2.GaussianBlur(image, (0, 0), 1.5), 0, 255).astype(np.uint8)


def _shifted(image: np.ndarray, dx: float, dy: float) -> np.ndarray:
    warp = np.float32([[1, 0, dx], [0, 1, dy]])
    return cv2.warpAffine(image, warp, (SIZE[1], SIZE[0]), flags=cv2.INTER_CUBIC)


def test_detected_corners_are_spread_over_the_grid():
    config = VoConfig(max_features=320, grid_rows=4, grid_cols=8)
    features = FeatureTracker(config).detect(_texture(), TrackedFeatures.empty())
    assert 0.5 * config.max_features <= len(features) <= config.max_features
    rows = (features.points[:, 1] * config.grid_rows // SIZE[0]).astype(int)
    cols = (features.points[:, 0] * config.grid_cols // SIZE[1]).astype(int)
    counts = np.bincount(rows * config.grid_cols + cols, minlength=32)
    assert counts.min() > 0 and counts.max() <= config.max_features // 32
    assert len(np.unique(features.ids)) == len(features)


def test_a_known_shift_is_tracked_and_ids_are_kept():
    tracker = FeatureTracker(VoConfig())
    first = _texture()
    features = tracker.detect(first, TrackedFeatures.empty())
    inner = np.all((features.points > 20) & (features.points < np.array(SIZE[::-1]) - 20), axis=1)
    features = TrackedFeatures(features.points[inner], features.ids[inner])
    result = tracker.track(first, _shifted(first, 3.0, -2.0), features)
    assert result.n_tracked >= 0.95 * len(features)
    kept = np.isin(features.ids, result.features.ids)
    moved = result.features.points - features.points[kept]
    np.testing.assert_allclose(np.median(moved, axis=0), [3.0, -2.0], atol=0.02)
    assert np.percentile(np.linalg.norm(moved - [3.0, -2.0], axis=1), 90) < 0.1
    assert result.median_flow_px == np.median(np.linalg.norm(moved, axis=1))


def test_the_forward_backward_check_drops_points_on_a_changed_region():
    tracker = FeatureTracker(VoConfig())
    first = _texture()
    features = tracker.detect(first, TrackedFeatures.empty())
    second = _shifted(first, 2.0, 0.0)
    second[:, : SIZE[1] // 2] = _texture(seed=7)[:, : SIZE[1] // 2]  # left half replaced
    result = tracker.track(first, second, features)
    left = features.points[:, 0] < SIZE[1] // 2 - 20
    right = features.points[:, 0] > SIZE[1] // 2 + 20
    tracked = np.isin(features.ids, result.features.ids)
    assert tracked[left].mean() < 0.2 < 0.9 < tracked[right].mean()


def test_replenish_only_below_the_configured_fraction():
    config = VoConfig()
    tracker = FeatureTracker(config)
    image = _texture()
    full = tracker.detect(image, TrackedFeatures.empty())
    same, added = tracker.replenish(image, full)
    assert added == 0 and same is full
    few = TrackedFeatures(full.points[:10], full.ids[:10])
    more, added = tracker.replenish(image, few)
    assert added > 0 and len(more) == 10 + added
    assert np.array_equal(more.ids[:10], few.ids) and more.ids[10:].min() > full.ids.max()
