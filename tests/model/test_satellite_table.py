"""Satellite states tabulated per (epoch, satellite): finding each query's row, by the nearest
epoch within a tolerance and the same satellite."""

from __future__ import annotations

import numpy as np

from vo_doppler.model.satellite_table import SatelliteTable


def _table(time, system, prn) -> SatelliteTable:
    n = len(time)
    return SatelliteTable(
        time=np.asarray(time, dtype=float),
        system=np.asarray(system),
        prn=np.asarray(prn),
        position=np.zeros((n, 3)),
        velocity=np.zeros((n, 3)),
        clock_bias_s=np.zeros(n),
        clock_drift=np.zeros(n),
        travel_time_s=np.full(n, 0.07),
    )


TABLE = _table([10.0, 10.0, 11.0, 11.0], ["G", "E", "G", "G"], [5, 5, 5, 7])


def test_each_query_finds_the_row_of_its_nearest_epoch_and_satellite():
    assert len(TABLE) == 4
    rows = TABLE.rows_for(
        [11.0, 10.0, 10.0002, 10.9995, 11.0],
        np.array(["G", "E", "G", "G", "G"]),
        [7, 5, 5, 5, 5],
    )
    np.testing.assert_array_equal(rows, [3, 1, 0, 2, 2])


def test_queries_without_a_row_get_minus_one():
    rows = TABLE.rows_for(
        [10.5, 10.002, 10.0, 10.0, 9.0, 12.0],
        np.array(["G", "G", "G", "R", "G", "G"]),
        [5, 5, 7, 5, 5, 5],
    )
    np.testing.assert_array_equal(rows, [-1, -1, -1, -1, -1, -1])
    # a looser tolerance reaches 2 ms away
    assert TABLE.rows_for([10.002], np.array(["G"]), [5], tolerance_s=0.005)[0] == 0


def test_an_empty_table_matches_nothing():
    empty = _table([], np.array([], dtype="U1"), np.array([], dtype=int))
    np.testing.assert_array_equal(empty.rows_for([10.0, 11.0], np.array(["G", "E"]), [1, 2]), -1)
