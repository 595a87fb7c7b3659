"""A comma2k19 segment with one bad array (wrong length, shape or type, NaN, empty, unsorted,
a header claiming terabytes, a physically impossible value) is an InputError naming that array
file (``vo-doppler import`` exits 1), and what the import writes holds only possible values.

The synthetic segment (tests/helpers/comma2k19_segment.py) imports cleanly; each case replaces
one of its arrays."""

from __future__ import annotations

import io

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from numpy.lib import format as npformat

from tests.conftest import shared_data_dir
from tests.helpers.comma2k19_segment import (
    npy_bytes,
    segment_arrays,
    write_orbits,
    write_segment,
)
from vo_doppler.bounds import CARRIER_PHASE, DOPPLER
from vo_doppler.cli import main
from vo_doppler.errors import EXIT_FAILURE, InputError
from vo_doppler.io.comma2k19 import array_header, read_raw_gnss
from vo_doppler.io.comma2k19_import import import_comma2k19
from vo_doppler.io.rinex_obs import read_obs

GOOD = segment_arrays()
POSITIONS = "global_pose/frame_positions"
RAW_VALUE = "processed_log/GNSS/raw_gnss_ublox/value"
RAW_T = "processed_log/GNSS/raw_gnss_ublox/t"
GYRO_T, GYRO_VALUE = "processed_log/IMU/gyro/t", "processed_log/IMU/gyro/value"


def claimed_header(shape: tuple[int, ...], payload: bytes = b"\0" * 16) -> bytes:
    """An ``.npy`` header declaring ``shape`` of float64, followed by only ``payload``."""
    out = io.BytesIO()
    npformat.write_array_header_1_0(out, {"descr": "<f8", "fortran_order": False, "shape": shape})
    return out.getvalue() + payload


def changed(relative: str, change) -> bytes:
    array = GOOD[relative].copy()
    return npy_bytes(change(array))


def _nan_row(row: int):
    def change(array):
        array[row] = np.nan
        return array

    return change


def _column(column: int, value: float, rows=slice(None)):
    def change(array):
        array[rows, column] = value
        return array

    return change


CASES = {
    # wrong length, shape, type; empty; NaN; unsorted; not an array file; a huge header
    "frame times one short": ("global_pose/frame_times", lambda a: a[:-1], POSITIONS),
    "positions of 2 columns": (POSITIONS, lambda a: a[:, :2], POSITIONS),
    "velocities complex": ("global_pose/frame_velocities", lambda a: a.astype(complex), None),
    "orientations with NaN": ("global_pose/frame_orientations", _nan_row(7), None),
    "orientations not unit": ("global_pose/frame_orientations", lambda a: 3.0 * a, None),
    "gyro times empty": (GYRO_T, lambda a: a[:0], None),
    "gyro values as text": (GYRO_VALUE, lambda a: a.astype(str), None),
    "gyro values 3-D": (GYRO_VALUE, lambda a: a[:, :, None], None),
    "gyro times with NaN": (GYRO_T, _nan_row(3), None),
    "gyro times unsorted": (GYRO_T, lambda a: a[::-1].copy(), None),
    "gyro values one short": (GYRO_VALUE, lambda a: a[:-1], None),
    "accelerometer empty": ("processed_log/IMU/accelerometer/value", lambda a: a[:0], None),
    "wheel speeds of 2 columns": ("processed_log/CAN/wheel_speed/value", lambda a: a[:, :2], None),
    "raw GNSS times with NaN": (RAW_T, _nan_row(0), None),
    "raw GNSS times one short": (RAW_T, lambda a: a[:-1], RAW_VALUE),
    "raw GNSS of 4 columns": (RAW_VALUE, lambda a: a[:, :4], None),
    "raw GNSS as bool": (RAW_VALUE, lambda a: a > 0, None),
    # impossible values
    "origin 6,000 km down": (POSITIONS, lambda a: 0.05 * a, None),
    "poses faster than sound": ("global_pose/frame_velocities", lambda a: 40.0 * a, None),
    "a pose 100 km away": (POSITIONS, _column(0, 1.0e5, 50), POSITIONS),
    "frame GPS week NaN": ("global_pose/frame_gps_times", _column(0, np.nan, 4), None),
    "frame GPS time after 2100": ("global_pose/frame_gps_times", _column(0, 7000.0), None),
    "truth times after 2100": ("global_pose/frame_times", lambda a: a + 3.0e9, None),
    "raw GNSS week after 2100": (RAW_VALUE, _column(1, 7000.0), None),
    "raw GNSS time of week NaN": (RAW_VALUE, _column(2, np.nan, 6), None),
    "log clock 1e300": (RAW_T, lambda a: a + 1.0e300, None),
    "yaw rate 1e9 rad/s": (GYRO_VALUE, _column(2, 1.0e9), None),
    "wheel speed 1e9 m/s": ("processed_log/CAN/wheel_speed/value", lambda a: a * 1e8, None),
    "acceleration 1e9 m/s²": (
        "processed_log/IMU/accelerometer/value",
        _column(0, 1.0e9),
        None,
    ),
    "every Doppler beyond a satellite's": (RAW_VALUE, _column(6, 1.0e5), None),
}
RAW_BYTES = {
    "header claiming 7 TiB": (RAW_VALUE, claimed_header((10**12,))),
    "header claiming 7 TiB of poses": (POSITIONS, claimed_header((2 * 10**11, 3))),
    "not a numpy file": (GYRO_T, b"t,value\n1,2\n"),
    "a pickled object array": (GYRO_T, b"\x93NUMPY\x01\x00v\x00{'descr': '|O', "),
    "an empty file": (RAW_VALUE, b""),
}


