"""A receiver's σ per observation row, joined to other rows by (time, system, PRN, code)."""

from __future__ import annotations

import numpy as np

from vo_doppler.model.row_sigma import RowSigma


def _sigma() -> RowSigma:
    return RowSigma(
        time=np.array([10.0, 10.0, 10.0, 11.0]),
        system=np.array(["G", "G", "E", "G"]),
        prn=np.array([5, 5, 5, 5]),
        code=np.array(["D1C", "C1C", "D1C", "D1C"]),
        sigma=np.array([0.1, 3.0, 0.2, 0.4]),
    )


def test_each_row_gets_the_sigma_of_its_own_time_system_satellite_and_code():
    sigma = _sigma()
    assert len(sigma) == 4
    got = sigma.at(
        [11.0, 10.0, 10.0, 10.0],
        np.array(["G", "E", "G", "G"]),
        [5, 5, 5, 5],
        ["D1C", "D1C", "C1C", "D1C"],
    )
    np.testing.assert_array_equal(got, [0.4, 0.2, 3.0, 0.1])


def test_rows_the_receiver_reported_nothing_for_are_nan():
    got = _sigma().at(
        [12.0, 10.0, 10.0, 10.0],  # another epoch, another satellite, system or code
        np.array(["G", "G", "R", "G"]),
        [5, 6, 5, 5],
        ["D1C", "D1C", "D1C", "L1C"],
    )
    assert np.isnan(got).all()


def test_an_empty_table_gives_nan_for_every_row():
    empty = RowSigma(
        np.zeros(0), np.zeros(0, dtype="U1"), np.zeros(0, int), np.zeros(0, "U3"), np.zeros(0)
    )
    assert len(empty) == 0
    got = empty.at([1.0, 2.0], np.array(["G", "E"]), [1, 2], ["D1C", "D1C"])
    assert got.shape == (2,) and np.isnan(got).all()
