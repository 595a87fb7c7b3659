"""Heading error and drift figures: exact cases."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.lowcost.dead_reckoning import (
    track_yaw,
)
from vo_doppler.lowcost.drift import drift_rate_deg_per_min, heading_error


def test_track_yaw_and_heading_error_unwrapping():
    yaw = track_yaw(np.array([0.0, 1.0, 1.0, 1.0]), np.array([0.0, 0.0, 5.0, 5.1]))
    np.testing.assert_allclose(yaw[:2], [0.0, np.pi / 2])
    assert np.isnan(yaw[2]) and np.isnan(yaw[3])
    t = np.arange(0.0, 600.0, 1.0)
    error = heading_error(np.radians(t), np.zeros_like(t))
    np.testing.assert_allclose(error, np.radians(t), atol=1e-9)
    assert drift_rate_deg_per_min(t, error) == pytest.approx(60.0)
    assert drift_rate_deg_per_min(t, error, window_s=10.0) == pytest.approx(60.0)
