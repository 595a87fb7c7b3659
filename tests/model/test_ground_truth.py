"""A ground-truth track checks its shapes on construction."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.model.ground_truth import GroundTruth


def test_a_track_of_n_positions_with_a_course_per_time():
    truth = GroundTruth(np.arange(4.0), np.zeros((4, 3)), None, np.full(4, np.nan), "csv")
    assert len(truth) == 4
    assert len(GroundTruth(np.arange(2.0), np.ones((2, 3)), None, None, "tum")) == 2


def test_positions_or_courses_of_another_shape_are_refused():
    with pytest.raises(ValueError, match=r"enu has shape \(4, 2\), expected \(3, 3\)"):
        GroundTruth(np.arange(3.0), np.zeros((4, 2)), None, None, "csv")
    with pytest.raises(ValueError, match="course_rad must have one value per time"):
        GroundTruth(np.arange(3.0), np.zeros((3, 3)), None, np.zeros(2), "csv")
