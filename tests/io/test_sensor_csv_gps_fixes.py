"""Gyro CSV and GPS CSV/NMEA readers: round trips (property tests), bad rows skipped and counted."""

from __future__ import annotations

import datetime as dt
import logging
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.helpers.nmea import gga, rmc
from vo_doppler.errors import InputError
from vo_doppler.io.gps_fixes import (
    read_gps_csv,
    read_gps_fixes,
    read_nmea,
    utc_to_gps_seconds,
    write_gps_csv,
)
from vo_doppler.io.sensor_csv import (
    FORWARD_ACCELERATION_COLUMN,
    SPEED_COLUMN,
    YAW_RATE_COLUMN,
    read_numeric_csv,
    read_sensor_csv,
    read_sensor_csv_with_report,
    read_speed_csv,
    read_yaw_rate_csv,
    write_sensor_csv,
)
from vo_doppler.model.series import SensorSeries

finite = st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)
yaw_rates = st.floats(-5.0, 5.0, allow_nan=False)  # what a car can report (vo_doppler.bounds)
tmp_settings = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


def in_time_order(rows: list[tuple]) -> list[tuple]:
    """Rows with distinct times, sorted by time (the readers' time-order policy)."""
    return sorted({row[0]: row for row in rows}.values())


@tmp_settings
@given(st.lists(st.tuples(finite, yaw_rates), min_size=1, max_size=50).map(in_time_order))
def test_gyro_csv_round_trip(tmp_path, rows):
    t, rate = np.array(sorted(rows)).T  # sensor times never go backwards (the reader's rule)
    path = tmp_path / "gyro.csv"
    write_sensor_csv(path, SensorSeries(t, rate), YAW_RATE_COLUMN)
    series = read_yaw_rate_csv(path)
    np.testing.assert_array_equal(series.t, t)
    np.testing.assert_array_equal(series.value, rate)
    assert len(series) == len(t) and series.n_skipped == 0


@tmp_settings
@given(
    st.lists(
        st.tuples(finite, st.floats(-90, 90), st.floats(-180, 180), st.floats(0, 100)),
        min_size=1,
        max_size=50,
    ).map(in_time_order)
)
def test_gps_csv_round_trip(tmp_path, rows):
    t, lat, lon, speed = np.array(rows).T
    path = tmp_path / "gps.csv"
    write_gps_csv(path, t, np.radians(lat), np.radians(lon), speed)
    fixes = read_gps_fixes(path)
    np.testing.assert_array_equal(fixes.t, t)
    np.testing.assert_allclose(np.degrees(fixes.lat), lat, atol=1e-12)
    np.testing.assert_allclose(np.degrees(fixes.lon), lon, atol=1e-12)
    np.testing.assert_array_equal(fixes.speed, speed)


def test_gyro_csv_bad_rows_are_skipped_and_counted(tmp_path, caplog):
    path = tmp_path / "gyro.csv"
    path.write_text(
        "# a comment\nt,yaw_rate_rad_s\n0.0,0.1\n0.01,nan\n0.02,abc\n0.03\n\n0.04,0.2\n0.05,inf\n"
    )
    with caplog.at_level(logging.WARNING):
        series = read_yaw_rate_csv(path)
    np.testing.assert_array_equal(series.t, [0.0, 0.04])
    assert series.n_skipped == 4
    _, report = read_numeric_csv(path, ("t", YAW_RATE_COLUMN))
    assert (report.n_malformed, report.n_non_finite) == (2, 2)
    assert report.skipped_lines == [4, 5, 6, 9] and report.row_lines == [3, 8]
    assert "skipped 2 malformed, 2 non-finite and 0 out-of-range rows" in caplog.text


def _speed_rows(n: int, bad: dict[int, str]) -> str:
    """A ``t,speed_mps`` CSV of ``n`` rows at 10 m/s, row k replaced by ``bad[k]``."""
    rows = [f"{0.01 * k:.2f},{bad.get(k, '10.0')}" for k in range(n)]
    return "t,speed_mps\n" + "\n".join(rows) + "\n"


