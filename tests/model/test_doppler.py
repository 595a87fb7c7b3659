"""DopplerRows owns its per-row arrays: sorted on construction, they stay sorted whatever the
caller does to its arrays; their frame is a member of VectorFrame."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from vo_doppler.model.doppler import DopplerRows, VectorFrame

ROW_ARRAYS = ("t", "los", "sat_velocity", "sat_clock_drift", "range_rate", "weight", "sat_id")


def rows_of(t: np.ndarray, range_rate: np.ndarray, weight: np.ndarray) -> DopplerRows:
    return DopplerRows(t, np.eye(3)[:2], np.zeros((2, 3)), 0.5, range_rate, weight, ["G01", "G02"])


def test_rows_given_sorted_are_copied_not_kept_as_the_callers_arrays():
    t, range_rate, weight = np.array([1.0, 2.0]), np.array([4.0, -3.0]), np.array([2.0, 1.0])
    rows = rows_of(t, range_rate, weight)
    t[1], range_rate[0], weight[0] = 0.0, np.nan, -1.0
    np.testing.assert_array_equal(rows.t, [1.0, 2.0])
    np.testing.assert_array_equal(rows.range_rate, [4.0, -3.0])
    np.testing.assert_array_equal(rows.weight, [2.0, 1.0])


def test_rows_sorted_on_construction_are_copies_in_time_order():
    rows = rows_of(np.array([2.0, 1.0]), np.array([-3.0, 4.0]), np.array([1.0, 2.0]))
    np.testing.assert_array_equal(rows.t, [1.0, 2.0])
    np.testing.assert_array_equal(rows.range_rate, [4.0, -3.0])
    np.testing.assert_array_equal(rows.sat_clock_drift, [0.5, 0.5])
    assert list(rows.sat_id) == ["G02", "G01"]
    for name in ROW_ARRAYS:
        getattr(rows, name)[0] = getattr(rows, name)[1]  # each its own writeable array
    rows.weight[1] = 9.0
    assert rows.sat_clock_drift[1] == 0.5 and rows.weight[0] == 1.0


def test_the_frame_is_a_member_and_an_unknown_one_is_refused():
    rows = rows_of(np.array([0.0, 1.0]), np.zeros(2), np.ones(2))
    ecef = dataclasses.replace(rows, frame="ecef")
    assert rows.frame is VectorFrame.ENU and ecef.frame is VectorFrame.ECEF
    with pytest.raises(ValueError, match=r"^frame must be one of ecef, enu, not 'ECEF'$"):
        dataclasses.replace(rows, frame="ECEF")
