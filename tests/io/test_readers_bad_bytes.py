"""Every text reader under the same bad bytes: a Latin-1 byte, a megabyte-long line, a PNG, a
device and a folder each give the project's InputError naming the file (and line), never a
UnicodeDecodeError, ``_csv.Error`` or an endless read; no such input under 1 MB takes more than
500 MB."""

from __future__ import annotations

import tracemalloc
from collections.abc import Callable
from pathlib import Path

import pytest

from vo_doppler.errors import InputError
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.can import load_dbc, read_can_log
from vo_doppler.io.gps_fixes import read_gps_fixes
from vo_doppler.io.heading_csv import COLUMNS, read_heading_csv
from vo_doppler.io.images import read_times
from vo_doppler.io.sensor_csv import read_speed_csv, read_yaw_rate_csv
from vo_doppler.io.sequence import read_manifest
from vo_doppler.io.trajectory import read_kitti, read_trajectory

DBC = (
    'VERSION ""\nBS_:\nBU_: X\nBO_ 36 KIN: 8 X\n SG_ YAW : 7|16@0- (0.01,0) [-300|300] "deg/s" X\n'
)
HEADING = (
    ",".join(COLUMNS) + "\n" + "1.0,10,1,1,8,6,10,1,0.1,1.0\n" + "2.0,10,1,1,8,6,10,1,0.1,1.0\n"
)


def _gga(second: int) -> str:
    body = f"GPGGA,1200{second:02d}.00,3541.628,N,13942.204,E,1,08,0.9,40.0,M,39.0,M,,"
    checksum = 0
    for char in body:
        checksum ^= ord(char)
    return f"${body}*{checksum:02X}"


# name, file name, good text, reader
READERS: list[tuple[str, str, str, Callable[[Path], object]]] = [
    ("speed csv", "speed.csv", "t,speed_mps\n0,1.0\n1,2.0\n", read_speed_csv),
    ("gyro csv", "gyro.csv", "t,yaw_rate_rad_s\n0,0.1\n1,0.2\n", read_yaw_rate_csv),
    ("gps csv", "gps.csv", "t,lat_deg,lon_deg\n0,35,139\n1,35.0001,139\n", read_gps_fixes),
    ("nmea", "fixes.nmea", f"{_gga(0)}\n{_gga(1)}\n", read_gps_fixes),
    ("tum", "poses.tum", "0 0 0 0 0 0 0 1\n1 1 0 0 0 0 0 1\n", read_trajectory),
    ("kitti", "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n", read_kitti),
    ("heading csv", "heading.csv", HEADING, read_heading_csv),
    (
        "kitti calib",
        "calib.txt",
        "P1: 1 0 0 0 0 1 0 0 0 0 1 0\nP0: 700 0 600 0 0 700 180 0 0 0 1 0\n",
        read_camera,
    ),
    ("yaml calib", "calib.yaml", "fx: 700\nfy: 700\ncx: 600\ncy: 180\n", read_camera),
    ("times", "times.txt", "0.0\n0.1\n", lambda path: read_times(path, 2)),
    ("dbc", "bus.dbc", DBC, load_dbc),
    (
        "candump",
        "bus.log",
        "(1.0) can0 024#0000000000000000\n(1.1) can0 024#0000000000000001\n",
        read_can_log,
    ),
    ("manifest", "sequence.yaml", "format: vo-doppler-sequence/1\nname: x\n", read_manifest),
]
IDS = [r[0] for r in READERS]


@pytest.mark.parametrize(("name", "file", "text", "reader"), READERS, ids=IDS)
def test_the_good_text_reads(tmp_path, name, file, text, reader):
    path = tmp_path / file
    path.write_text(text)
    assert reader(path) is not None


@pytest.mark.parametrize(("name", "file", "text", "reader"), READERS, ids=IDS)
def test_a_latin1_byte_names_the_file_and_line(tmp_path, name, file, text, reader):
    path = tmp_path / file
    first, rest = text.split("\n", 1)
    path.write_bytes((first + "\n").encode() + b"\xe9" + rest.encode())
    with pytest.raises(InputError, match=rf"{file}:2: .*not UTF-8 text \(byte 0xE9\)"):
        reader(path)


@pytest.mark.parametrize(("name", "file", "text", "reader"), READERS, ids=IDS)
def test_a_megabyte_line_is_bounded(tmp_path, name, file, text, reader):
    """Text readers refuse the line; the CAN log skips it as an unreadable line."""
    path = tmp_path / file
    first, rest = text.split("\n", 1)
    path.write_text(first + "\n" + "1," * 500_000 + "\n" + rest)
    tracemalloc.start()
    try:
        if name == "candump":
            assert read_can_log(path).n_unreadable == 1
        else:
            with pytest.raises(InputError, match=rf"{file}:2: .*line has 1000000 bytes"):
                reader(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 500 * 2**20


@pytest.mark.parametrize(("name", "file", "text", "reader"), READERS, ids=IDS)
def test_a_png_is_named_as_such(tmp_path, name, file, text, reader):
    path = tmp_path / file
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(200))
    with pytest.raises(InputError, match=rf"{file}: .*is a PNG image"):
        reader(path)


@pytest.mark.parametrize(("name", "file", "text", "reader"), READERS, ids=IDS)
def test_devices_and_folders_are_refused(tmp_path, name, file, text, reader):
    if Path("/dev/zero").exists():
        with pytest.raises(InputError, match="not a regular file"):
            reader(Path("/dev/zero"))
    folder_message = "cannot read the sequence manifest" if name == "manifest" else "is a folder"
    with pytest.raises(InputError, match=folder_message):
        reader(tmp_path)
