"""Threshold filter ([KZ] Eq. 9): exact cases."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.lowcost.threshold_filter import threshold_filter


def test_threshold_filter():
    out = threshold_filter(np.array([0.1, -0.1, 0.3, -0.5, 0.2]), 0.2)
    np.testing.assert_array_equal(out, [0.0, 0.0, 0.3, -0.5, 0.2])
    with pytest.raises(ValueError):
        threshold_filter(np.zeros(2), -1.0)
