"""Metric scale from a speed signal: exact cases."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.errors import InputError
from vo_doppler.model.timeseries import travelled_distance
from vo_doppler.vo.scale import metric_positions


def poses_along_z(centres: np.ndarray) -> np.ndarray:
    poses = np.tile(np.eye(4), (len(centres), 1, 1))
    poses[:, :3, 3] = centres
    return poses


@settings(max_examples=50, deadline=None)
@given(st.floats(0.1, 40.0), st.floats(0.01, 0.5))
def test_constant_speed_gives_exact_steps(speed, dt):
    t = np.arange(20) * dt
    centres = np.column_stack([np.zeros(20), np.zeros(20), 0.37 * np.arange(20)])
    positions = metric_positions(poses_along_z(centres), t, t, np.full(20, speed))
    np.testing.assert_allclose(np.diff(positions[:, 2]), speed * dt, rtol=1e-12)
    np.testing.assert_allclose(positions[:, :2], 0.0)


def test_trapezoid_distance_and_held_speed_outside_the_record():
    t = np.array([0.0, 1.0, 2.0])
    v = np.array([0.0, 2.0, 2.0])
    np.testing.assert_allclose(
        travelled_distance(t, v, np.array([-1.0, 0.5, 1.0, 2.0, 3.0]), outside="extend"),
        [0.0, 0.5, 1.0, 3.0, 5.0],
    )


def test_no_vo_motion_but_moving_follows_the_optical_axis():
    centres = np.array([[0, 0, 0], [0, 0, 1.0], [0, 0, 1.0], [0, 0, 2.0]])
    poses = poses_along_z(centres)
    t = np.arange(4.0)
    positions = metric_positions(poses, t, t, np.full(4, 3.0))
    np.testing.assert_allclose(positions[:, 2], [0.0, 3.0, 6.0, 9.0])


def test_steps_beyond_the_speed_record_keep_the_vo_scale(caplog):
    t = np.arange(40) * 0.1
    true_steps = 1.0 + 0.5 * np.sin(np.arange(39) / 5.0)  # a vehicle that speeds up and slows
    heading = np.cumsum(np.r_[0.0, np.full(38, 0.02)])  # and turns
    truth = np.zeros((40, 3))
    truth[1:, 0] = np.cumsum(true_steps * np.sin(heading))
    truth[1:, 2] = np.cumsum(true_steps * np.cos(heading))
    vo_scale = 0.25
    poses = poses_along_z(vo_scale * truth)
    speed = np.r_[true_steps[0], true_steps] / 0.1
    last = 20  # the speed record ends at frame 20: 1.9 s of images beyond it
    step_speed = 2.0 * true_steps[:last] / 0.1  # trapezoid speeds giving the true steps
    samples = np.empty(last + 1)
    samples[0] = speed[0]
    for i in range(last):
        samples[i + 1] = step_speed[i] - samples[i]
    positions = metric_positions(poses, t, t[: last + 1], samples)
    np.testing.assert_allclose(positions, truth, atol=1e-9)
    assert "outside the speed record" in caplog.text


def test_a_speed_record_that_misses_every_step_is_an_input_error():
    t = np.arange(10.0)
    poses = poses_along_z(np.column_stack([np.zeros(10), np.zeros(10), np.arange(10.0)]))
    with pytest.raises(InputError, match="does not cover any step"):
        metric_positions(poses, t, np.array([20.0, 21.0]), np.array([1.0, 1.0]))
