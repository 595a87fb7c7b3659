"""fusion.correction: which headings each source hands to the correction."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.fusion.correction import CorrectionConfig, absolute_heading
from vo_doppler.model.heading import HeadingTable


def _table() -> HeadingTable:
    n = 4
    return HeadingTable(
        t=np.arange(n, dtype=float),
        yaw_tc=np.full(n, np.nan),
        sigma_tc=np.full(n, np.nan),
        tc_reliable=np.zeros(n, dtype=bool),
        n_obs_window=np.zeros(n, dtype=int),
        n_sat_epoch=np.full(n, 5),
        yaw_conv=np.array([0.1, 0.2, 0.3, 0.4]),
        conv_valid=np.array([True, False, False, True]),
        gyro_bias=np.zeros(n),
        wheel_scale=np.ones(n),
        sigma_conv=np.array([0.03, np.nan, np.nan, 0.03]),
        conv_gnss_valid=np.array([True, False, True, True]),
        sigma_conv_gnss=np.array([0.01, np.nan, 0.01, 0.01]),
    )


def test_the_conventional_source_is_the_published_method_valid_by_gnss_tests_alone():
    heading = absolute_heading(_table(), "conv", CorrectionConfig())
    np.testing.assert_array_equal(heading.valid, [True, False, True, True])
    np.testing.assert_array_equal(heading.sigma[heading.valid], [0.01, 0.01, 0.01])


def test_a_table_without_gnss_only_flags_uses_its_conventional_validity():
    table = _table()
    table = HeadingTable(**{**table.__dict__, "conv_gnss_valid": None, "sigma_conv_gnss": None})
    heading = absolute_heading(table, "conv", CorrectionConfig())
    np.testing.assert_array_equal(heading.valid, [True, False, False, True])
    np.testing.assert_array_equal(heading.sigma[heading.valid], [0.03, 0.03])


def test_an_unknown_source_is_refused_naming_the_sources():
    with pytest.raises(
        ValueError, match=r"^source: unknown heading source 'gps'; choose from tc, conv, tc\+conv$"
    ):
        absolute_heading(_table(), "gps", CorrectionConfig())
