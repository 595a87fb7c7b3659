"""Error per 100 m on trajectories with a known answer."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from vo_doppler.eval.per_distance import MIN_PATH_M, error_per_100m, too_short_for_distance_figures
from vo_doppler.model.trajectory import Trajectory


def line(n: int, step: float, heading_rad: float = 0.0) -> Trajectory:
    s = np.arange(n) * step
    positions = np.column_stack([s * np.cos(heading_rad), s * np.sin(heading_rad), 0 * s])
    return Trajectory(np.arange(n, dtype=float), positions, Rotation.identity(n))


def test_heading_offset_gives_chord_error_per_window():
    truth = line(301, 1.0)
    estimate = line(301, 1.0, np.radians(2.0))
    result = error_per_100m(estimate, truth)
    expected = 2 * 100.0 * np.sin(np.radians(1.0))
    assert result.n_windows == 201
    assert result.mean_m_per_100m == pytest.approx(expected, rel=1e-9)
    assert result.max_m_per_100m == pytest.approx(expected, rel=1e-9)


def test_translation_only_alignment_ignores_a_constant_offset():
    truth = line(201, 1.0)
    shifted = Trajectory(truth.t, truth.positions + np.array([5.0, -3.0, 1.0]), truth.orientations)
    assert error_per_100m(shifted, truth).max_m_per_100m == pytest.approx(0.0, abs=1e-12)


def test_short_path_is_scaled_to_100m():
    truth = line(51, 1.0)
    estimate = Trajectory(truth.t, truth.positions * 1.01, truth.orientations)
    result = error_per_100m(estimate, truth)
    assert result.window_m == pytest.approx(50.0)
    assert result.mean_m_per_100m == pytest.approx(1.0, rel=1e-9)


@settings(max_examples=30, deadline=None)
@given(st.floats(1.0, 3.0), st.floats(0.0, 6.28), st.integers(150, 400))
def test_scale_error_grows_linearly(scale, heading, n):
    truth = line(n, 1.0, heading)
    estimate = Trajectory(truth.t, truth.positions * scale, truth.orientations)
    result = error_per_100m(estimate, truth)
    assert result.mean_m_per_100m == pytest.approx(100.0 * (scale - 1.0), rel=1e-6, abs=1e-9)


def test_horizontal_error_ignores_height_drift():
    truth = line(201, 1.0)
    climbing = truth.positions.copy()
    climbing[:, 2] = 0.01 * np.arange(201)
    estimate = Trajectory(truth.t, climbing, truth.orientations)
    assert error_per_100m(estimate, truth).mean_m_per_100m == pytest.approx(1.0, rel=1e-9)
    assert error_per_100m(estimate, truth, horizontal=True).max_m_per_100m == pytest.approx(0.0)


@pytest.mark.parametrize(("n", "step"), [(50, 0.0), (50, 1e-9), (50, 0.1)])
def test_a_path_shorter_than_the_minimum_has_no_figure(n, step):
    truth = line(n, step)
    estimate = Trajectory(truth.t, truth.positions + np.array([0.0, 0.01, 0.0]), truth.orientations)
    result = error_per_100m(estimate, truth)
    assert result.mean_m_per_100m is None and result.max_m_per_100m is None
    assert result.n_windows == 0 and result.errors_m.size == 0


def test_the_minimum_path_is_the_boundary():
    assert too_short_for_distance_figures(MIN_PATH_M) is None
    reason = too_short_for_distance_figures(MIN_PATH_M - 0.1)
    assert reason.startswith("the ground-truth path is 4.9 m long, shorter than the 5 m")
    truth = line(51, MIN_PATH_M / 50)
    estimate = Trajectory(truth.t, truth.positions * 1.01, truth.orientations)
    assert error_per_100m(estimate, truth).mean_m_per_100m == pytest.approx(1.0, rel=1e-9)
