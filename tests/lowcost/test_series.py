"""Cleaning of sensor series: bad samples counted."""

from __future__ import annotations

import numpy as np

from vo_doppler.lowcost.series import clean_series


def test_clean_series_counts_bad_samples():
    t = np.array([0.0, 1.0, 1.0, np.nan, 3.0, 2.0, 100.0])
    v = np.array([0.0, 1.0, 9.0, 1.0, 3.0, 2.0, np.nan])
    t2, v2, report = clean_series(t, v, "x")
    np.testing.assert_array_equal(t2, [0.0, 1.0, 2.0, 3.0])
    np.testing.assert_array_equal(v2, [0.0, 1.0, 2.0, 3.0])
    assert (report.n_non_finite, report.n_duplicate_times, report.n_unordered) == (2, 1, 1)
    t3, _, report = clean_series(np.array([0.0, 1, 2, 30, 31]), np.zeros(5), "gappy")
    assert report.n_gaps == 1 and report.longest_gap_s == 28.0 and len(t3) == 5
