"""Speed from ground-truth poses: its trapezoidal integral between poses is each true step."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from vo_doppler.errors import InputError
from vo_doppler.eval.reference_speed import speed_from_poses
from vo_doppler.model.trajectory import Trajectory


def _line(t: np.ndarray, x: np.ndarray) -> Trajectory:
    positions = np.column_stack([x, np.zeros_like(x), np.zeros_like(x)])
    return Trajectory(t, positions, Rotation.identity(len(t)))


def test_constant_speed_is_recovered_exactly():
    t = 0.1 * np.arange(20)
    speed = speed_from_poses(_line(t, 12.5 * t))
    np.testing.assert_allclose(speed.value, 12.5, rtol=1e-12)
    np.testing.assert_array_equal(speed.t, t)
    assert speed.unit == "m/s"


@settings(max_examples=50, deadline=None)
@given(st.lists(st.floats(0.2, 3.0), min_size=2, max_size=30))
def test_trapezoid_between_poses_is_the_step_length(steps):
    t = np.arange(len(steps) + 1) * 0.1
    x = np.r_[0.0, np.cumsum(steps)]
    speed = speed_from_poses(_line(t, x)).value
    trapezoid = 0.5 * (speed[1:] + speed[:-1]) * 0.1
    step_rate = np.r_[steps[0], steps] / 0.1
    # Either every trapezoid is the step, or (the recursion went negative) the step rate.
    assert np.allclose(trapezoid, steps, rtol=1e-9) or np.allclose(speed, step_rate, rtol=1e-12)
    assert np.all(speed >= 0)


def test_too_few_poses_or_unordered_times_are_refused():
    with pytest.raises(InputError) as too_few:
        speed_from_poses(_line(np.zeros(1), np.zeros(1)), "poses.txt")
    assert str(too_few.value) == "poses.txt: need at least two poses for a speed, got 1"
    with pytest.raises(InputError) as unordered:
        speed_from_poses(_line(np.array([0.0, 0.0, 1.0]), np.arange(3.0)))
    assert str(unordered.value) == (
        "pose times must increase, but pose 1 (t = 0.000000 s) follows t = 0.000000 s"
    )
