"""KITTI raw OXTS reader on a synthetic folder: a circle driven at constant speed."""

from __future__ import annotations

from datetime import datetime

import numpy as np
import pymap3d
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import shared_data_dir
from vo_doppler.errors import InputError
from vo_doppler.io.kitti_oxts import (
    BOUNDS,
    EARTH_RADIUS_M,
    OXTS_FIELDS,
    read_oxts,
    read_timestamps,
)

LAT0 = 49.011
LON0 = 8.423
RADIUS = 40.0
SPEED = 8.0
RATE = SPEED / RADIUS  # rad/s, counter-clockwise
DT = 0.1
N = 60
YAW0 = 0.3


def _write_circle(folder):
    """Frames on a CCW circle in the devkit's Mercator plane (scale from LAT0)."""
    data = folder / "data"
    data.mkdir(parents=True)
    scale = np.cos(np.radians(LAT0))
    x0 = scale * EARTH_RADIUS_M * np.radians(LON0)
    y0 = scale * EARTH_RADIUS_M * np.log(np.tan(np.pi / 4 + np.radians(LAT0) / 2))
    stamps = []
    for i in range(N):
        t = i * DT
        yaw = YAW0 + RATE * t
        # centre of the circle to the left of the initial heading
        cx, cy = x0 - RADIUS * np.sin(YAW0), y0 + RADIUS * np.cos(YAW0)
        x, y = cx + RADIUS * np.sin(yaw), cy - RADIUS * np.cos(yaw)
        lon = np.degrees(x / (scale * EARTH_RADIUS_M))
        lat = np.degrees(2 * np.arctan(np.exp(y / (scale * EARTH_RADIUS_M))) - np.pi / 2)
        values = dict.fromkeys(OXTS_FIELDS, 0.0)
        values.update(lat=lat, lon=lon, alt=115.0, yaw=np.arctan2(np.sin(yaw), np.cos(yaw)))
        values.update(vf=SPEED, wz=RATE, numsats=9, navstat=4)
        line = " ".join(f"{values[name]:.15g}" for name in OXTS_FIELDS)
        (data / f"{i:010d}.txt").write_text(line + "\n")
        nanos = 123_456_789 + i * 100_000_000
        stamps.append(f"2011-09-26 13:02:{25 + nanos // 10**9:02d}.{nanos % 10**9:09d}")
    (folder / "timestamps.txt").write_text("\n".join(stamps) + "\n")
    return folder


def test_circle_gives_exact_relative_poses_yaw_rate_and_speed(tmp_path):
    record = read_oxts(_write_circle(tmp_path / "oxts"))
    elapsed = np.arange(N) * DT
    np.testing.assert_allclose(record.t - record.t[0], elapsed, atol=1e-6)
    # (2011-09-26 13:02:25 − 1980-01-06) + 15 leap seconds, from Python datetime
    assert record.t[0] == pytest.approx(1001077360.123456789, abs=1e-6)
    angle = RATE * elapsed
    expected = np.stack([RADIUS * np.sin(angle), RADIUS * (1 - np.cos(angle))], axis=1)
    np.testing.assert_allclose(record.poses[:, :2, 3], expected, atol=1e-6)
    np.testing.assert_allclose(record.poses[:, 2, 3], 0.0, atol=1e-9)
    yaw = np.arctan2(record.poses[:, 1, 0], record.poses[:, 0, 0])
    np.testing.assert_allclose(yaw, np.arctan2(np.sin(angle), np.cos(angle)), atol=1e-12)
    np.testing.assert_allclose(record.poses[0], np.eye(4), atol=1e-9)
    np.testing.assert_allclose(record.yaw_rate.value, RATE, rtol=1e-14)
    np.testing.assert_allclose(record.speed.value, SPEED, rtol=1e-14)
    trajectory = record.trajectory()
    assert trajectory.path_length == pytest.approx(SPEED * elapsed[-1], rel=1e-3)


