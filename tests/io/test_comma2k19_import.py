"""Which precise orbits a comma2k19 segment takes from a folder of SP3 files, the picklable
import step of a batch over raw segments, and segments without a DBC."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from tests.conftest import require_shared
from tests.helpers.precise_text import sp3_text
from vo_doppler.errors import InputError, OutputError
from vo_doppler.io.comma2k19 import read_gyro_yaw_rate, read_wheel_speed
from vo_doppler.io.comma2k19_import import (
    Comma2k19Import,
    import_comma2k19,
    orbits_for_segment,
    segment_gps_span,
)
from vo_doppler.io.sequence import read_sequence

COMMA = "comma2k19_example1"
SP3 = "Sta20124_1400_1845.sp3"


def write_orbit_day(path, start_gps_s: float, hours: float) -> None:
    t = start_gps_s + 900.0 * np.arange(int(hours * 4) + 1)
    position = np.full((t.size, 1, 3), 2.6e7)
    path.write_text(sp3_text(t, ["G01"], position, np.zeros((t.size, 1))))


@pytest.mark.shared_data
def test_the_folder_file_around_the_segment_is_chosen(tmp_path):
    segment = require_shared(COMMA)
    start, end = segment_gps_span(segment)
    assert end - start == pytest.approx(59.95, abs=0.01)  # 1200 frames at 20 Hz
    (tmp_path / SP3).symlink_to(segment / SP3)
    write_orbit_day(tmp_path / "earlier.SP3", start - 30 * 3600.0, 24.0)
    write_orbit_day(tmp_path / "just_covering.sp3", start - 900.0, 0.5)
    (tmp_path / "notes.txt").write_text("not an orbit file")
    assert orbits_for_segment(segment, tmp_path) == tmp_path / SP3
    assert orbits_for_segment(segment, segment / SP3) == segment / SP3


@pytest.mark.shared_data
def test_a_folder_without_a_covering_file_is_an_error_naming_the_time(tmp_path):
    segment = require_shared(COMMA)
    start, _ = segment_gps_span(segment)
    write_orbit_day(tmp_path / "other_day.sp3", start - 30 * 3600.0, 24.0)
    with pytest.raises(InputError, match=r"no SP3 file covers the segment .*GPS week 2012"):
        orbits_for_segment(segment, tmp_path)
    (tmp_path / "other_day.sp3").unlink()
    with pytest.raises(InputError, match=r"no SP3 files \(\*\.sp3\)"):
        orbits_for_segment(segment, tmp_path)


def test_the_import_step_pickles_and_names_its_orbits(tmp_path):
    step = Comma2k19Import(tmp_path / "orbits")
    assert pickle.loads(pickle.dumps(step)) == step
    assert "orbits" in repr(step)


def segment_without_dbc(tmp_path):
    """The example segment's folders linked into ``tmp_path``, without its DBC and CAN log: a
    comma2k19 segment as the dataset ships it."""
    source = require_shared(COMMA)
    segment = tmp_path / "segment"
    segment.mkdir()
    for entry in ("global_pose", "processed_log"):
        (segment / entry).symlink_to(source / entry)
    return segment


@pytest.mark.slow
@pytest.mark.shared_data
def test_a_segment_without_a_dbc_takes_the_decoded_wheel_speeds_and_the_gyro(tmp_path):
    segment = segment_without_dbc(tmp_path)
    sp3 = require_shared(f"{COMMA}/{SP3}")
    with_can = import_comma2k19(require_shared(COMMA), tmp_path / "can", sp3)
    without = import_comma2k19(segment, tmp_path / "vehicle", sp3)
    assert (with_can.vehicle_signals, without.vehicle_signals) == ("can", "vehicle")
    can, csv = read_sequence(with_can.folder), read_sequence(without.folder)
    # the same four wheels: comma's decoded m/s against the DBC's km/h from the raw frames
    at = csv.wheel_speed.t[10:-10]
    difference = np.interp(at, can.wheel_speed.t, can.wheel_speed.value) - np.interp(
        at, csv.wheel_speed.t, csv.wheel_speed.value
    )
    assert np.median(np.abs(difference)) < 0.01
    t_gyro, yaw_rate = read_gyro_yaw_rate(segment)
    np.testing.assert_array_equal(csv.yaw_rate.value, yaw_rate)
    np.testing.assert_allclose(csv.yaw_rate.t, t_gyro + without.gps_minus_log_s, atol=1e-6)
    assert csv.observations.epoch_time.size == can.observations.epoch_time.size
    with pytest.raises(InputError, match="DBC for the CAN log is not a file"):
        import_comma2k19(segment, tmp_path / "x", sp3, dbc=tmp_path / "missing.dbc")


def test_a_signal_of_the_wrong_shape_is_named(tmp_path):
    folder = tmp_path / "processed_log" / "CAN" / "wheel_speed"
    folder.mkdir(parents=True)
    with (folder / "t").open("wb") as stream:
        np.save(stream, np.arange(5.0))
    with (folder / "value").open("wb") as stream:
        np.save(stream, np.ones((5, 3)))
    with pytest.raises(
        InputError, match=r"wheel_speed/value: array of shape \(5, 3\), expected \(N, 4\)"
    ):
        read_wheel_speed(tmp_path)


def test_the_import_never_writes_into_its_segment_or_a_foreign_folder(tmp_path):
    """Checked before anything is read: the segment itself, a folder holding it, and a
    non-empty folder that no import wrote are refused, untouched."""
    segment = tmp_path / "route" / "segment"
    segment.mkdir(parents=True)
    (segment / "raw.bin").write_text("data")
    orbits = tmp_path / "orbits.sp3"
    for output in (segment, segment.parent):
        with pytest.raises(OutputError, match="the input"):
            import_comma2k19(segment, output, orbits)
    other = tmp_path / "other"
    other.mkdir()
    (other / "sequence.yaml").write_text("format: vo-doppler-sequence/1\n")
    with pytest.raises(OutputError, match="not written by 'vo-doppler import'"):
        import_comma2k19(segment, other, orbits)
    assert sorted(p.name for p in tmp_path.rglob("*")) == [
        "other",
        "raw.bin",
        "route",
        "segment",
        "sequence.yaml",
    ]


@pytest.mark.shared_data
@pytest.mark.parametrize(
    ("orbits", "message"),
    [
        ("garbage", r"garbage\.sp3:1: (not an SP3-c/d file|NUL bytes)"),
        ("truncated", r"truncated\.sp3: the orbits do not cover the segment .*404106"),
        ("other_day", r"other_day\.sp3: the orbits do not cover the segment .*GPS week 2012"),
    ],
)
def test_orbits_run_would_refuse_stop_the_import_before_it_writes(tmp_path, orbits, message):
    segment = require_shared(COMMA)
    path = tmp_path / f"{orbits}.sp3"
    if orbits == "garbage":
        path.write_bytes(bytes(range(256)) * 4)
    elif orbits == "truncated":  # the first 6 of the day's 20 epochs
        lines = (segment / SP3).read_text().splitlines(keepends=True)
        cut = [k for k, line in enumerate(lines) if line.startswith("*  ")][6]
        path.write_text("".join(lines[:cut]))
    else:
        write_orbit_day(path, segment_gps_span(segment)[0] - 30 * 3600.0, 24.0)
    with pytest.raises(InputError, match=message):
        import_comma2k19(segment, tmp_path / "out", path)
    assert not (tmp_path / "out").exists()


@pytest.mark.shared_data
def test_a_dbc_run_would_refuse_stops_the_import_before_it_writes(tmp_path):
    segment = require_shared(COMMA)
    sp3 = segment / SP3
    not_a_dbc = tmp_path / "base.nav"
    not_a_dbc.write_text(
        "     3.04           N: GNSS NAV DATA    M: MIXED            RINEX VERSION\n"
    )
    with pytest.raises(InputError, match=r"base\.nav: cannot load the CAN database"):
        import_comma2k19(segment, tmp_path / "out", sp3, dbc=not_a_dbc)
    other = tmp_path / "other.dbc"
    other.write_text(
        'VERSION ""\nBS_:\nBU_: XXX\nBO_ 36 KIN: 8 XXX\n SG_ YAW : 7|16@0- (0.01,0) '
        '[-300|300] "deg/s" XXX\n'
    )
    with pytest.raises(InputError, match=r"other\.dbc: message 'KINEMATICS' is not in the DBC"):
        import_comma2k19(segment, tmp_path / "out", sp3, dbc=other)
    assert not (tmp_path / "out").exists()