@pytest.mark.parametrize("value", ["1e9", "400", "-10.5"])
def test_an_isolated_speed_beyond_a_car_is_skipped_counted_and_named(tmp_path, caplog, value):
    path = tmp_path / "speed.csv"
    path.write_text(_speed_rows(200, {57: value}))
    with caplog.at_level(logging.WARNING):
        series = read_speed_csv(path)
    assert len(series) == 199 and series.n_skipped == 1 and np.all(series.value == 10.0)
    assert 0.57 not in series.t
    _, report = read_numeric_csv(path, ("t", SPEED_COLUMN))
    assert report.n_out_of_range == 1 and report.skipped_lines == [59]  # header is line 1
    expected = (
        f"{path}: skipped 0 malformed, 0 non-finite and 1 out-of-range rows (speed_mps "
        f"{float(value):g} beyond [-10, 150] m/s) (first lines: 59)"
    )
    assert report.problems() == [expected] and expected in caplog.text


def test_signals_at_a_cars_limits_are_kept(tmp_path):
    path = tmp_path / "speed.csv"
    path.write_text(_speed_rows(4, {0: "-10", 1: "150", 2: "0"}))
    np.testing.assert_array_equal(read_speed_csv(path).value, [-10.0, 150.0, 0.0, 10.0])
    path = tmp_path / "yaw.csv"
    path.write_text(
        "t,yaw_rate_rad_s\n0,-5\n1,5\n2,5.001\n" + "".join(f"{3 + k},0.1\n" for k in range(100))
    )
    series = read_yaw_rate_csv(path)
    assert series.value[:2].tolist() == [-5.0, 5.0] and series.n_skipped == 1
    path = tmp_path / "acc.csv"
    path.write_text("t,forward_acceleration_mps2\n0,-50\n1,50\n")
    assert read_sensor_csv(path, FORWARD_ACCELERATION_COLUMN).value.tolist() == [-50.0, 50.0]


def test_a_column_often_beyond_a_car_is_an_error_naming_the_first_line(tmp_path):
    path = tmp_path / "yaw.csv"  # deg/s written as rad/s: the turns go beyond 5
    rows = [f"{k},{30.0 if 40 <= k < 43 else 1.0}" for k in range(200)]
    path.write_text("t,yaw_rate_rad_s\n" + "\n".join(rows) + "\n")
    with pytest.raises(InputError) as info:
        read_yaw_rate_csv(path)
    assert str(info.value) == (
        f"{path}:42: yaw_rate_rad_s = 30 is outside what a vehicle can report, "
        "[-5, 5] rad/s, and so are 3 of the 200 rows: not isolated bad rows; check the "
        "column's unit"
    )


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty"),
        ("time,rate\n0,1\n", "lacks column"),
        ("t,yaw_rate_rad_s\nx,y\n", "no usable data rows"),
    ],
)
def test_gyro_csv_unusable_files_raise(tmp_path, text, message):
    path = tmp_path / "gyro.csv"
    path.write_text(text)
    with pytest.raises(InputError, match=message) as info:
        read_yaw_rate_csv(path)
    assert str(path) in str(info.value)