def test_bad_packets_name_the_file_and_line(tmp_path):
    folder = _write_circle(tmp_path / "oxts")
    packet = folder / "data" / "0000000007.txt"
    packet.write_text(packet.read_text().replace("115", "nan", 1))
    with pytest.raises(InputError, match=r"0000000007.txt:1: non-finite"):
        read_oxts(folder)
    packet.write_text("1 2 3\n")
    with pytest.raises(InputError, match=r"0000000007.txt:1: 3 numbers, expected 30"):
        read_oxts(folder)


def test_bad_timestamps_name_the_line(tmp_path):
    folder = _write_circle(tmp_path / "oxts")
    lines = (folder / "timestamps.txt").read_text().splitlines()
    lines[4], lines[5] = lines[5], lines[4]
    (folder / "timestamps.txt").write_text("\n".join(lines))
    with pytest.raises(InputError, match=r"timestamps.txt:6: timestamps do not increase"):
        read_oxts(folder)
    lines[2] = "2011-13-26 13:02:25.1"
    (folder / "timestamps.txt").write_text("\n".join(lines))
    with pytest.raises(InputError, match=r"timestamps.txt:3: date or time out of range"):
        read_oxts(folder)


def test_subsampled_folder_reads_the_frames_that_exist_with_their_own_lines(tmp_path, caplog):
    folder = _write_circle(tmp_path / "oxts")
    full = read_oxts(folder)
    kept = np.array([3, 4, 10, 42, 59])
    for path in (folder / "data").iterdir():
        if int(path.stem) not in kept:
            path.unlink()
    with caplog.at_level("WARNING"):
        record = read_oxts(folder)
    np.testing.assert_array_equal(record.frames, kept)
    np.testing.assert_array_equal(record.t, full.t[kept])
    np.testing.assert_array_equal(record.yaw_rate.t, full.t[kept])
    np.testing.assert_allclose(record.fields["lat"], full.fields["lat"][kept], rtol=0, atol=0)
    # relative to the first frame that exists (frame 3), as the devkit does; the Mercator
    # scale comes from frame 3's latitude too, which moves these 40 m by 5 µm
    expected = np.linalg.inv(full.poses[3]) @ full.poses[kept]
    np.testing.assert_allclose(record.poses, expected, atol=1e-5)
    assert record.warnings == (
        f"{folder / 'data'}: 5 data files for the 60 timestamps of {folder / 'timestamps.txt'} "
        "(a subsampled drive): the 5 frames that exist are used, each with the timestamp line "
        "of its number",
    )
    assert record.warnings[0] in caplog.text
    assert full.warnings == ()


def test_frame_files_that_cannot_be_timed_name_the_file(tmp_path):
    folder = _write_circle(tmp_path / "oxts")
    data = folder / "data"
    (data / "0000000060.txt").write_text((data / "0000000001.txt").read_text())
    with pytest.raises(
        InputError, match=r"0000000060.txt: frame 60 has no timestamp: .*timestamps.txt has 60"
    ):
        read_oxts(folder)
    (data / "0000000060.txt").unlink()
    (data / "notes.txt").write_text("x")
    with pytest.raises(InputError, match=r"notes.txt: not a KITTI frame file name"):
        read_oxts(folder)
    (data / "notes.txt").unlink()
    (data / "00000000001.txt").write_text("x")  # 11 digits
    with pytest.raises(InputError, match=r"00000000001.txt: not a KITTI frame file name"):
        read_oxts(folder)
    (data / "00000000001.txt").unlink()
    (data / "1.txt").write_text((data / "0000000001.txt").read_text())
    with pytest.raises(InputError, match=r"data: frame 1 is given twice"):
        read_oxts(folder)
    for path in data.iterdir():
        path.unlink()
    with pytest.raises(InputError, match=r"data: no KITTI frame files \(.txt\)"):
        read_oxts(folder)


def test_blank_lines_only_at_the_end_of_the_timestamps(tmp_path):
    folder = _write_circle(tmp_path / "oxts")
    stamps = folder / "timestamps.txt"
    stamps.write_text(stamps.read_text() + "\n  \n")
    assert read_oxts(folder).t.size == N
    lines = stamps.read_text().splitlines()
    lines.insert(5, "")
    stamps.write_text("\n".join(lines))
    with pytest.raises(InputError, match=r"timestamps.txt:6: not a timestamp: ''"):
        read_oxts(folder)
    stamps.write_text("\n")
    with pytest.raises(InputError, match=r"timestamps.txt: no timestamps"):
        read_oxts(folder)


