"""heading.csv: the conventional velocity's speed σ and HDOP written and read back; files
without those columns read as NaN; the minimal heading CSV (your own heading) and its errors."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

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
    checked = np.array([True, False, False, True])
    gnss = _table().conv_valid
    table = replace(
        _table(),
        conv_gnss_valid=gnss,
        conv_valid=checked,
        sigma_conv=np.where(checked, 0.006, np.nan),
        sigma_conv_gnss=np.where(gnss, 0.002, np.nan),
    )
    path = tmp_path / "heading.csv"
    write_heading_csv(path, table)
    back = read_heading_csv(path)
    np.testing.assert_array_equal(back.conv_valid, [True, False, False, True])
    np.testing.assert_array_equal(back.conv_gnss_valid, [True, False, True, True])
    np.testing.assert_allclose(np.degrees(back.sigma_conv_gnss[[0, 2, 3]]), 0.1146, atol=1e-4)
    np.testing.assert_allclose(np.degrees(back.sigma_conv[[0, 3]]), 0.3438, atol=1e-4)


def test_files_without_the_gnss_only_columns_take_the_checked_ones(tmp_path):
    path = tmp_path / "heading.csv"
    table = replace(_table(), conv_gnss_valid=np.ones(4, dtype=bool))
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


def test_a_minimal_heading_csv_reads_as_the_conventional_heading(tmp_path):
    path = tmp_path / "own.csv"
    path.write_text(
        "gps_time_s,pitch_deg,course_deg,sigma_deg\n"
        "1.2e9,1,90,0.5\n"  # east: yaw 0
        "1200000001.0,1,,\n"  # no heading: not valid, σ may be empty
        "1200000002.0,1,-90,2\n"  # west
        "1200000003.0,1,nan,nan\n"
    )
    table = read_heading_csv(path)
    np.testing.assert_array_equal(table.t, 1.2e9 + np.arange(4.0))
    np.testing.assert_allclose(table.yaw_conv, [0.0, np.nan, -np.pi, np.nan], atol=1e-15)
    np.testing.assert_array_equal(table.conv_valid, [True, False, True, False])
    valid, sigma = table.published_conventional
    np.testing.assert_array_equal(valid, table.conv_valid)
    np.testing.assert_allclose(sigma, np.radians([0.5, np.nan, 2.0, np.nan]))
    np.testing.assert_allclose(table.sigma_conv, sigma)
    assert not table.tc_available.any() and not table.tc_reliable.any()
    assert np.isnan(table.wheel_scale).all() and np.isnan(table.gyro_bias).all()


def test_a_minimal_heading_csv_valid_column_is_honoured(tmp_path):
    path = tmp_path / "own.csv"
    path.write_text("gps_time_s,heading_deg,sigma_deg,valid\n0,0,1,1\n1,0,1,0\n2,0,-1,0\n")
    table = read_heading_csv(path)
    np.testing.assert_array_equal(table.conv_valid, [True, False, False])
    np.testing.assert_allclose(table.yaw_conv, [np.pi / 2, np.nan, np.nan])


@pytest.mark.parametrize(
    ("text", "line", "message"),
    [
        ("gps_time_s,course_deg,heading_deg,sigma_deg\n0,1,2,3\n", 1, "both heading_deg and"),
        ("gps_time_s,course_deg,sigma_deg\n0,90,1\n0,90,1\n", 3, "is not after the previous"),
        ("gps_time_s,course_deg,sigma_deg\n0,90,1\n1,1e9,1\n", 3, "is not a direction"),
        ("gps_time_s,course_deg,sigma_deg\n0,90,1\n1,90,inf\n", 3, "is not a standard dev"),
        ("gps_time_s,course_deg,sigma_deg\n0,90,1\n1,90\n", 3, "row has 2 fields, the header 3"),
        ("gps_time_s,course_deg,sigma_deg\n", None, "header but no rows"),
        ("t,course_deg,sigma_deg\n0,1,1\n", 1, "or a minimal heading CSV: gps_time_s"),
    ],
)
def test_a_bad_minimal_heading_csv_is_named_by_line(tmp_path, text, line, message):
    path = tmp_path / "own.csv"
    path.write_text(text)
    with pytest.raises(InputError, match=message) as error:
        read_heading_csv(path)
    assert error.value.path == path and error.value.line == line


def test_the_minimal_heading_csv_of_docs_formats_reads(tmp_path):
    """The example in docs/formats.md, "Your own absolute heading", is a readable file."""
    text = (Path(__file__).parents[2] / "docs" / "formats.md").read_text()
    section = text.split("## Your own absolute heading", 1)[1]
    example = section.split("```\n", 2)[1]
    path = tmp_path / "own.csv"
    path.write_text(example)
    table = read_heading_csv(path)
    np.testing.assert_allclose(table.t, [1418912345.0, 1418912345.1])
    np.testing.assert_allclose(table.yaw_conv, np.radians([90 - 87.25, 90 - 87.31]))
    np.testing.assert_allclose(table.sigma_conv, np.radians(0.8))
