"""heading.csv: the conventional velocity's speed σ and HDOP written and read back; files
without those columns read as NaN."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.io.heading_csv import read_heading_csv, write_heading_csv
from vo_doppler.model.heading import HeadingTable


def _table(n: int = 4) -> HeadingTable:
    valid = np.array([True, False, True, True])[:n]
    return HeadingTable(
        t=1.2e9 + np.arange(n, dtype=float),
        yaw_tc=np.full(n, 0.3),
        sigma_tc=np.full(n, 0.01),
        tc_reliable=np.ones(n, dtype=bool),
        n_obs_window=np.full(n, 40),
        n_sat_epoch=np.full(n, 9),
        yaw_conv=np.where(valid, 0.31, np.nan),
        conv_valid=valid,
        gyro_bias=np.zeros(n),
        wheel_scale=np.ones(n),
        sigma_conv=np.where(valid, 0.002, np.nan),
        speed_sigma_conv=np.where(valid, [0.031, 0.0, 0.0447, 0.12], np.nan),
        hdop_conv=np.where(valid, [0.72, 0.0, 0.765, 1.5], np.nan),
    )


def test_speed_sigma_and_hdop_round_trip(tmp_path):
    table = _table()
    path = tmp_path / "heading.csv"
    write_heading_csv(path, table)
    header = path.read_text().splitlines()[0].split(",")
    assert {"conv_speed_sigma_mps", "conv_hdop"} <= set(header)
    back = read_heading_csv(path)
    np.testing.assert_allclose(back.speed_sigma_conv, table.speed_sigma_conv, atol=5e-5)
    np.testing.assert_allclose(back.hdop_conv, table.hdop_conv, atol=5e-4)
    assert np.isnan(back.speed_sigma_conv[1]) and np.isnan(back.hdop_conv[1])


def test_files_without_the_columns_read_as_nan(tmp_path):
    path = tmp_path / "heading.csv"
    write_heading_csv(path, _table())
    rows = [line.split(",") for line in path.read_text().splitlines()]
    new = ("conv_speed_sigma_mps", "conv_hdop")
    keep = [i for i, name in enumerate(rows[0]) if name not in new]
    path.write_text("\n".join(",".join(row[i] for i in keep) for row in rows) + "\n")
    back = read_heading_csv(path)
    assert np.isnan(back.speed_sigma_conv).all() and np.isnan(back.hdop_conv).all()
    assert np.isfinite(back.sigma_conv[0])


def test_gnss_only_validity_and_sigma_round_trip_apart_from_the_checked_ones(tmp_path):
    table = _table()
    table.conv_gnss_valid = table.conv_valid
    table.conv_valid = np.array([True, False, False, True])
    table.sigma_conv = np.where(table.conv_valid, 0.006, np.nan)
    table.sigma_conv_gnss = np.where(table.conv_gnss_valid, 0.002, np.nan)
    path = tmp_path / "heading.csv"
    write_heading_csv(path, table)
    back = read_heading_csv(path)
    np.testing.assert_array_equal(back.conv_valid, [True, False, False, True])
    np.testing.assert_array_equal(back.conv_gnss_valid, [True, False, True, True])
    np.testing.assert_allclose(np.degrees(back.sigma_conv_gnss[[0, 2, 3]]), 0.1146, atol=1e-4)
    np.testing.assert_allclose(np.degrees(back.sigma_conv[[0, 3]]), 0.3438, atol=1e-4)


def test_files_without_the_gnss_only_columns_take_the_checked_ones(tmp_path):
    path = tmp_path / "heading.csv"
    table = _table()
    table.conv_gnss_valid = np.ones(4, dtype=bool)
    write_heading_csv(path, table)
    rows = [line.split(",") for line in path.read_text().splitlines()]
    new = ("conv_gnss_valid", "heading_conv_gnss_sigma_deg")
    keep = [i for i, name in enumerate(rows[0]) if name not in new]
    path.write_text("\n".join(",".join(row[i] for i in keep) for row in rows) + "\n")
    back = read_heading_csv(path)
    assert back.conv_gnss_valid is None and back.sigma_conv_gnss is None
    valid, sigma = back.published_conventional
    np.testing.assert_array_equal(valid, back.conv_valid)
    np.testing.assert_array_equal(sigma, back.sigma_conv)


def test_a_header_without_rows_is_an_input_error(tmp_path):
    """The QA case: `correct` on such a file failed with an IndexError (exit 3)."""
    path = tmp_path / "heading.csv"
    write_heading_csv(path, _table())
    path.write_text(path.read_text().splitlines()[0] + "\n")
    with pytest.raises(InputError, match=r"heading\.csv: heading CSV has its header but no rows"):
        read_heading_csv(path)
