"""CAN logs and DBCs that are damaged: unreadable lines resumed after (counted), impossible ids
and times skipped, BLF files python-can cannot open named, ASC times independent of the reading
machine's timezone, a DBC with a megabyte line refused, frames early or duplicated handled by
the stated time-order policy."""

from __future__ import annotations

import contextlib
import gc
import subprocess
import sys
import warnings

import can
import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.io.can import load_dbc, read_can_log, read_can_motion

DBC = """VERSION ""
BS_:
BU_: X
BO_ 36 KIN: 8 X
 SG_ YAW_RATE : 7|16@0- (0.01,0) [-300|300] "deg/s" X
BO_ 170 WHEELS: 8 X
 SG_ WL : 7|16@0+ (0.01,0) [0|600] "km/h" X
"""
T0 = 1.6e9


@pytest.fixture
def dbc(tmp_path):
    path = tmp_path / "bus.dbc"
    path.write_text(DBC)
    return path


def messages(n: int = 10) -> list[can.Message]:
    db = load_dbc_text()
    kin, wheels = db.get_message_by_name("KIN"), db.get_message_by_name("WHEELS")
    out = []
    for i in range(n):
        t = T0 + 0.1 * i
        out.append(
            can.Message(
                timestamp=t,
                arbitration_id=36,
                is_extended_id=False,
                channel=0,
                data=kin.encode({"YAW_RATE": float(i)}),
            )
        )
        out.append(
            can.Message(
                timestamp=t + 0.05,
                arbitration_id=170,
                is_extended_id=False,
                channel=0,
                data=wheels.encode({"WL": 36.0}),
            )
        )
    return out


def load_dbc_text():
    import cantools

    return cantools.database.load_string(DBC, "dbc")


def write_log(path, items) -> None:
    with can.Logger(str(path)) as writer:
        for message in items:
            writer.on_message_received(message)


def test_nan_times_and_ids_beyond_29_bits_are_skipped_and_counted(tmp_path):
    path = tmp_path / "bus.csv"
    write_log(path, messages(3))
    lines = path.read_text().splitlines()
    lines[2] = "nan," + lines[2].split(",", 1)[1]
    lines[3] = lines[3].split(",", 1)[0] + ",0x123456789012345678901," + lines[3].split(",", 2)[2]
    path.write_text("\n".join(lines) + "\n")
    frames = read_can_log(path)
    assert len(frames) == 4 and frames.n_unreadable == 2
    assert np.all(np.isfinite(frames.t))


def test_candump_lines_after_bad_ones_are_read_once(tmp_path):
    path = tmp_path / "bus.log"
    write_log(path, messages(10))
    lines = path.read_text().splitlines()
    damaged = []
    for line in lines:
        damaged += [line, "garbage line", "(1.0) can0 0AA#ZZ"]
    path.write_text("\n".join(damaged) + "\n")
    frames = read_can_log(path)
    assert len(frames) == 20 and frames.n_unreadable == 40
    np.testing.assert_allclose(np.sort(frames.t), sorted(m.timestamp for m in messages(10)))


@pytest.mark.parametrize("content", [b"", b"LOGG", b"garbage" + bytes(200)])
def test_blf_python_can_cannot_open_is_an_input_error(tmp_path, content):
    path = tmp_path / "bus.blf"
    path.write_bytes(content)
    with pytest.raises(InputError, match=r"bus.blf: cannot read the CAN log"):
        read_can_log(path)


def test_prefixed_blf_is_an_input_error(tmp_path):
    good = tmp_path / "good.blf"
    write_log(good, messages(3))
    path = tmp_path / "bus.blf"
    path.write_bytes(b"prefix" + good.read_bytes())
    with pytest.raises(InputError, match=r"bus.blf: cannot read the CAN log"):
        read_can_log(path)


