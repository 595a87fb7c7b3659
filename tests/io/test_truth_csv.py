"""Ground-truth files for ``eval gnss``: lat/lon CSVs (with and without header), GSDC
ground_truth.csv and TUM; every bad row names its line, any text is read or refused cleanly."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tests.conftest import require_shared
from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame
from vo_doppler.io.trajectory import write_tum
from vo_doppler.io.truth_csv import read_ground_truth, sequence_origin
from vo_doppler.model.gpstime import SECONDS_PER_WEEK, UNIX_TIME_AT_GPS_EPOCH_S
from vo_doppler.model.trajectory import Trajectory

HK = "hk_tst_canyon_drive/groundTruth_TST_first_half.csv"


def write(tmp_path, text: str, name: str = "truth.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_week_and_seconds_of_week_rows(tmp_path):
    path = write(
        tmp_path,
        "2051,46701,22.30115538,114.17900033,6.5958\n"
        "2051,46702,22.30115530,114.17900034,6.5852\n\n"
        "2051,46703.5,22.30115521,114.17900036,6.5743\n",
    )
    truth = read_ground_truth(path)
    assert truth.t == pytest.approx(2051 * SECONDS_PER_WEEK + np.array([46701, 46702, 46703.5]))
    assert truth.enu[0] == pytest.approx([0.0, 0.0, 0.0])
    assert truth.frame == EnuFrame(np.radians(22.30115538), np.radians(114.17900033), 6.5958)
    assert truth.course_rad is None and "week" in truth.source


def test_headed_rows_with_a_course_and_a_given_origin(tmp_path):
    path = write(
        tmp_path,
        "gps_time_s,lat_deg,lon_deg,height_m,course_deg\n"
        "1000.0,45.0,7.0,100.0,350\n"
        "1001.0,45.0001,7.0,100.0,\n",
    )
    origin = EnuFrame(np.radians(45.0), np.radians(7.0), 90.0)
    truth = read_ground_truth(path, origin=origin)
    assert truth.t == pytest.approx([1000.0, 1001.0])
    assert truth.enu[0] == pytest.approx([0.0, 0.0, 10.0], abs=1e-6)
    assert truth.enu[1, 1] == pytest.approx(11.1, abs=0.1)
    assert np.degrees(truth.course_rad[0]) == pytest.approx(350.0)
    assert np.isnan(truth.course_rad[1])
    assert truth.frame is origin


def test_pos_csv_reads_as_truth(tmp_path):
    path = write(
        tmp_path,
        "gps_time_s,lat_deg,lon_deg,height_m,x_m,valid\n1.0,10,20,30,5,1\n2.0,10,20,31,5,1\n",
    )
    truth = read_ground_truth(path, "latlon")
    assert truth.enu[:, 2] == pytest.approx([0.0, 1.0], abs=1e-6)


def test_gsdc_ground_truth_times_and_bearing(tmp_path):
    path = write(
        tmp_path,
        "MessageType,Provider,LatitudeDegrees,LongitudeDegrees,AltitudeMeters,SpeedMps,"
        "BearingDegrees,UnixTimeMillis\n"
        "Fix,GT,37.0,-122.0,20.0,1.0,288.5,1694113198000\n"
        "Fix,GT,37.0,-122.0,20.0,1.0,,1694113199000\n",
    )
    truth = read_ground_truth(path)
    assert truth.t[0] == pytest.approx(1694113198.0 - UNIX_TIME_AT_GPS_EPOCH_S + 18.0)
    assert np.degrees(truth.course_rad[0]) == pytest.approx(288.5)
    assert np.isnan(truth.course_rad[1])
    assert truth.source == "GSDC ground_truth.csv"


def test_tum_with_and_without_origin(tmp_path):
    t = np.arange(5.0)
    path = tmp_path / "truth.tum"
    write_tum(path, Trajectory(t, np.column_stack([t, 2 * t, 0 * t]), Rotation.identity(5)))
    origin = EnuFrame(0.5, 0.2, 3.0)
    truth = read_ground_truth(path, origin=origin)
    assert truth.frame is origin and truth.enu[4] == pytest.approx([4.0, 8.0, 0.0])
    assert read_ground_truth(path).frame is None


def test_sequence_origin_and_ground_truth(tmp_path):
    (tmp_path / "gt.tum").write_text("0 0 0 0 0 0 0 1\n")
    (tmp_path / "sequence.yaml").write_text(
        "format: vo-doppler-sequence/1\n"
        "origin: {lat_deg: 22.3, lon_deg: 114.2, height_m: 5.0}\n"
        "ground_truth: {trajectory: gt.tum}\n"
    )
    frame, truth = sequence_origin(tmp_path)
    assert frame == EnuFrame(np.radians(22.3), np.radians(114.2), 5.0)
    assert truth == tmp_path / "gt.tum"


@pytest.mark.parametrize(
    ("text", "fmt", "words", "line"),
    [
        ("2051,46701,22.3,114.1,6\n2051,46701,22.3,114.1,6\n", "auto", "not after", 2),
        ("2051,46701,22.3,114.1,6\n2051,46702,22.3,114.1\n", "latlon", "4 fields", 2),
        ("2051.5,46701,22.3,114.1,6\n", "auto", "not a GPS time", 1),
        ("2051,604800,22.3,114.1,6\n", "auto", "not a GPS time", 1),
        ("2051,1,95.0,114.1,6\n", "auto", "latitude 95 is out of range", 1),
        ("2051,1,22.0,114.1,60000\n", "auto", "height", 1),
        ("2051,1,22.0,x,6\n", "latlon", "not a number", 1),
        ("gps_time_s,lat_deg,lon_deg\n1,2,3\n", "auto", "no column height_m", 1),
        ("gps_time_s,lat_deg,lon_deg,height_m\n1,2,3\n", "auto", "3 fields for 4", 2),
        ("gps_time_s,lat_deg,lon_deg,height_m\n", "auto", "no rows", None),
        ("gps_time_s,lat_deg,lon_deg,height_m\n1,2,,4\n", "auto", "longitude is blank", 2),
        ("a,b,c\n", "auto", "cannot tell", None),
        ("# only a comment\n", "auto", "no data rows", None),
        ("LatitudeDegrees,LongitudeDegrees\n1,2\n", "auto", "no column AltitudeMeters", 1),
    ],
)
def test_bad_rows_name_their_line(tmp_path, text, fmt, words, line):
    path = write(tmp_path, text)
    with pytest.raises(InputError, match=words) as caught:
        read_ground_truth(path, fmt)
    assert caught.value.path == path and caught.value.line == line


rows = st.lists(
    st.tuples(
        st.floats(0.001, 5.0),  # step to the next time (s)
        st.floats(-89.0, 89.0),
        st.floats(-179.0, 179.0),
        st.floats(-100.0, 3000.0),
    ),
    min_size=1,
    max_size=30,
)


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(rows=rows, week=st.integers(0, 3000), start=st.floats(0.0, 600000.0))
def test_written_rows_read_back(tmp_path, rows, week, start):
    """Rows written with the precision of the published files read back to the same times and
    the same geodetic positions; seconds of week roll over into the next week."""
    tow = start + np.cumsum([0.0] + [r[0] for r in rows[1:]])
    tow = np.round(tow, 3)
    if np.any(np.diff(tow) <= 0):
        return  # rounding joined two times: not a valid file
    weeks = week + np.floor(tow / SECONDS_PER_WEEK)
    tow_of_week = tow - (weeks - week) * SECONDS_PER_WEEK
    lines = [
        f"{w:.0f},{s:.3f},{r[1]:.9f},{r[2]:.9f},{r[3]:.4f}"
        for w, s, r in zip(weeks, tow_of_week, rows, strict=True)
    ]
    path = write(tmp_path, "\n".join(lines) + "\n")
    truth = read_ground_truth(path)
    assert truth.t == pytest.approx(week * SECONDS_PER_WEEK + tow, abs=1e-6)
    lat = np.radians([float(line.split(",")[2]) for line in lines])
    lon = np.radians([float(line.split(",")[3]) for line in lines])
    height = np.array([float(line.split(",")[4]) for line in lines])
    assert truth.enu == pytest.approx(truth.frame.geodetic_to_enu(lat, lon, height), abs=1e-6)
    assert truth.enu[0] == pytest.approx([0.0, 0.0, 0.0], abs=1e-6)


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(text=st.text(alphabet="0123456789,.-e \n#abgps_time_lat_deg", max_size=200))
def test_any_text_reads_or_is_refused_cleanly(tmp_path, text):
    path = write(tmp_path, text)
    try:
        truth = read_ground_truth(path)
    except InputError as exc:
        assert exc.path == path
        return
    assert np.all(np.diff(truth.t) > 0) and np.isfinite(truth.enu).all()


def test_the_hong_kong_truth_reads():
    truth = read_ground_truth(require_shared(HK))
    week, first, last = 2051, 46701.0, 46942.0
    assert len(truth) == 242
    assert truth.t[[0, -1]] == pytest.approx(week * SECONDS_PER_WEEK + np.array([first, last]))
    steps = np.linalg.norm(np.diff(truth.enu[:, :2], axis=0), axis=1)
    assert steps.max() < 25.0  # a car in a city at 1 Hz
    assert np.degrees(truth.frame.lat_rad) == pytest.approx(22.30115538)


def test_the_gsdc_ground_truth_reads():
    truth = read_ground_truth(require_shared("android_pixel7pro/ground_truth.csv"))
    assert len(truth) == 5 and truth.source == "GSDC ground_truth.csv"
    assert truth.t[0] == pytest.approx(1694113198.0 - UNIX_TIME_AT_GPS_EPOCH_S + 18.0)
    assert np.degrees(truth.course_rad) == pytest.approx(288.28, abs=0.01)