def _import(tmp_path, replaced: dict[str, bytes]):
    segment = write_segment(tmp_path / "segment", replaced)
    orbits = write_orbits(tmp_path / "orbits.sp3")
    return segment, orbits


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_bad_array_is_an_input_error_naming_its_file(tmp_path, name):
    relative, change, named = CASES[name]
    segment, orbits = _import(tmp_path, {relative: changed(relative, change)})
    with pytest.raises(InputError) as caught:
        import_comma2k19(segment, tmp_path / "out", orbits)
    assert str(segment / (named or relative)) in str(caught.value)


@pytest.mark.parametrize("name", sorted(RAW_BYTES))
def test_an_unreadable_array_file_is_named_before_it_is_loaded(tmp_path, name):
    relative, data = RAW_BYTES[name]
    segment, orbits = _import(tmp_path, {relative: data})
    with pytest.raises(InputError) as caught:
        import_comma2k19(segment, tmp_path / "out", orbits)
    assert str(segment / relative) in str(caught.value)


def test_a_terabyte_header_is_refused_from_the_header_alone(tmp_path):
    path = tmp_path / "value"
    path.write_bytes(claimed_header((10**12,)))
    with pytest.raises(InputError, match=r"declares 8,000,000,000,000 bytes .* holds 16"):
        array_header(path)


def test_the_command_exits_1_naming_the_array(tmp_path, capsys):
    relative, change, _ = CASES["raw GNSS of 4 columns"]
    segment, orbits = _import(tmp_path, {relative: changed(relative, change)})
    out = str(tmp_path / "out")
    code = main(["import", "comma2k19", str(segment), "--orbits", str(orbits), "-o", out])
    assert code == EXIT_FAILURE
    assert str(segment / relative) in capsys.readouterr().err


def test_impossible_measurements_are_dropped_and_never_written(tmp_path):
    """One row each: Doppler beyond any satellite's range rate, a carrier phase of 1e300, a
    C/N0 of −1, σ 0, GPS satellite 254: dropped and counted; the RINEX written holds only
    values within the bounds."""
    value = GOOD[RAW_VALUE].copy()
    value[0, 6] = 1.0e5
    value[1, 9] = 1.0e300
    value[2, 8] = -1.0
    value[3, 7] = 0.0
    value[4, 0] = 254.0
    segment, orbits = _import(tmp_path, {RAW_VALUE: npy_bytes(value)})
    assert read_raw_gnss(segment).n_dropped == 5
    import_comma2k19(segment, tmp_path / "out", orbits)
    obs = read_obs(tmp_path / "out" / "gnss" / "raw_gnss_ublox.obs")
    doppler = obs.value[np.char.startswith(np.array(obs.codes)[obs.code], "D")]
    phase = obs.value[np.char.startswith(np.array(obs.codes)[obs.code], "L")]
    assert not DOPPLER.outside(doppler).any()
    assert not CARRIER_PHASE.outside(phase).any()
    assert obs.value.size == 4 * (GOOD[RAW_VALUE].shape[0] - 5)


