"""Headed numeric CSV files: columns by name whatever their order and case, comments and blank
lines, bad rows skipped with their lines, vehicle signals bounded, rows in time order, and the
sensor CSVs written and read back exactly."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.io.sensor_csv import (
    YAW_RATE_COLUMN,
    read_numeric_csv,
    read_sensor_csv_with_report,
    read_speed_csv,
    read_yaw_rate_csv,
    write_sensor_csv,
)
from vo_doppler.model.series import SensorSeries


def _write(tmp_path, text: str):
    path = tmp_path / "s.csv"
    path.write_text(text)
    return path


def test_columns_by_name_with_comments_blank_lines_and_an_optional_column(tmp_path):
    path = _write(tmp_path, "# a log\nSpeed_MPS, x ,T\n\n4.0,9,1.0\n# note\n3.5,9,2.0\n")
    columns, report = read_numeric_csv(path, ("t", "speed_mps"), optional=("x", "absent"))
    assert list(columns) == ["t", "speed_mps", "x"]
    np.testing.assert_array_equal(columns["t"], [1.0, 2.0])
    np.testing.assert_array_equal(columns["speed_mps"], [4.0, 3.5])
    assert report.n_rows == 2 and report.row_lines == [4, 6] and report.problems() == []


def test_bad_rows_are_skipped_counted_and_named_by_line(tmp_path):
    rows = [f"{k},{0.01 * k}" for k in range(200)]
    rows[10] = "10,abc"  # line 12
    rows[20] = "20,0.2,7"  # line 22: a field too many
    rows[30] = "30,nan"  # line 32
    rows[40] = "40,9.0"  # line 42: 9 rad/s, beyond a car's
    path = _write(tmp_path, "t,yaw_rate_rad_s\n" + "\n".join(rows) + "\n")
    series, report = read_sensor_csv_with_report(path, YAW_RATE_COLUMN, time_offset_s=100.0)
    assert (report.n_malformed, report.n_non_finite, report.n_out_of_range) == (2, 1, 1)
    assert report.skipped_lines == [12, 22, 32, 42]
    assert len(series) == 196 and series.n_skipped == 4 and series.unit == "rad/s"
    assert series.t[0] == 100.0 and series.t[-1] == 299.0
    (problem,) = report.problems()
    assert problem == (
        f"{path}: skipped 2 malformed, 1 non-finite and 1 out-of-range rows "
        "(yaw_rate_rad_s 9 beyond [-5, 5] rad/s) (first lines: 12, 22, 32, 42)"
    )


def test_a_column_in_the_wrong_unit_is_an_error_naming_the_first_line(tmp_path):
    # deg/s where rad/s is expected: most rows beyond ±5
    rows = [f"{k},{10.0 + k}" for k in range(50)]
    path = _write(tmp_path, "t,yaw_rate_rad_s\n1000,0.1\n" + "\n".join(rows) + "\n")
    with pytest.raises(
        InputError, match=r"s\.csv:3: yaw_rate_rad_s = 10 is outside .* 50 of the 51"
    ):
        read_yaw_rate_csv(path)


def test_missing_columns_an_empty_file_or_no_usable_row_are_errors(tmp_path):
    with pytest.raises(InputError, match=r"s\.csv:2: CSV header 't,v' lacks column\(s\) speed_mps"):
        read_speed_csv(_write(tmp_path, "# c\nt,v\n1,2\n"))
    with pytest.raises(InputError, match=r"s\.csv: CSV file is empty"):
        read_speed_csv(_write(tmp_path, "# only a comment\n"))
    with pytest.raises(InputError, match=r"s\.csv: CSV file has no usable data rows"):
        read_speed_csv(_write(tmp_path, "t,speed_mps\n1,x\n"))


def test_a_row_going_back_in_time_names_its_line(tmp_path):
    with pytest.raises(InputError, match=r"s\.csv.*\b4\b"):
        read_speed_csv(_write(tmp_path, "t,speed_mps\n1,2\n3,2\n2,2\n"))


def test_a_row_repeating_the_one_before_exactly_is_dropped_and_named(tmp_path):
    path = _write(tmp_path, "t,speed_mps\n1,2\n1,2\n2,3\n")
    series, report = read_sensor_csv_with_report(path, "speed_mps")
    np.testing.assert_array_equal(series.t, [1.0, 2.0])
    assert report.problems() == [
        f"{path}: dropped 1 rows repeating the row before exactly (lines 3)"
    ]


def test_written_signals_read_back_to_the_last_bit(tmp_path):
    t = 1.4e9 + np.array([0.0, 0.1, 0.2])
    series = SensorSeries(t, np.array([np.pi / 7, -1e-9, 2.0 / 3.0]))
    path = tmp_path / "gyro.csv"
    write_sensor_csv(path, series, YAW_RATE_COLUMN)
    assert path.read_text().splitlines()[0] == "t,yaw_rate_rad_s"
    back = read_yaw_rate_csv(path)
    np.testing.assert_array_equal(back.t, t)
    np.testing.assert_array_equal(back.value, series.value)
