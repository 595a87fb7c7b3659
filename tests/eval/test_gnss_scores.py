"""GNSS outputs scored against ground truth: exact figures on constructed drives."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.heading_table import plain_heading_table
from tests.helpers.velocity import velocity_solution
from vo_doppler.eval.gnss_scores import (
    ErrorStats,
    Thresholds,
    held_course,
    score_gnss,
    score_heading,
    score_positions,
    score_velocity,
    truth_at,
)
from vo_doppler.geo import EnuFrame, course_to_yaw, wrap_angle
from vo_doppler.model.gnss_solutions import SppSolution
from vo_doppler.model.ground_truth import GroundTruth

FRAME = EnuFrame(np.radians(22.3), np.radians(114.18), 10.0)


def straight_truth(t: np.ndarray, speed: float, course_deg: float, **kw) -> GroundTruth:
    """A drive at constant speed along one course (clockwise from north), from the origin."""
    c = np.radians(course_deg)
    distance = speed * (t - t[0])
    enu = np.column_stack([distance * np.sin(c), distance * np.cos(c), np.zeros(t.size)])
    return GroundTruth(t, enu, kw.get("frame", FRAME), kw.get("course"), "test")


def enu_velocity(speed, course_deg) -> np.ndarray:
    c = np.radians(np.asarray(course_deg, dtype=float))
    speed = np.broadcast_to(np.asarray(speed, dtype=float), c.shape)
    return np.column_stack([speed * np.sin(c), speed * np.cos(c), np.zeros(c.size)])


def test_a_two_degree_course_offset_is_two_degrees_everywhere():
    t = np.arange(100.0, 161.0)
    truth = straight_truth(t, 10.0, 30.0)
    epochs = t[5:-5] + 0.5
    velocity = velocity_solution(epochs, enu_velocity(10.0, np.full(epochs.size, 32.0)))
    scores = score_velocity(velocity, truth)
    course = scores.course_error_deg
    assert course.count == epochs.size
    assert course.median == pytest.approx(2.0, abs=1e-9)
    assert course.p95 == pytest.approx(2.0, abs=1e-9)
    assert course.max == pytest.approx(2.0, abs=1e-9)
    assert course.beyond == {5.0: 0, 15.0: 0}
    assert scores.speed_error_mps.max == pytest.approx(0.0, abs=1e-9)
    assert scores.availability == 1.0
    yaw = np.full(epochs.size, course_to_yaw(np.radians(32.0)))
    heading = score_heading(plain_heading_table(epochs, yaw_tc=yaw, yaw_conv=yaw - 0.1), truth)
    assert heading.tight.error_deg.median == pytest.approx(2.0, abs=1e-9)
    assert heading.tight.error_deg.max == pytest.approx(2.0, abs=1e-9)
    assert heading.conventional.error_deg.median == pytest.approx(2.0 + np.degrees(0.1))


def test_known_errors_give_exact_medians_p95_and_counts():
    """21 epochs with course errors 0, 1, …, 20° (alternating sides) and speed errors 0, 0.1,
    …, 2.0 m/s: median 10° and 1.0 m/s, p95 (linear) 19° and 1.9 m/s, 15 beyond 5°, 5 beyond
    15°."""
    t = np.arange(0.0, 31.0)
    truth = straight_truth(t, 10.0, 90.0)
    epochs = t[5:26]
    k = np.arange(21.0)
    sides = np.where(k % 2 == 0, 1.0, -1.0)
    velocity = velocity_solution(epochs, enu_velocity(10.0 + 0.1 * k, 90.0 + sides * k))
    scores = score_velocity(velocity, truth)
    course, speed = scores.course_error_deg, scores.speed_error_mps
    assert (course.median, course.p95, course.max) == pytest.approx((10.0, 19.0, 20.0))
    assert course.beyond == {5.0: 15, 15.0: 5}
    assert (speed.median, speed.p95, speed.max) == pytest.approx((1.0, 1.9, 2.0))
    assert course.to_dict()["beyond_5"] == 15 and course.to_dict()["beyond_15"] == 5


def test_availability_counts_valid_moving_epochs_only():
    t = np.arange(0.0, 41.0)
    truth = straight_truth(t, 5.0, 0.0)
    valid = np.zeros(t.size, dtype=bool)
    valid[:10] = True
    velocity = velocity_solution(t, enu_velocity(5.0, np.zeros(t.size)), valid)
    scores = score_velocity(velocity, truth)
    assert scores.coverage.moving == 41
    assert scores.availability == pytest.approx(10 / 41)
    assert scores.course_error_deg.count == 10


def test_standstill_speeds_of_valid_epochs():
    """Standing still for 10 s between two stretches of driving: the valid epochs' own speeds
    0.0, 0.1, …, 0.8 m/s without 0.4 (not valid): median 0.4, 5 above 0.2 m/s."""
    t = np.arange(0.0, 40.0)
    east = np.concatenate([np.arange(15.0) * 5.0, np.full(10, 70.0), 70.0 + np.arange(1, 16) * 5])
    enu = np.column_stack([east, np.zeros(40), np.zeros(40)])
    truth = GroundTruth(t, enu, FRAME, None, "test")
    epochs = np.arange(15.0, 25.0)
    speeds = np.arange(10) * 0.1
    valid = np.ones(10, dtype=bool)
    valid[4] = False
    velocity = velocity_solution(epochs, enu_velocity(speeds, np.zeros(10)), valid)
    scores = score_velocity(velocity, truth)
    # the last epoch borders the motion again: central differences give it 2.5 m/s
    standing = scores.standstill_speed_mps
    assert scores.coverage.standstill == 9
    assert standing.count == 8
    assert standing.median == pytest.approx(0.4)
    assert standing.max == pytest.approx(0.8)
    assert standing.beyond == {0.2: 5}
    assert scores.coverage.moving == 0 and scores.availability is None


def test_epochs_outside_the_truth_or_in_its_gap_are_counted_not_scored():
    t = np.r_[np.arange(10.0, 21.0), np.arange(30.0, 41.0)]  # a 9-s gap
    truth = straight_truth(t, 10.0, 45.0)
    epochs = np.arange(0.0, 51.0)
    velocity = velocity_solution(epochs, enu_velocity(10.0, np.full(51, 45.0)))
    scores = score_velocity(velocity, truth)
    assert scores.coverage.scored == 22
    assert scores.coverage.outside == 51 - 22
    assert scores.coverage.to_dict()["outside_truth"] == 29
    assert scores.course_error_deg.max == pytest.approx(0.0, abs=1e-9)


def test_no_overlap_is_reported_by_name():
    truth = straight_truth(np.arange(0.0, 10.0), 10.0, 0.0)
    later = np.arange(100.0, 110.0)
    scores = score_gnss(
        truth,
        velocity=velocity_solution(later, enu_velocity(10.0, np.zeros(10))),
        heading=plain_heading_table(np.arange(0.0, 10.0)),
    )
    assert scores.without_overlap() == ["velocity"]
    assert scores.to_dict()["positions"] is None


def test_truth_course_is_held_through_a_stop_and_the_file_course_wins():
    velocity = np.array([[0.0, 5.0, 0], [5.0, 0.0, 0], [0.1, -0.1, 0], [0.0, 0.0, 0], [0, 5, 0]])
    course = held_course(velocity, None, 1.0)
    assert np.degrees(course) == pytest.approx([0.0, 90.0, 90.0, 90.0, 0.0])
    own = np.array([np.nan, np.radians(80.0), np.nan, np.nan, np.nan])
    assert np.degrees(held_course(velocity, own, 1.0)) == pytest.approx([0, 80, 80, 80, 0])
    slow = held_course(np.zeros((3, 3)), None, 1.0)
    assert np.isnan(slow).all()
    starting = held_course(np.array([[0.0, 0.0, 0], [0.0, -3.0, 0]]), None, 1.0)
    assert np.degrees(starting) == pytest.approx([180.0, 180.0])


def test_course_is_interpolated_across_north():
    t = np.array([0.0, 1.0, 2.0])
    enu = np.array([[0.0, 0.0, 0.0], [0.0, 10.0, 0.0], [0.0, 20.0, 0.0]])
    own = np.radians([358.0, 2.0, 2.0])
    at = truth_at(GroundTruth(t, enu, None, own, "test"), np.array([0.5]))
    assert wrap_angle(at.course_rad) == pytest.approx([0.0], abs=1e-9)


def test_tight_heading_counts_only_where_available_and_reliable():
    t = np.arange(0.0, 21.0)
    truth = straight_truth(t, 10.0, 0.0)
    yaw = np.full(21, course_to_yaw(0.0))
    yaw[:5] = np.nan  # unavailable
    reliable = np.ones(21, dtype=bool)
    reliable[5:10] = False
    yaw_conv = np.full(21, course_to_yaw(np.radians(20.0)))
    conv_valid = np.zeros(21, dtype=bool)
    conv_valid[-4:] = True
    table = plain_heading_table(
        t, yaw_tc=yaw, tc_reliable=reliable, yaw_conv=yaw_conv, conv_valid=conv_valid
    )
    scores = score_heading(table, truth)
    assert scores.tight.availability == pytest.approx(11 / 21)
    assert scores.tight.error_deg.count == 11
    assert scores.conventional.availability == pytest.approx(4 / 21)
    assert scores.conventional.error_deg.median == pytest.approx(20.0)
    assert scores.conventional.error_deg.beyond == {5.0: 4, 15.0: 4}


def test_position_errors_in_the_truth_frame():
    t = np.arange(0.0, 11.0)
    truth = straight_truth(t, 10.0, 90.0)
    offset = np.array([3.0, 4.0, -2.0])
    ecef = FRAME.enu_to_ecef(truth.enu + offset)
    valid = np.ones(11, dtype=bool)
    valid[0] = False
    solution = SppSolution(t, ecef, {}, np.full(11, 8), np.zeros(11), np.ones(11), valid, 0)
    scores = score_positions(solution, truth)
    assert scores.availability == pytest.approx(10 / 11)
    assert scores.horizontal_m.median == pytest.approx(5.0, abs=1e-6)
    assert scores.horizontal_m.max == pytest.approx(5.0, abs=1e-6)
    assert scores.vertical_m.p95 == pytest.approx(2.0, abs=1e-6)
    with pytest.raises(ValueError, match="no geodetic frame"):
        score_positions(solution, GroundTruth(truth.t, truth.enu, None, None, "TUM"))


def test_stats_of_nothing_and_thresholds():
    assert ErrorStats.of(np.zeros(0), (5.0,)).to_dict() == {
        "count": 0,
        "median": None,
        "p95": None,
        "max": None,
        "beyond_5": 0,
    }
    with pytest.raises(ValueError):
        Thresholds(moving_mps=0.1, standstill_mps=0.2)


def test_thresholds_choose_moving_epochs():
    t = np.arange(0.0, 21.0)
    truth = straight_truth(t, 2.0, 0.0)
    velocity = velocity_solution(t, enu_velocity(2.0, np.zeros(21)))
    assert score_velocity(velocity, truth).coverage.moving == 0
    slow = Thresholds(moving_mps=1.5)
    assert score_velocity(velocity, truth, slow).coverage.moving == 21
