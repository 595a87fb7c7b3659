"""The pipelines' evaluation over the time the ground truth covers: a truth that starts late,
one from another time, and a path that does not move; the positions as written against the
truth (not moved to it)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.helpers.heading_table import plain_heading_table
from vo_doppler.eval.pipelines import (
    absolute_position_errors,
    epochs_within,
    evaluate_pipelines,
    evaluation_warnings,
    heading_availability,
)
from vo_doppler.model.trajectory import Trajectory

T0 = 1000.0


def drive(t: np.ndarray, speed: float = 10.0, yaw: float = 0.3) -> Trajectory:
    """A straight drive at ``speed`` (m/s) heading ``yaw`` (rad) from the origin at ``T0``."""
    s = speed * (t - T0)
    positions = np.column_stack([s * np.cos(yaw), s * np.sin(yaw), 0 * s])
    return Trajectory(t, positions, Rotation.from_euler("z", np.full((len(t), 1), yaw)))


T = T0 + np.arange(0.0, 60.0, 0.05)
TABLE = plain_heading_table(T0 + np.arange(0.0, 60.0, 0.5))
USABLE = np.ones(len(TABLE), bool)


def pipelines() -> dict[str, Trajectory]:
    """The dead reckoning alone turned 10° and 40 m off, and a corrected one 3 % long."""
    truth = drive(T)
    turn = Rotation.from_euler("z", np.radians(10.0))
    alone = truth.transformed(turn.as_matrix(), np.array([40.0, -5.0, 0.0]))
    long = Trajectory(T, truth.positions * 1.03, truth.orientations)
    return {"dr": alone, "dr_gps_tc": long}


def test_a_truth_starting_late_is_evaluated_from_its_start():
    late = drive(T[T >= T0 + 0.46])
    trajectories = pipelines()
    errors, per_100m, shown = evaluate_pipelines(trajectories, TABLE, USABLE, late)
    assert set(errors) == set(per_100m) == set(shown) == {"dr", "dr_gps_tc"}
    first = int(np.searchsorted(T, late.t[0]))
    # The dead reckoning alone, turned to the truth's heading at the first common pose, is exact.
    np.testing.assert_allclose(shown["dr"].positions, drive(T).positions, atol=1e-9)
    assert errors["dr"].error_per_100m_m == pytest.approx(0.0, abs=1e-9)
    assert errors["dr"].heading_rmse_deg == pytest.approx(0.0, abs=1e-9)
    # The 3 % long one starts at the truth's position there and drifts 3 m per 100 m.
    np.testing.assert_allclose(shown["dr_gps_tc"].positions[first], late.positions[0], atol=1e-9)
    assert errors["dr_gps_tc"].error_per_100m_m == pytest.approx(3.0, rel=1e-6)
    coverage = errors["dr"].coverage
    assert coverage.starts_after_s == pytest.approx(0.5) and coverage.ends_before_s == 0.0
    assert coverage.evaluated_s == pytest.approx(59.95 - 0.5)
    warnings = evaluation_warnings(trajectories, errors, late)
    assert warnings == [
        "wheel + gyro DR alone, wheel + gyro DR + GPS (tightly coupled): only 59.5 s of the "
        "60.0 s of each trajectory (99%) were evaluated, from 0.50 s after its first pose to "
        "0.00 s before its last: the ground truth covers no more of it in time (moved to the "
        "truth's position at the first pose evaluated)"
    ]


def test_heading_use_counts_only_the_epochs_with_vehicle_signals_inside_the_trajectory():
    """Issue 30: "absolute heading used [% of GNSS epochs]" counted the epochs without vehicle
    signals, where no tightly coupled heading can exist. Vehicle signals over the middle 30 s
    of a 60-s GNSS record, the tight heading used at every epoch they cover; the conventional
    one valid at every epoch, the dead reckoning over the covered 30 s."""
    vehicle = (T0 + 15.0, T0 + 45.0)
    covered = (TABLE.t >= vehicle[0]) & (TABLE.t <= vehicle[1])
    dr = drive(T[epochs_within(T, vehicle)])
    shares = heading_availability(TABLE, covered, {"dr_gps_tc": dr, "dr_gps_conv": dr}, vehicle)
    assert shares["dr_gps_tc"] == 1.0 and shares["dr_gps_conv"] == 1.0
    assert shares["dr"] == shares["vo"] == 0.0
    # without the spans every GNSS epoch counts, as before: about half
    assert heading_availability(TABLE, covered)["dr_gps_tc"] == pytest.approx(61 / 120)
    truth = drive(T)
    errors, _, _ = evaluate_pipelines({"dr_gps_tc": dr}, TABLE, covered, truth, vehicle)
    assert errors["dr_gps_tc"].heading_availability == 1.0


def test_a_truth_covering_all_but_the_last_sample_raises_no_warning():
    truth = drive(T[:-1])
    errors, _, _ = evaluate_pipelines(pipelines(), TABLE, USABLE, truth)
    assert errors["dr"].coverage.ends_before_s == pytest.approx(0.05)
    assert evaluation_warnings(pipelines(), errors, truth) == []


def test_a_truth_from_another_time_is_not_evaluated_and_says_so():
    elsewhere = drive(T + 1000.0)
    trajectories = pipelines()
    errors, per_100m, shown = evaluate_pipelines(trajectories, TABLE, USABLE, elsewhere)
    assert errors == per_100m == shown == {}
    (warning,) = evaluation_warnings(trajectories, errors, elsewhere)
    assert warning == (
        "not evaluated: wheel + gyro DR alone, wheel + gyro DR + GPS (tightly coupled): the "
        "ground truth (GPS time 2000.00 to 2059.95 s) covers fewer than two of their poses "
        "(1000.00 to 1059.95 s)"
    )


def test_a_static_path_has_no_figure_per_distance():
    still = drive(T, speed=0.0)
    trajectories = {
        "dr": Trajectory(T, still.positions + np.array([0.0, 1e-8, 0.0]), still.orientations)
    }
    errors, per_100m, _ = evaluate_pipelines(trajectories, TABLE, USABLE, still)
    figures = errors["dr"]
    for value in (
        figures.error_per_100m_m,
        figures.error_per_100m_max_m,
        figures.error_per_100m_3d_m,
        figures.kitti_translation_pct,
        figures.kitti_rotation_deg_per_100m,
        per_100m["dr"].mean_m_per_100m,
    ):
        assert value is None
    assert figures.heading_rmse_deg == pytest.approx(0.0, abs=1e-9)
    assert evaluation_warnings(trajectories, errors, still) == [
        "the ground-truth path is 0.0 m long, shorter than the 5 m that figures per distance "
        "(error per 100 m, KITTI segment errors, drift in % of the path) need: they are not "
        "available"
    ]


def test_absolute_errors_are_of_the_track_as_written_inside_the_truths_span():
    """A track 3 m east, 4 m north and 5 m up of the truth at its start, drifting 0.1 m/s
    north and sinking 0.05 m/s; the truth covers only its first 20 s."""
    truth = drive(T[T <= T0 + 20.0])
    elapsed = T - T0
    offset = np.column_stack([np.full_like(T, 3.0), 4.0 + 0.1 * elapsed, 5.0 - 0.05 * elapsed])
    written = Trajectory(T, drive(T).positions + offset, drive(T).orientations)
    found = absolute_position_errors(written, truth)
    inside = elapsed[elapsed <= 20.0]
    horizontal = np.hypot(3.0, 4.0 + 0.1 * inside)
    assert found.poses == inside.size
    assert found.start_horizontal_m == pytest.approx(5.0, abs=1e-9)
    assert found.start_vertical_m == pytest.approx(5.0, abs=1e-9)
    assert found.end_horizontal_m == pytest.approx(np.hypot(3.0, 6.0), abs=1e-9)
    assert found.end_vertical_m == pytest.approx(4.0, abs=1e-9)
    assert found.median_horizontal_m == pytest.approx(np.median(horizontal), abs=1e-9)
    assert found.median_vertical_m == pytest.approx(4.5, abs=1e-9)
    # The evaluation moves the track onto the truth: it cannot see the 5 m.
    _, _, shown = evaluate_pipelines({"dr_gps_tc": written}, TABLE, USABLE, truth)
    assert np.linalg.norm(shown["dr_gps_tc"].positions[0] - truth.positions[0]) < 1e-9


def test_no_absolute_error_without_a_pose_inside_the_truths_span():
    assert absolute_position_errors(drive(T), drive(T + 1000.0)) is None
