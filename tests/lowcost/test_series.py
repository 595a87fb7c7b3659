"""Cleaning of sensor series: bad samples counted."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.errors import InputError
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


@pytest.mark.parametrize("shape", [(0,), (0, 2), (1, 2)])
def test_too_few_samples_of_any_shape_are_an_input_error(shape):
    """Zero rows of (lat, lon) pairs used to fail in a reshape (exit 3)."""
    with pytest.raises(InputError, match=rf"fixes: fewer than 2 usable samples \({shape[0]}\)"):
        clean_series(np.zeros(shape[0]), np.zeros(shape), "fixes")


def test_a_row_with_one_non_finite_column_is_dropped():
    values = np.array([[1.0, 2.0], [np.nan, 3.0], [4.0, 5.0]])
    t, kept, report = clean_series(np.arange(3.0), values, "fixes")
    np.testing.assert_array_equal(t, [0.0, 2.0])
    np.testing.assert_array_equal(kept, [[1.0, 2.0], [4.0, 5.0]])
    assert report.n_non_finite == 1