def _write_fixes(folder, enu, yaw, roll=0.0, pitch=0.0):
    """OXTS packets at the ENU positions ``enu`` (N, 3) of the WGS 84 frame at (LAT0, LON0,
    115 m), through pymap3d's own ENU → geodetic (not the code under test)."""
    data = folder / "data"
    data.mkdir(parents=True)
    stamps = []
    for i, (e, n, u) in enumerate(enu):
        lat, lon, alt = pymap3d.enu2geodetic(e, n, u, LAT0, LON0, 115.0)
        values = dict.fromkeys(OXTS_FIELDS, 0.0)
        values.update(lat=lat, lon=lon, alt=alt, yaw=yaw[i], roll=roll, pitch=pitch)
        line = " ".join(repr(float(values[name])) for name in OXTS_FIELDS)
        (data / f"{i:010d}.txt").write_text(line + "\n")
        stamps.append(f"2011-09-26 13:02:{25 + i:02d}.5")
    (folder / "timestamps.txt").write_text("\n".join(stamps) + "\n")
    return folder


def test_enu_trajectory_is_exact_in_the_first_fixs_frame(tmp_path):
    # 1 km east, 1 km north, 20 m up: far enough for the Mercator scale and the turn of the
    # local level frame (meridian convergence Δλ·sin φ) to show
    enu = np.array([[0.0, 0.0, 0.0], [1000.0, 0.0, 0.0], [1000.0, 1000.0, 20.0]])
    yaw = np.array([0.2, 0.2, -1.0])
    record = read_oxts(_write_fixes(tmp_path / "oxts", enu, yaw))
    origin = record.origin()
    assert np.degrees(origin.lat_rad) == pytest.approx(LAT0, abs=1e-12)
    assert origin.height_m == pytest.approx(115.0, abs=1e-6)
    truth = record.enu_trajectory()
    np.testing.assert_allclose(truth.positions, enu, atol=1e-6)
    np.testing.assert_allclose(truth.t - truth.t[0], [0.0, 1.0, 2.0], atol=1e-6)
    lon = np.radians(record.fields["lon"])
    convergence = (lon - lon[0]) * np.sin(np.radians(LAT0))
    heading = np.arctan2(
        truth.orientations.as_matrix()[:, 1, 0], truth.orientations.as_matrix()[:, 0, 0]
    )
    np.testing.assert_allclose(heading, yaw + convergence, atol=1e-7)
    assert abs(convergence[1]) > 1e-4  # the turn is really there, and applied
    # the devkit's Mercator poses are 0.19 % short east at this latitude: not the ENU output
    mercator_east = record.poses[1, :2, 3] @ [np.cos(0.2), -np.sin(0.2)]
    assert mercator_east == pytest.approx(1000.0 * (1 - 0.00191), abs=0.05)


def test_enu_orientation_follows_the_oxts_roll_and_pitch_signs(tmp_path):
    enu = np.zeros((2, 3))
    enu[1, 0] = 1.0
    record = read_oxts(_write_fixes(tmp_path / "oxts", enu, [0.0, 0.0], roll=0.1, pitch=0.05))
    matrix = record.enu_trajectory().orientations.as_matrix()[0]
    forward, left = matrix[:, 0], matrix[:, 1]
    assert forward[2] == pytest.approx(-np.sin(0.05), abs=1e-12)  # pitch > 0: front down
    assert left[2] == pytest.approx(np.sin(0.1) * np.cos(0.05), abs=1e-12)  # roll > 0: left up


@settings(max_examples=200, deadline=None)
@given(
    when=st.datetimes(min_value=datetime(2009, 1, 1), max_value=datetime(2012, 6, 30, 23, 59)),
    nanos=st.integers(0, 999_999_999),
    digits=st.integers(1, 9),
)
def test_timestamp_lines_are_utc_with_the_leap_seconds_of_their_date(
    tmp_path_factory, when, nanos, digits
):
    """GPS − UTC was 15 s from 2009-01-01 to 2012-06-30 (IERS Bulletin C); the fraction is
    the digits written, whatever their number."""
    fraction = f"{nanos:09d}"[:digits]
    line = when.strftime("%Y-%m-%d %H:%M:%S") + "." + fraction
    path = tmp_path_factory.mktemp("stamps") / "timestamps.txt"
    path.write_text(line + "\n")
    (t,) = read_timestamps(path)
    whole = (when.replace(microsecond=0) - datetime(1980, 1, 6)).total_seconds() + 15
    assert t == pytest.approx(whole + int(fraction) / 10**digits, abs=2e-7)


