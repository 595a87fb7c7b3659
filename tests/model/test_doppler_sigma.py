"""A receiver's Doppler σ per (epoch, satellite, code), times matched to the millisecond."""

from __future__ import annotations

import numpy as np

from vo_doppler.model.doppler_sigma import ReportedSigma

SIGMA = ReportedSigma(
    t=np.array([100.0, 100.0, 100.1]),
    sat_id=np.array(["G05", "E11", "G05"]),
    code=np.array(["D1C", "D1C", "D1C"]),
    sigma_mps=np.array([0.05, 0.08, 0.06]),
)


def test_each_row_gets_its_epochs_satellites_and_codes_sigma():
    assert len(SIGMA) == 3
    got = SIGMA.at(
        np.array([100.1, 100.0, 100.0004, 99.9996]),  # within half a millisecond
        np.array(["G05", "E11", "G05", "G05"]),
        np.array(["D1C", "D1C", "D1C", "D1C"]),
    )
    np.testing.assert_array_equal(got, [0.06, 0.08, 0.05, 0.05])


def test_rows_without_a_reported_sigma_are_nan():
    got = SIGMA.at(
        np.array([100.0006, 100.0, 100.0, 100.2]),  # 0.6 ms off, another satellite, code, time
        np.array(["G05", "G06", "G05", "G05"]),
        np.array(["D1C", "D1C", "D5Q", "D1C"]),
    )
    assert np.isnan(got).all()
