"""DopplerRows owns its per-row arrays: sorted on construction and read-only, they stay sorted
whatever the caller does to its arrays; rows made from other rows share what did not change;
their frame is a member of VectorFrame."""

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
        with pytest.raises(ValueError, match="read-only"):
            getattr(rows, name)[0] = getattr(rows, name)[1]


def test_rows_made_from_rows_share_the_arrays_that_did_not_change():
    rows = rows_of(np.array([1.0, 2.0]), np.array([4.0, -3.0]), np.array([2.0, 1.0]))
    weight = np.array([5.0, 6.0])
    reweighted = dataclasses.replace(rows, weight=weight)
    for name in set(ROW_ARRAYS) - {"weight"}:
        assert getattr(reweighted, name) is getattr(rows, name)
    assert not np.shares_memory(reweighted.weight, weight)
    weight[0] = -1.0
    np.testing.assert_array_equal(reweighted.weight, [5.0, 6.0])
    np.testing.assert_array_equal(rows.weight, [2.0, 1.0])


def test_rows_made_from_rows_in_another_order_are_sorted_copies():
    rows = rows_of(np.array([1.0, 2.0]), np.array([4.0, -3.0]), np.array([2.0, 1.0]))
    later = dataclasses.replace(rows, t=np.array([3.0, 0.0]))
    np.testing.assert_array_equal(later.t, [0.0, 3.0])
    np.testing.assert_array_equal(later.range_rate, [-3.0, 4.0])
    assert list(later.sat_id) == ["G02", "G01"]
    np.testing.assert_array_equal(rows.range_rate, [4.0, -3.0])
    assert not np.shares_memory(later.range_rate, rows.range_rate)


def test_rows_turned_into_enu_share_everything_but_the_vectors():
    lat, lon = np.radians(35.0), np.radians(139.0)
    ecef = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)]) * 6.4e6
    rows = dataclasses.replace(
        rows_of(np.array([1.0, 2.0]), np.array([4.0, -3.0]), np.array([2.0, 1.0])),
        frame="ecef",
        receiver_ecef=np.tile(ecef, (2, 1)),
    )
    enu = rows.in_enu()
    for name in set(ROW_ARRAYS) - {"los", "sat_velocity"}:
        assert getattr(enu, name) is getattr(rows, name)
    assert enu.receiver_ecef is rows.receiver_ecef
    np.testing.assert_allclose(np.linalg.norm(enu.los, axis=1), 1.0, atol=1e-12)
    assert not np.shares_memory(enu.los, rows.los)


def test_rows_with_the_required_columns_only_share_them_and_keep_the_counts():
    rows = dataclasses.replace(
        rows_of(np.array([1.0, 2.0]), np.array([4.0, -3.0]), np.array([2.0, 1.0])),
        epoch=np.array([0, 1]),
        code=np.array(["D1C", "D1C"]),
        cn0=np.array([40.0, 35.0]),
        receiver_ecef=np.zeros((2, 3)),
        n_no_ephemeris=3,
        missing=("G07@1.000",),
    )
    core = rows.required_only()
    for name in ROW_ARRAYS:
        assert getattr(core, name) is getattr(rows, name)
    assert core.epoch is None and core.code is None and core.cn0 is None
    assert core.receiver_ecef is None
    assert (core.n_no_ephemeris, core.missing, core.frame) == (3, ("G07@1.000",), rows.frame)
    assert rows.cn0 is not None


def test_the_frame_is_a_member_and_an_unknown_one_is_refused():
    rows = rows_of(np.array([0.0, 1.0]), np.zeros(2), np.ones(2))
    ecef = dataclasses.replace(rows, frame="ecef")
    assert rows.frame is VectorFrame.ENU and ecef.frame is VectorFrame.ECEF
    with pytest.raises(ValueError, match=r"^frame must be one of ecef, enu, not 'ECEF'$"):
        dataclasses.replace(rows, frame="ECEF")