def test_missing_file_raises_input_error(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        read_yaw_rate_csv(tmp_path / "absent.csv")
    with pytest.raises(InputError, match="cannot read"):
        read_gps_fixes(tmp_path / "absent.nmea")


def test_gps_csv_out_of_range_fixes_skipped(tmp_path):
    path = tmp_path / "gps.csv"
    path.write_text("t,lat_deg,lon_deg\n0,10,20\n1,95,20\n2,10,200\n3,nan,1\n4,10.5,20.5\n")
    fixes = read_gps_csv(path)
    np.testing.assert_array_equal(fixes.t, [0.0, 4.0])
    assert fixes.n_skipped == 3 and np.all(np.isnan(fixes.speed))


def test_a_row_repeated_exactly_is_dropped_with_a_warning_naming_its_line(tmp_path, caplog):
    path = tmp_path / "speed.csv"
    path.write_text("t,speed_mps\n0.0,10.0\n0.1,10.5\n0.1,10.5\n# note\n0.1,10.5\n0.2,11.0\n")
    with caplog.at_level(logging.WARNING):
        series, report = read_sensor_csv_with_report(path, SPEED_COLUMN)
    np.testing.assert_array_equal(series.t, [0.0, 0.1, 0.2])
    np.testing.assert_array_equal(series.value, [10.0, 10.5, 11.0])
    expected = f"{path}: dropped 2 rows repeating the row before exactly (lines 4, 6)"
    assert report.problems() == [expected] and expected in caplog.text


def test_two_values_at_one_time_are_an_error_naming_the_file_and_both_lines(tmp_path):
    """Which of the two is the measurement cannot be told: the first one was kept silently."""
    path = tmp_path / "yaw.csv"
    path.write_text("t,yaw_rate_rad_s\n0.0,0.01\n0.1,0.02\n0.1,0.05\n0.2,0.03\n")
    with pytest.raises(InputError, match=r"yaw\.csv:4: lines 3 and 4 of the yaw\.csv rows are "):
        read_yaw_rate_csv(path)


def test_nmea_gga_rmc_pairs_give_gps_time_and_speed(tmp_path):
    start = dt.datetime(2024, 6, 24, 8, 20, 0)
    lines = []
    for i in range(5):
        moment = start + dt.timedelta(seconds=0.5 * i)
        lines += [gga(moment.time(), 48.1 + i * 1e-5, -11.5, 1), rmc(moment, 48.1, -11.5, 10.0)]
    lines.insert(3, gga(start.time(), 1.0, 1.0).replace("*", "0*"))  # bad checksum
    lines.append(gga((start + dt.timedelta(seconds=9)).time(), 48.2, -11.5, quality=0))
    lines.append(rmc(start + dt.timedelta(seconds=9), 48.2, -11.5, 0.0, status="V"))
    path = tmp_path / "log.nmea"
    path.write_text("\n".join(["garbage line", *lines]) + "\n")
    fixes = read_gps_fixes(path)
    expected_t0 = (start - dt.datetime(1980, 1, 6)).total_seconds() + 18.0
    np.testing.assert_allclose(fixes.t, expected_t0 + 0.5 * np.arange(5))
    np.testing.assert_allclose(np.degrees(fixes.lat), 48.1 + np.arange(5) * 1e-5, atol=1e-9)
    np.testing.assert_allclose(np.degrees(fixes.lon), -11.5, atol=1e-9)
    np.testing.assert_allclose(fixes.speed, 10.0 * 1852 / 3600)
    assert fixes.n_skipped == 3 and fixes.time_system == "gps"


def test_nmea_midnight_roll_over_and_gga_only(tmp_path):
    before = dt.datetime(2020, 12, 31, 23, 59, 59)
    after = before + dt.timedelta(seconds=2)
    path = tmp_path / "midnight.nmea"
    path.write_text("\n".join([rmc(before, 1.0, 2.0, 1.0), gga(after.time(), 1.0, 2.0)]) + "\n")
    fixes = read_nmea(path)
    assert fixes.t[1] - fixes.t[0] == pytest.approx(2.0)
    gga_only = tmp_path / "gga.nmea"
    gga_only.write_text(gga(dt.time(1, 2, 3, 500000), 1.0, 2.0) + "\n")
    fixes = read_nmea(gga_only)
    assert fixes.time_system == "utc-seconds-of-day" and fixes.t[0] == pytest.approx(3723.5)
    empty = tmp_path / "empty.nmea"
    empty.write_text(gga(dt.time(1, 2, 3), 1.0, 2.0, quality=0) + "\n")
    with pytest.raises(InputError, match="no GGA or RMC fix"):
        read_nmea(empty)


def _rmc_log(tmp_path, knots: list[float]) -> Path:
    """An RMC sentence a second with these speeds (knots), line k + 1 for speed k."""
    start = dt.datetime(2024, 6, 24, 8, 20, 0)
    path = tmp_path / "speeds.nmea"
    moments = [start + dt.timedelta(seconds=k) for k in range(len(knots))]
    path.write_text(
        "".join(f"{rmc(m, 48.1, -11.5, v)}\n" for m, v in zip(moments, knots, strict=True))
    )
    return path


def test_nmea_isolated_absurd_speeds_skip_their_sentence_with_a_warning(tmp_path, caplog):
    """1e9 knots and a negative speed over ground (a magnitude) are no vehicle's: their
    sentences are skipped and named, the other 198 read."""
    knots = [10.0] * 200
    knots[50], knots[60] = 1e9, -3.0
    path = _rmc_log(tmp_path, knots)
    with caplog.at_level(logging.WARNING):
        fixes = read_nmea(path)
    assert len(fixes.t) == 198 and fixes.n_skipped == 2
    np.testing.assert_allclose(fixes.speed, 10.0 * 1852 / 3600)
    assert (
        f"{path}: skipped 2 RMC sentences with a speed over ground outside [0, 150] m/s "
        "(first 5.14444e+08 m/s; lines 51, 61)"
    ) in caplog.text


def test_nmea_speeds_out_of_range_beyond_one_percent_are_an_error_naming_the_line(tmp_path):
    knots = [10.0] * 100
    knots[40], knots[70] = 400.0, 500.0  # 2 % beyond 150 m/s (291.6 knots)
    path = _rmc_log(tmp_path, knots)
    expected = (
        f"{path}:41: RMC speed over ground 205.778 m/s (400 knots) is outside what a vehicle "
        "can report, [0, 150] m/s, and so are 2 of the 100 RMC speeds: not isolated bad "
        "sentences; check the receiver's output"
    )
    with pytest.raises(InputError, match=f"^{re.escape(expected)}$"):
        read_nmea(path)


def test_nmea_gga_keeps_its_fix_when_the_rmc_speed_at_its_time_is_skipped(tmp_path):
    start = dt.datetime(2024, 6, 24, 8, 20, 0)
    lines = [rmc(start + dt.timedelta(seconds=k), 48.1, -11.5, 10.0) for k in range(200)]
    lines[5] = rmc(start + dt.timedelta(seconds=5), 48.1, -11.5, 1e9)
    lines.insert(6, gga((start + dt.timedelta(seconds=5)).time(), 48.2, -11.5))
    path = tmp_path / "gga.nmea"
    path.write_text("\n".join(lines) + "\n")
    fixes = read_nmea(path)
    assert len(fixes.t) == 200 and np.isnan(fixes.speed[5])
    assert np.degrees(fixes.lat[5]) == pytest.approx(48.2)


@tmp_settings
@given(st.floats(-89.9, 89.9), st.floats(-179.9, 179.9), st.integers(0, 86399))
def test_nmea_coordinates_round_trip(tmp_path, lat, lon, second):
    moment = dt.datetime(2023, 3, 1) + dt.timedelta(seconds=second)
    path = Path(tmp_path) / "one.nmea"
    path.write_text(rmc(moment, lat, lon, 3.0) + "\n")
    fixes = read_nmea(path)
    assert np.degrees(fixes.lat[0]) == pytest.approx(lat, abs=1e-8)
    assert np.degrees(fixes.lon[0]) == pytest.approx(lon, abs=1e-8)
    assert fixes.t[0] == pytest.approx(utc_to_gps_seconds(moment))


def test_utc_to_gps_leap_seconds():
    # The leap second at the end of 2016 makes these two UTC moments 3 days + 1 s apart.
    before = utc_to_gps_seconds(dt.datetime(2016, 12, 30))
    after = utc_to_gps_seconds(dt.datetime(2017, 1, 2))
    assert after - before == pytest.approx(3 * 86400 + 1)
    assert utc_to_gps_seconds(dt.datetime(1980, 1, 6)) == 0.0
    assert utc_to_gps_seconds(dt.datetime(2018, 8, 2, tzinfo=dt.UTC)) == pytest.approx(1217203218.0)
