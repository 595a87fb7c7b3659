"""The time-order policies: exact outcomes on small series."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.errors import InputError
from vo_doppler.io.time_order import order_samples


def test_error_policy_names_the_line_of_the_sample_going_back():
    with pytest.raises(InputError, match=r"f.csv:12: time goes backwards by 0.5 s in the gyro"):
        order_samples([0.0, 1.0, 0.5], [1, 2, 3], "f.csv", "gyro", np.array([10, 11, 12]))


def test_non_finite_times_are_errors():
    with pytest.raises(InputError, match=r"f.csv:11: gyro time is nan"):
        order_samples([0.0, np.nan], [1, 2], "f.csv", "gyro", np.array([10, 11]))


def test_sort_policy_sorts_small_steps_and_refuses_large_ones():
    t, v, report = order_samples([0.0, 0.3, 0.2, 0.4], [0, 3, 2, 4], None, "can", policy="sort")
    np.testing.assert_array_equal(t, [0.0, 0.2, 0.3, 0.4])
    np.testing.assert_array_equal(v, [0, 2, 3, 4])
    assert report.n_out_of_order == 1 and "1 samples out of time order" in report.problems()[0]
    with pytest.raises(InputError, match="time goes backwards by 5 s"):
        order_samples([0.0, 6.0, 1.0], [0, 1, 2], None, "can", policy="sort")


def test_sorted_duplicates_identical_dropped_conflicting_counted_first_kept():
    t, v, report = order_samples(
        [0.0, 1.0, 1.0, 2.0, 2.0],
        [[0, 0], [1, 1], [1, 1], [2, 2], [9, 2]],
        None,
        "x",
        policy="sort",
    )
    np.testing.assert_array_equal(t, [0.0, 1.0, 2.0])
    np.testing.assert_array_equal(v, [[0, 0], [1, 1], [2, 2]])
    assert (report.n_duplicates, report.n_conflicting_duplicates) == (1, 1)
    assert report.as_dict() == {
        "samples": 5,
        "out_of_order": 0,
        "duplicates": 1,
        "conflicting_duplicates": 1,
    }


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1e6, 1e6, allow_nan=False), min_size=1, max_size=40))
def test_sorted_output_is_strictly_increasing_or_the_input_was_refused(times):
    try:
        t, _, _ = order_samples(times, np.arange(len(times)), None, "x", policy="sort")
    except InputError:
        late = np.maximum.accumulate(times)[:-1] - np.asarray(times)[1:]
        assert late.max() > 0.5
        return
    assert np.all(np.diff(t) > 0)


def test_error_policy_drops_identical_duplicates_and_keeps_their_lines():
    t, v, report = order_samples(
        [0.0, 1.0, 1.0, 1.0, 2.0], [5, 6, 6, 6, 7], "f.csv", "x", np.array([2, 3, 4, 5, 7])
    )
    np.testing.assert_array_equal(t, [0.0, 1.0, 2.0])
    np.testing.assert_array_equal(v, [5, 6, 7])
    assert report.n_duplicates == 2 and report.duplicate_lines == [4, 5]


def test_error_policy_refuses_two_values_at_one_time_naming_both_lines():
    with pytest.raises(InputError) as info:
        order_samples(
            [0.0, 1.0, 1.0, 2.0],
            [[0.0, 5.0], [1.0, 6.0], [1.0, 6.5], [2.0, 7.0]],
            "f.csv",
            "speed rows",
            np.array([2, 3, 4, 6]),
        )
    assert str(info.value) == (
        "f.csv:4: lines 3 and 4 of the speed rows are both at t = 1.000000 s with different "
        "values (line 3: 1, 6; line 4: 1, 6.5): which is the measurement cannot be told; keep "
        "one of them"
    )