@settings(
    max_examples=30, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    relative=st.sampled_from(sorted(GOOD)),
    row=st.integers(0, 10**6),
    value=st.sampled_from([np.nan, np.inf, -np.inf, 1e300, -1e300, 0.0, -1.0, 1e20]),
)
def test_any_one_bad_number_is_an_input_error_or_an_import_of_possible_values(
    tmp_path_factory, relative, row, value
):
    """Property: one number of any array replaced by an odd value never crashes the import."""
    folder = tmp_path_factory.mktemp("case")
    array = GOOD[relative].copy()
    array.flat[row % array.size] = value
    segment, orbits = _import(folder, {relative: npy_bytes(array)})
    try:
        import_comma2k19(segment, folder / "out", orbits)
    except InputError as exc:
        assert str(segment) in str(exc)
        return
    obs = read_obs(folder / "out" / "gnss" / "raw_gnss_ublox.obs")
    assert np.isfinite(obs.value).all()


RAW_CAN = "processed_log/CAN/raw_can"


def _raw_can(n: int = 20) -> dict[str, np.ndarray]:
    return {
        f"{RAW_CAN}/t": 100.0 + 0.01 * np.arange(n),
        f"{RAW_CAN}/address": np.full(n, 0x24, dtype=np.int64),
        f"{RAW_CAN}/data": np.array([b"\x01\x02\x03"] * n, dtype="S8"),
        f"{RAW_CAN}/src": np.zeros(n, dtype=np.int64),
    }


@pytest.mark.parametrize(
    ("name", "array"),
    [
        ("data", np.zeros(20)),
        ("data", np.array([b"0123456789"] * 20, dtype="S10")),
        ("address", np.full(20, -1.0)),
        ("address", np.full(20, 2.0**40)),
        ("t", np.full(20, np.nan)),
        ("src", np.zeros(19)),
    ],
)
def test_bad_raw_can_arrays_are_named_when_the_can_log_is_written_from_them(tmp_path, name, array):
    """A segment with the DBC but no candump log: the log is written from ``raw_can``."""
    dbc = shared_data_dir() / "comma2k19_example1" / "toyota_2017_motion.dbc"
    if not dbc.is_file():
        pytest.skip(f"{dbc} absent")
    arrays = {**_raw_can(), f"{RAW_CAN}/{name}": array}
    segment, orbits = _import(tmp_path, {k: npy_bytes(v) for k, v in arrays.items()})
    for relative, value in arrays.items():
        (segment / relative).parent.mkdir(parents=True, exist_ok=True)
        (segment / relative).write_bytes(npy_bytes(value))
    (segment / dbc.name).write_bytes(dbc.read_bytes())
    with pytest.raises(InputError) as caught:
        import_comma2k19(segment, tmp_path / "out", orbits)
    assert str(segment / RAW_CAN / name) in str(caught.value)


def test_good_raw_can_arrays_are_written_as_a_candump_log(tmp_path):
    dbc = shared_data_dir() / "comma2k19_example1" / "toyota_2017_motion.dbc"
    if not dbc.is_file():
        pytest.skip(f"{dbc} absent")
    segment, orbits = _import(tmp_path, {})
    for relative, value in _raw_can().items():
        (segment / relative).parent.mkdir(parents=True, exist_ok=True)
        (segment / relative).write_bytes(npy_bytes(value))
    (segment / dbc.name).write_bytes(dbc.read_bytes())
    import_comma2k19(segment, tmp_path / "out", orbits)
    lines = (tmp_path / "out" / "can" / "can_motion.log").read_text().splitlines()
    assert len(lines) == 20 and " 024#0102030000000000" in lines[0]