def _files_left_open(read) -> list[str]:
    """The ResourceWarnings (files garbage-collected while open) of calling ``read``, whose
    InputError is let go first (its traceback would keep the reader alive)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ResourceWarning)
        with contextlib.suppress(InputError):
            read()
        gc.collect()
    return [str(w.message) for w in caught if issubclass(w.category, ResourceWarning)]


@pytest.mark.parametrize("suffix", [".blf", ".asc"])
@pytest.mark.parametrize("damage", ["none", "empty", "header", "truncated"])
def test_binary_and_asc_logs_are_closed_however_the_reading_ends(tmp_path, suffix, damage):
    """python-can's readers left the file open when the header was corrupt (ResourceWarning
    in the tests above); a log read through, or stopped by a truncated record, is closed too."""
    path = tmp_path / f"bus{suffix}"
    write_log(path, messages(200))
    whole = path.read_bytes()
    content = {
        "none": whole,
        "empty": b"",
        "header": b"garbage" + bytes(200),
        "truncated": whole[: len(whole) * 2 // 3],
    }[damage]
    path.write_bytes(content)
    assert _files_left_open(lambda: read_can_log(path)) == []


READ_ASC = (
    "import sys; from vo_doppler.io.can import read_can_log; "
    "print(repr(list(read_can_log(sys.argv[1]).t)))"
)


def test_asc_times_do_not_depend_on_the_reading_timezone(tmp_path):
    path = tmp_path / "bus.asc"
    write = (
        "import sys, can; sys.path.insert(0, '.'); from tests.io.test_can_robust import "
        "messages, write_log; write_log(sys.argv[1], messages(3))"
    )
    subprocess.run([sys.executable, "-c", write, str(path)], check=True, env={"TZ": "UTC"})
    times = {
        tz: subprocess.run(
            [sys.executable, "-c", READ_ASC, str(path)],
            check=True,
            capture_output=True,
            text=True,
            env={"TZ": tz},
        ).stdout
        for tz in ("UTC", "Asia/Tokyo", "America/New_York")
    }
    assert len(set(times.values())) == 1
    np.testing.assert_allclose(eval(times["UTC"]), [m.timestamp for m in messages(3)], atol=1e-5)


def test_dbc_with_a_megabyte_line_is_refused(tmp_path):
    path = tmp_path / "bus.dbc"
    path.write_text(DBC + 'CM_ "' + "x" * 1_000_000 + '";\n')
    with pytest.raises(InputError, match=r"bus.dbc:8: CAN database line has 1000007 bytes"):
        load_dbc(path)


def test_dbc_parser_errors_are_wrapped(tmp_path):
    path = tmp_path / "bus.dbc"
    path.write_text("BO_ this is not a DBC\n")
    with pytest.raises(InputError, match=r"bus.dbc: cannot load the CAN database"):
        load_dbc(path)


def test_a_non_dbc_tried_in_every_format_gives_our_error_and_no_deprecation_warning(
    tmp_path, recwarn
):
    """Without a known suffix cantools tries its CDD parser too, which warned that it is
    deprecated beside our error."""
    path = tmp_path / "garbage.obs"
    path.write_text("t,lat_deg,lon_deg\n0,37.7,-122.4\n")
    with pytest.raises(InputError, match=r"garbage.obs: cannot load the CAN database: "):
        load_dbc(path)
    assert [w for w in recwarn if issubclass(w.category, DeprecationWarning)] == []


def test_frames_slightly_late_are_sorted_and_counted(tmp_path, dbc):
    items = messages(10)
    items[4], items[6] = items[6], items[4]  # KIN frames 0.1 s apart swap places
    path = tmp_path / "bus.log"
    write_log(path, items)
    motion = read_can_motion(path, dbc, "KIN.YAW_RATE", "WHEELS.WL")
    np.testing.assert_allclose(np.degrees(motion.yaw_rate.value), np.arange(10.0), atol=1e-9)
    assert motion.report.time_order["KIN"].n_out_of_order == 1


def test_duplicates_with_other_values_keep_the_first_and_are_counted(tmp_path, dbc):
    items = messages(5)
    twin = can.Message(
        timestamp=items[2].timestamp,
        arbitration_id=36,
        is_extended_id=False,
        channel=0,
        data=load_dbc_text().get_message_by_name("KIN").encode({"YAW_RATE": 99.0}),
    )
    same = items[4]
    path = tmp_path / "bus.log"
    write_log(path, [*items[:3], twin, *items[3:5], same, *items[5:]])
    motion = read_can_motion(path, dbc, "KIN.YAW_RATE", "WHEELS.WL")
    order = motion.report.time_order["KIN"]
    assert order.n_conflicting_duplicates == 1 and order.n_duplicates == 1
    np.testing.assert_allclose(np.degrees(motion.yaw_rate.value), np.arange(5.0), atol=1e-9)


def test_a_block_of_frames_seconds_early_is_an_error_naming_the_line(tmp_path, dbc):
    path = tmp_path / "bus.log"
    write_log(path, messages(10))
    lines = path.read_text().splitlines()
    for i in range(10, 14):
        stamp, rest = lines[i][1:].split(")", 1)
        lines[i] = f"({float(stamp) - 5.0:.6f}){rest}"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(
        InputError, match=r"bus.log:11: time goes backwards by 4.9 s in the CAN message KIN"
    ):
        read_can_motion(path, dbc, "KIN.YAW_RATE", "WHEELS.WL")
