"""KITTI raw OXTS reader on a synthetic folder: a circle driven at constant speed."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from vo_doppler.errors import InputError
from vo_doppler.io.kitti_oxts import EARTH_RADIUS_M, OXTS_FIELDS, read_oxts

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


def test_file_count_must_match_timestamps(tmp_path):
    folder = _write_circle(tmp_path / "oxts")
    (folder / "data" / "0000000059.txt").unlink()
    with pytest.raises(InputError, match="59 OXTS data files for 60 timestamps"):
        read_oxts(folder)


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