@settings(max_examples=100, deadline=None)
@given(
    values=st.lists(
        st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False), min_size=30, max_size=30
    ),
    lat=st.floats(-90, 90),
    lon=st.floats(-180, 180),
    angles=st.lists(st.floats(-3.14159, 3.14159), min_size=3, max_size=3),
)
def test_packet_lines_read_back_every_number_exactly(tmp_path_factory, values, lat, lon, angles):
    """Any numbers within the fields' bounds (a drawn ±1e6 mapped into ``BOUNDS``) read back."""
    values[0], values[1], values[3:6] = lat, lon, angles
    for name, bounds in BOUNDS.items():
        k = OXTS_FIELDS.index(name)
        values[k] = bounds.low + (values[k] + 1e6) / 2e6 * (bounds.high - bounds.low)
    folder = tmp_path_factory.mktemp("oxts") / "oxts"
    (folder / "data").mkdir(parents=True)
    (folder / "data" / "0000000000.txt").write_text(" ".join(repr(v) for v in values) + "\n")
    (folder / "timestamps.txt").write_text("2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26\n")
    record = read_oxts(folder)
    assert [float(record.fields[name][0]) for name in OXTS_FIELDS] == values
    assert record.speed.value[0] == values[OXTS_FIELDS.index("vf")]
    assert record.yaw_rate.value[0] == values[OXTS_FIELDS.index("wz")]


@settings(
    max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    line=st.text(alphabet="0123456789.-e :xn", max_size=60),
    stamp=st.text(alphabet="0123456789.-: ", max_size=32),
)
def test_damaged_packet_or_timestamp_fails_only_with_input_errors(tmp_path_factory, line, stamp):
    folder = _write_circle(tmp_path_factory.mktemp("oxts") / "oxts")
    (folder / "data" / "0000000003.txt").write_text(line)
    stamps = (folder / "timestamps.txt").read_text().splitlines()
    stamps[3] = stamp
    (folder / "timestamps.txt").write_text("\n".join(stamps))
    try:
        record = read_oxts(folder)
    except InputError as exc:
        assert "timestamps.txt:" in str(exc) or "0000000003.txt" in str(exc)
        return
    assert np.all(np.isfinite(record.poses)) and np.all(np.diff(record.t) > 0)


OXTS_BAD = {"vf": 1.0e9, "wz": 50.0, "alt": 1.0e6, "vn": -200.0, "af": 100.0, "wx": -6.0}


@pytest.mark.parametrize("name", sorted(OXTS_BAD))
def test_a_value_no_vehicle_reports_names_the_packet_and_field(tmp_path, name):
    values = [49.0, 8.4, 110.0, 0.0, 0.0, 0.1] + [1.0] * 19 + [4, 11, 6, 6, 6]
    values[OXTS_FIELDS.index(name)] = OXTS_BAD[name]
    folder = tmp_path / "oxts"
    (folder / "data").mkdir(parents=True)
    packet = folder / "data" / "0000000000.txt"
    packet.write_text(" ".join(repr(v) for v in values) + "\n")
    (folder / "timestamps.txt").write_text("2011-09-26 13:02:25.964389445\n")
    with pytest.raises(InputError, match=rf"0000000000\.txt:1: {name} = .* is outside"):
        read_oxts(folder)


def test_the_shared_oxts_of_1e9_mps_is_refused():
    folder = shared_data_dir() / "bad_inputs_found" / "oxts_1e9"
    if not folder.is_dir():
        pytest.skip(f"{folder} absent")
    with pytest.raises(InputError, match=r"oxts_1e9/data/0000000000\.txt:1: .* is outside"):
        read_oxts(folder)
