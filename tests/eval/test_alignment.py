"""Trajectory alignment on exact cases: Umeyama's similarity with and without scale and on a
mirrored cloud, the closed-form SE(2) about the up axis, Rodrigues' rotation, the first-pose
alignment, and the choice of method."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.choices import values
from vo_doppler.errors import InputError
from vo_doppler.eval.alignment import (
    Alignment,
    align,
    rotation_about,
    se2_about_up,
    umeyama,
)
from vo_doppler.model.trajectory import Trajectory

UP = np.array([0.0, 0.0, 1.0])
SOURCE = np.random.default_rng(7).normal(size=(40, 3)) * [20.0, 10.0, 2.0]


def test_rodrigues_rotation_equals_the_axis_angle_rotation():
    axis = np.array([1.0, -2.0, 0.5])
    expected = Rotation.from_rotvec(0.7 * axis / np.linalg.norm(axis)).as_matrix()
    np.testing.assert_allclose(rotation_about(3.0 * axis, 0.7), expected, atol=1e-15)
    np.testing.assert_allclose(rotation_about(UP, np.pi / 2) @ [1, 0, 0], [0, 1, 0], atol=1e-15)


def test_umeyama_without_scale_keeps_scale_one_and_fits_rotation_and_translation():
    rotation = Rotation.from_euler("ZYX", [0.4, -0.1, 0.2]).as_matrix()
    target = SOURCE @ rotation.T + [5.0, -3.0, 1.0]
    r, t, s = umeyama(SOURCE, target, with_scale=False)
    assert s == 1.0
    np.testing.assert_allclose(r, rotation, atol=1e-12)
    np.testing.assert_allclose(t, [5.0, -3.0, 1.0], atol=1e-10)
    # with scale asked, the scale of a rigid motion is found to be one
    assert umeyama(SOURCE, target, with_scale=True)[2] == pytest.approx(1.0, abs=1e-12)


def test_umeyama_returns_a_proper_rotation_for_a_mirrored_target():
    mirrored = SOURCE * [1.0, 1.0, -1.0]  # a reflection: no rotation maps one onto the other
    r, _, _ = umeyama(SOURCE, mirrored, with_scale=False)
    assert np.linalg.det(r) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-12)


def test_se2_finds_the_turn_about_up_and_the_shift():
    turn = rotation_about(UP, -2.5)
    target = SOURCE @ turn.T + [100.0, 50.0, -4.0]
    r, t, s = se2_about_up(SOURCE, target, 2.0 * UP)
    np.testing.assert_allclose(r, turn, atol=1e-12)
    np.testing.assert_allclose(t, [100.0, 50.0, -4.0], atol=1e-10)
    assert s == 1.0


def test_se2_ignores_a_tilt_it_cannot_represent():
    # the target also pitched by 0.01 rad: the best turn about up is still the yaw alone
    tilt = Rotation.from_euler("ZYX", [0.3, 0.01, 0.0]).as_matrix()
    r, _, _ = se2_about_up(SOURCE, SOURCE @ tilt.T, UP)
    np.testing.assert_allclose(r @ UP, UP, atol=1e-15)
    assert np.arctan2(r[1, 0], r[0, 0]) == pytest.approx(0.3, abs=1e-4)


def _trajectory(positions, yaw) -> Trajectory:
    n = len(positions)
    return Trajectory(np.arange(n, dtype=float), positions, Rotation.from_euler("z", yaw[:, None]))


def test_align_by_method():
    yaw = np.linspace(0.0, 1.0, len(SOURCE))
    truth = _trajectory(SOURCE, yaw)
    turn = rotation_about(UP, 0.8)
    estimate = truth.transformed(turn, [7.0, 8.0, 9.0], scale=0.5)
    assert align(estimate, truth, "none", UP) is estimate
    similar = align(estimate, truth, "sim3", UP)
    np.testing.assert_allclose(similar.positions, truth.positions, atol=1e-9)
    np.testing.assert_allclose(similar.yaw(), truth.yaw(), atol=1e-12)
    # the first pose onto the truth's first pose, orientation included
    start = align(estimate, truth, "start", UP)
    np.testing.assert_allclose(start.matrices[0], truth.matrices[0], atol=1e-12)
    np.testing.assert_allclose(start.yaw(), truth.yaw(), atol=1e-12)
    rigid = truth.transformed(turn, [7.0, 8.0, 9.0])
    np.testing.assert_allclose(align(rigid, truth, "se2", UP).positions, SOURCE, atol=1e-9)


def test_an_unknown_method_is_refused_with_the_choices():
    assert values(Alignment) == ("none", "start", "se2", "sim3")
    truth = _trajectory(SOURCE, np.zeros(len(SOURCE)))
    assert [align(truth, truth, m, UP).positions.shape for m in Alignment] == [SOURCE.shape] * 4
    with pytest.raises(
        InputError,
        match=r"^alignment: unknown alignment 'se3'; choose from none, start, se2, sim3$",
    ):
        align(truth, truth, "se3", UP)
