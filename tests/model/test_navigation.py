"""Broadcast records in columns: parameters by name, subsets, and merging two files' records,
problems, skipped counts and header values."""

from __future__ import annotations

import numpy as np

from vo_doppler.model.navigation import Navigation, NavRecords, concat_records


def _records(prn, toc, channel=None) -> NavRecords:
    n = len(prn)
    params = {"sqrt_a": np.full(n, 5153.7), "channel": np.asarray(channel if channel else [0] * n)}
    return NavRecords(
        np.full(n, "R" if channel else "G"),
        np.asarray(prn),
        np.asarray(toc, dtype=float),
        params,
        np.arange(n) + 8,
    )


def test_records_by_name_and_subset():
    records = _records([3, 5, 9], [0.0, 7200.0, 14400.0])
    assert len(records) == 3
    np.testing.assert_array_equal(records["sqrt_a"], 5153.7)
    part = records.subset(np.array([False, True, True]))
    np.testing.assert_array_equal(part.prn, [5, 9])
    np.testing.assert_array_equal(part.toc, [7200.0, 14400.0])
    np.testing.assert_array_equal(part.line, [9, 10])
    assert len(part["sqrt_a"]) == 2


def test_concatenated_records_keep_their_order():
    both = concat_records(_records([3], [0.0]), _records([5, 9], [1.0, 2.0]))
    np.testing.assert_array_equal(both.prn, [3, 5, 9])
    np.testing.assert_array_equal(both.toc, [0.0, 1.0, 2.0])
    np.testing.assert_array_equal(both.line, [8, 8, 9])


def test_merging_two_files_adds_records_problems_and_skipped_counts():
    klobuchar = np.arange(8.0)
    first = Navigation(
        _records([3], [0.0]),
        _records([1], [0.0], channel=[1]),
        leap_seconds=None,
        problems=("a: one",),
        skipped={"EPH CNAV": 2},
    )
    second = Navigation(
        _records([5], [1.0]),
        _records([2], [1.0], channel=[-4]),
        leap_seconds=18,
        problems=("b: two",),
        klobuchar=klobuchar,
        skipped={"EPH CNAV": 1, "STO LNAV": 4},
    )
    merged = first.merged(second)
    np.testing.assert_array_equal(merged.kepler.prn, [3, 5])
    assert merged.glonass_channels() == {1: 1, 2: -4}
    assert merged.leap_seconds == 18 and merged.klobuchar is klobuchar
    assert merged.problems == ("a: one", "b: two")
    assert merged.skipped == {"EPH CNAV": 3, "STO LNAV": 4}
    assert first.skipped == {"EPH CNAV": 2}  # the merge changes neither input
    # the first file's header values win where both have one
    assert second.merged(first).leap_seconds == 18
    assert (
        Navigation(first.kepler, first.glonass, leap_seconds=17).merged(second).leap_seconds == 17
    )
