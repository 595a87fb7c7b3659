"""CAN ingestion: log formats, DBC decoding, units, sign, padding, bad frames, comma2k19."""

from __future__ import annotations

import math
import struct

import can
import cantools
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import require_shared
from vo_doppler.errors import InputError
from vo_doppler.io.can import (
    SignalRef,
    check_dbc,
    decode_motion,
    decode_signals,
    frames_from_arrays,
    load_dbc,
    parse_signal_list,
    read_can_log,
    read_can_motion,
)
from vo_doppler.io.can_report import CanDecodeReport
from vo_doppler.io.sensor_csv import read_speed_csv, read_yaw_rate_csv, write_sensor_csv
from vo_doppler.model.series import SensorSeries

DBC_TEXT = """VERSION ""
BS_:
BU_: XXX
BO_ 36 KIN: 8 XXX
 SG_ YAW_RATE : 7|16@0- (0.01,0) [-300|300] "deg/s" XXX
BO_ 170 WHEELS: 8 XXX
 SG_ WL : 7|16@0+ (0.01,0) [0|600] "km/h" XXX
 SG_ WR : 23|16@0+ (0.01,0) [0|600] "km/h" XXX
BO_ 171 REAR: 4 XXX
 SG_ W3 : 7|16@0+ (0.01,0) [0|600] "km/h" XXX
BO_ 40 ACC: 4 XXX
 SG_ AX : 7|16@0- (0.001,0) [-30|30] "m/s^2" XXX
 SG_ AG : 23|16@0- (0.0001,0) [-3|3] "g" XXX
BO_ 200 MUXED: 8 XXX
 SG_ SEL M : 0|8@1+ (1,0) [0|255] "" XXX
 SG_ V m1 : 8|16@1+ (1,0) [0|65535] "km/h" XXX
"""

COMMA = "comma2k19_example1"
T0 = 1.6e9  # 2020-09-13: BLF and ASC store calendar dates
FOUR_WHEELS = (
    "WHEEL_SPEEDS.WHEEL_SPEED_FL,WHEEL_SPEEDS.WHEEL_SPEED_FR,"
    "WHEEL_SPEEDS.WHEEL_SPEED_RL,WHEEL_SPEEDS.WHEEL_SPEED_RR"
)


@pytest.fixture
def dbc_path(tmp_path):
    path = tmp_path / "test.dbc"
    path.write_text(DBC_TEXT)
    return path


def _messages(db, n=20):
    """Yaw rate ramps −10…+9 deg/s, wheels 36 and 36.72 km/h (10 and 10.2 m/s)."""
    kin, wheels = db.get_message_by_name("KIN"), db.get_message_by_name("WHEELS")
    out = []
    for i in range(n):
        t = T0 + 0.01 * i
        out.append(
            can.Message(
                timestamp=t,
                arbitration_id=36,
                data=kin.encode({"YAW_RATE": i - 10.0}),
                is_extended_id=False,
                channel=0,
            )
        )
        out.append(
            can.Message(
                timestamp=t + 0.005,
                arbitration_id=170,
                data=wheels.encode({"WL": 36.0, "WR": 36.72}),
                is_extended_id=False,
                channel=0,
            )
        )
    return out


@pytest.mark.parametrize("suffix", [".log", ".asc", ".blf", ".csv"])
def test_every_log_format_decodes_to_si(tmp_path, dbc_path, suffix):
    db = load_dbc(dbc_path)
    path = tmp_path / f"bus{suffix}"
    with can.Logger(str(path)) as writer:
        for message in _messages(db):
            writer.on_message_received(message)
    motion = read_can_motion(path, dbc_path, "KIN.YAW_RATE", "WHEELS.WL,WHEELS.WR")
    assert len(motion.yaw_rate) == 20 and len(motion.speed) == 20
    expected = np.radians(np.arange(20) - 10.0)
    np.testing.assert_allclose(motion.yaw_rate.value, expected, atol=1e-9)
    np.testing.assert_allclose(motion.speed.value, 10.1, atol=1e-9)
    np.testing.assert_allclose(motion.yaw_rate.t, T0 + 0.01 * np.arange(20), atol=1e-5)
    assert motion.report.n_undecodable == 0 and motion.report.n_padded == 0


def test_sign_flag_and_time_offsets(dbc_path):
    db = load_dbc(dbc_path)
    frames = _frames(_messages(db))
    plain = decode_motion(frames, db, SignalRef("KIN", "YAW_RATE"), [SignalRef("WHEELS", "WL")])
    flipped = decode_motion(
        frames,
        db,
        SignalRef("KIN", "YAW_RATE"),
        [SignalRef("WHEELS", "WL")],
        yaw_rate_sign=-1.0,
        yaw_rate_offset_s=2.5,
        speed_offset_s=-1.0,
    )
    np.testing.assert_array_equal(flipped.yaw_rate.value, -plain.yaw_rate.value)
    np.testing.assert_allclose(flipped.yaw_rate.t, plain.yaw_rate.t + 2.5)
    np.testing.assert_allclose(flipped.speed.t, plain.speed.t - 1.0)
    np.testing.assert_allclose(plain.speed.value, 10.0)


def _frames(messages):
    return frames_from_arrays(
        [m.timestamp for m in messages],
        [m.arbitration_id for m in messages],
        np.array([bytes(m.data) for m in messages], dtype=object),
    )


def test_wheels_in_different_messages_are_interpolated(dbc_path):
    db = load_dbc(dbc_path)
    rear = db.get_message_by_name("REAR")
    messages = _messages(db, 10)
    messages += [
        can.Message(
            timestamp=T0 - 0.1 + 0.02 * i, arbitration_id=171, data=rear.encode({"W3": 3.6 * i})
        )
        for i in range(12)
    ]
    motion = decode_motion(_frames(messages), db, None, parse_signal_list("WHEELS.WL,REAR.W3"))
    # W3 is linear in time: i·1 m/s at T0 − 0.1 + 0.02 i.
    expected = 0.5 * (10.0 + (motion.speed.t - (T0 - 0.1)) / 0.02)
    np.testing.assert_allclose(motion.speed.value, expected, atol=1e-4)  # float64 at t ≈ 1.6e9
    assert motion.yaw_rate is None


def test_short_frames_are_skipped_and_named_by_default(dbc_path, caplog):
    db = load_dbc(dbc_path)
    wheels = db.get_message_by_name("WHEELS")
    full = wheels.encode({"WL": 36.0, "WR": 18.0})
    frames = frames_from_arrays(
        [1.0, 2.0, 3.0], [170, 170, 170], [full, full[:3], full], source="bus.log"
    )
    report = CanDecodeReport()
    out = decode_signals(frames, db, parse_signal_list("WHEELS.WL,WHEELS.WR"), report=report)
    assert report.n_short_skipped == 1 and report.n_padded == 0 and report.n_decoded == 2
    np.testing.assert_allclose(out[SignalRef("WHEELS", "WR")].t, [1.0, 3.0])
    np.testing.assert_allclose(out[SignalRef("WHEELS", "WR")].value, [5.0, 5.0])
    message = caplog.text
    assert "bus.log" in message and "0xAA" in message and "3 of 8 bytes" in message
    assert "t = 2.000000 s" in message


def test_short_frames_are_padded_and_counted_on_request(dbc_path):
    db = load_dbc(dbc_path)
    wheels = db.get_message_by_name("WHEELS")
    full = wheels.encode({"WL": 36.0, "WR": 0.0})  # WR bytes and the tail are zero
    frames = frames_from_arrays([1.0, 2.0], [170, 170], [full, full.rstrip(b"\0")])
    report = CanDecodeReport()
    refs = parse_signal_list("WHEELS.WL,WHEELS.WR")
    out = decode_signals(frames, db, refs, report=report, short_frames="pad")
    assert report.n_padded == 1 and report.n_short_skipped == 0 and report.n_decoded == 2
    np.testing.assert_allclose(out[SignalRef("WHEELS", "WL")].value, [10.0, 10.0])
    np.testing.assert_allclose(out[SignalRef("WHEELS", "WR")].value, [0.0, 0.0])
    with pytest.raises(ValueError, match="short_frames"):
        decode_signals(frames, db, refs, short_frames="guess")


def test_undecodable_frames_are_counted_not_fatal(dbc_path):
    db = load_dbc(dbc_path)
    muxed = db.get_message_by_name("MUXED")
    good = muxed.encode({"SEL": 1, "V": 72})
    bad = bytes([7]) + good[1:]  # multiplexer value 7 is not in the DBC
    frames = frames_from_arrays([1.0, 2.0, 3.0], [200, 200, 200], [good, bad, good])
    report = CanDecodeReport()
    out = decode_signals(frames, db, [SignalRef("MUXED", "V")], report=report)
    np.testing.assert_allclose(out[SignalRef("MUXED", "V")].value, [20.0, 20.0])
    assert report.n_undecodable == 1 and report.undecodable_by_id == {200: 1}
    assert "1 undecodable (0xC8×1)" in report.summary()


def test_unreadable_candump_lines_are_skipped(tmp_path, dbc_path):
    db = load_dbc(dbc_path)
    path = tmp_path / "bus.log"
    with can.Logger(str(path)) as writer:
        for message in _messages(db, 6):
            writer.on_message_received(message)
    lines = path.read_text().splitlines()
    lines.insert(3, "this is not a candump line")
    lines.insert(7, "(1600000000.05) vcan0 0AA#ZZZZ")
    path.write_text("\n".join(lines) + "\n")
    frames = read_can_log(path)
    assert len(frames) == 12 and frames.n_unreadable == 2
    motion = read_can_motion(path, dbc_path, "KIN.YAW_RATE", "WHEELS.WL")
    assert motion.report.n_unreadable_lines == 2 and len(motion.yaw_rate) == 6


def test_bad_signal_names_and_units(dbc_path):
    db = load_dbc(dbc_path)
    frames = _frames(_messages(db, 2))
    with pytest.raises(InputError, match="not in the DBC"):
        decode_motion(frames, db, SignalRef("KIN", "NOPE"))
    with pytest.raises(InputError, match=r"MESSAGE\.SIGNAL"):
        SignalRef.parse("YAW_RATE")
    with pytest.raises(InputError, match="not an angular rate"):
        decode_motion(frames, db, SignalRef("WHEELS", "WL"))
    with pytest.raises(InputError, match="unknown CAN log format"):
        read_can_log(dbc_path)


@settings(max_examples=40, deadline=None)
@given(  # what a car can report (vo_doppler.bounds): ±286 deg/s, 540 km/h
    yaw=st.floats(-286, 286, allow_nan=False).map(lambda v: round(v, 2)),
    kmh=st.floats(0, 540, allow_nan=False).map(lambda v: round(v, 2)),
)
def test_decode_round_trip_property(yaw, kmh):
    db = cantools.database.load_string(DBC_TEXT, "dbc")
    frames = frames_from_arrays(
        [0.0, 0.001],
        [36, 170],
        [
            db.get_message_by_name("KIN").encode({"YAW_RATE": yaw}),
            db.get_message_by_name("WHEELS").encode({"WL": kmh, "WR": kmh}),
        ],
    )
    motion = decode_motion(frames, db, SignalRef("KIN", "YAW_RATE"), parse_signal_list("WHEELS.WL"))
    assert math.isclose(motion.yaw_rate.value[0], math.radians(yaw), abs_tol=1e-9)
    assert math.isclose(motion.speed.value[0], kmh / 3.6, abs_tol=1e-9)


def test_sensor_csv_round_trip_and_bad_rows(tmp_path):
    series = SensorSeries([0.0, 0.05, 0.1], [0.1, -0.2, 0.3])
    path = tmp_path / "yaw.csv"
    write_sensor_csv(path, series, "yaw_rate_rad_s")
    back = read_yaw_rate_csv(path, time_offset_s=10.0)
    np.testing.assert_allclose(back.t, [10.0, 10.05, 10.1])
    np.testing.assert_allclose(back.value, series.value)
    speed = tmp_path / "speed.csv"
    speed.write_text("t,speed_mps\n0,1.0\n# comment\n1,nan\n2,abc\n3,4.0\n")
    got = read_speed_csv(speed)
    np.testing.assert_allclose(got.value, [1.0, 4.0])
    speed.write_text("t,speed_mps\n1,1.0\n0,2.0\n")
    with pytest.raises(InputError, match=r"speed.csv:3: time goes backwards"):
        read_speed_csv(speed)
    with pytest.raises(InputError, match=r"speed.csv:1: .*lacks column\(s\) yaw_rate_rad_s"):
        read_yaw_rate_csv(speed)


@pytest.mark.shared_data
def test_comma_candump_reproduces_processed_wheel_speed():
    log_path = require_shared(f"{COMMA}/can_motion.log")
    dbc = require_shared(f"{COMMA}/toyota_2017_motion.dbc")
    processed = require_shared(f"{COMMA}/processed_log/CAN/wheel_speed")
    expected_t = np.load(processed / "t")
    expected = np.load(processed / "value")  # columns FL, FR, RL, RR in m/s
    frames = read_can_log(log_path)
    db = load_dbc(dbc)
    refs = parse_signal_list(FOUR_WHEELS)
    decoded = decode_signals(frames, db, refs)
    for k, ref in enumerate(refs):
        assert len(decoded[ref]) == len(expected_t) == 4974
        np.testing.assert_allclose(decoded[ref].t, expected_t, atol=1e-6)
        assert np.max(np.abs(decoded[ref].value - expected[:, k])) <= 0.01
    motion = read_can_motion(log_path, dbc, "KINEMATICS.YAW_RATE", FOUR_WHEELS)
    assert np.max(np.abs(motion.speed.value - expected.mean(axis=1))) <= 0.01
    assert motion.report.n_undecodable == 0 and motion.report.n_unreadable_lines == 0


@pytest.mark.shared_data
def test_comma_raw_can_truncated_payloads():
    raw = require_shared(f"{COMMA}/processed_log/CAN/raw_can")
    dbc = require_shared(f"{COMMA}/toyota_2017_motion.dbc")
    expected = np.load(require_shared(f"{COMMA}/processed_log/CAN/wheel_speed/value"))
    data = np.load(raw / "data")
    assert data.dtype == np.dtype("S8")
    frames = frames_from_arrays(
        np.load(raw / "t"), np.load(raw / "address"), data, np.load(raw / "src")
    )
    report = CanDecodeReport()
    decoded = decode_signals(
        frames,
        load_dbc(dbc),
        parse_signal_list(FOUR_WHEELS),
        channel="0",
        report=report,
        short_frames="pad",  # numpy S8 dropped the payloads' trailing zero bytes
    )
    assert report.n_padded > 0 and report.n_undecodable == 0
    for k, ref in enumerate(parse_signal_list(FOUR_WHEELS)):
        assert np.max(np.abs(decoded[ref].value - expected[:, k])) <= 0.01


def _acceleration_messages(db, n=10):
    acc = db.get_message_by_name("ACC")
    return [
        can.Message(
            timestamp=T0 + 0.01 * i,
            arbitration_id=40,
            data=acc.encode({"AX": 0.5 * i, "AG": 0.05}),
            is_extended_id=False,
            channel=0,
        )
        for i in range(n)
    ]


def test_longitudinal_acceleration_in_m_s2_or_g_decodes_to_si(tmp_path, dbc_path):
    path = tmp_path / "bus.log"
    with can.Logger(str(path)) as writer:
        for message in _acceleration_messages(load_dbc(dbc_path)):
            writer.on_message_received(message)
    ax = read_can_motion(path, dbc_path, forward_acceleration="ACC.AX", yaw_rate_offset_s=1.5)
    np.testing.assert_allclose(ax.forward_acceleration.value, 0.5 * np.arange(10), atol=1e-9)
    np.testing.assert_allclose(ax.forward_acceleration.t, T0 + 1.5 + 0.01 * np.arange(10))
    ag = read_can_motion(path, dbc_path, forward_acceleration="ACC.AG")
    np.testing.assert_allclose(ag.forward_acceleration.value, 0.05 * 9.80665, atol=1e-9)
    assert read_can_motion(path, dbc_path).forward_acceleration is None


def test_an_acceleration_signal_that_is_not_one_is_named(tmp_path, dbc_path):
    path = tmp_path / "bus.log"
    path.write_text("(1600000000.000000) can0 028#00C8000000\n")
    with pytest.raises(InputError, match=r"WHEELS\.WL is in m/s, not m/s²"):
        read_can_motion(path, dbc_path, forward_acceleration="WHEELS.WL")


def _wheel_log(path, db, kmh) -> None:
    """A candump log of WHEELS frames at 100 Hz from T0, WL = WR = ``kmh[k]``."""
    wheels = db.get_message_by_name("WHEELS")
    with can.Logger(str(path)) as writer:
        for k, value in enumerate(kmh):
            writer.on_message_received(
                can.Message(
                    timestamp=T0 + 0.01 * k,
                    arbitration_id=170,
                    data=wheels.encode({"WL": value, "WR": value}),
                    is_extended_id=False,
                    channel=0,
                )
            )


def test_an_isolated_wheel_speed_beyond_a_car_is_skipped_and_named(tmp_path, dbc_path):
    kmh = np.full(200, 36.0)
    kmh[57] = 599.0  # 166 m/s: beyond any road vehicle
    path = tmp_path / "bus.log"
    _wheel_log(path, load_dbc(dbc_path), kmh)
    motion = read_can_motion(path, dbc_path, wheel_speed="WHEELS.WL,WHEELS.WR")
    assert len(motion.speed) == 199 and np.all(motion.speed.value == pytest.approx(10.0))
    assert T0 + 0.57 not in motion.speed.t
    problems = motion.report.problems()
    assert len(problems) == 2  # one per wheel signal
    assert "1 of the 200 samples of WHEELS.WL" in problems[0]
    assert f"at t = {T0 + 0.57:.6f} s" in problems[0] and "[-10, 150] m/s" in problems[0]


def test_a_wheel_speed_often_beyond_a_car_is_an_error_naming_signal_and_time(tmp_path, dbc_path):
    kmh = np.full(200, 36.0)
    kmh[[20, 90, 150]] = 599.0  # 1.5 % of the samples: a wrong factor, not a glitch
    path = tmp_path / "bus.log"
    _wheel_log(path, load_dbc(dbc_path), kmh)
    with pytest.raises(InputError, match="check the DBC factor") as info:
        read_can_motion(path, dbc_path, wheel_speed="WHEELS.WL")
    message = str(info.value)
    assert message.startswith(f"{path}: 3 of the 200 samples of WHEELS.WL")
    assert f"at t = {T0 + 0.2:.6f} s" in message


def test_a_candump_log_named_asc_is_an_error_saying_what_it_looks_like(tmp_path, dbc_path):
    path = tmp_path / "bus.asc"
    _wheel_log(tmp_path / "bus.log", load_dbc(dbc_path), np.full(5, 36.0))
    path.write_bytes((tmp_path / "bus.log").read_bytes())
    with pytest.raises(InputError) as info:
        read_can_motion(path, dbc_path, wheel_speed="WHEELS.WL")
    message = str(info.value)
    assert message.startswith(f"{path}: no CAN frame in this ASC log")
    assert "none of its 5 lines is one" in message
    assert "a candump -l line: name the file .log" in message
    assert not message.rstrip().endswith(";")


def test_a_log_without_the_requested_message_is_an_error(tmp_path, dbc_path):
    path = tmp_path / "bus.log"
    _wheel_log(path, load_dbc(dbc_path), np.full(5, 36.0))
    with pytest.raises(InputError, match=r"no decodable frame of message\(s\) KIN in the log "):
        read_can_motion(path, dbc_path, "KIN.YAW_RATE", "WHEELS.WL")
    with pytest.raises(InputError, match=r"from the log on channel 'can9' \(0 frames"):
        read_can_motion(path, dbc_path, wheel_speed="WHEELS.WL", channel="can9")
    path.write_text("0.010000 1 0AA Rx d 8 00 00 00 00 00 00 00 00\n" * 3)  # ASC lines
    with pytest.raises(InputError, match=r"log \(0 frames, .*, 3 unreadable log lines\)"):
        read_can_motion(path, dbc_path, wheel_speed="WHEELS.WL")


def test_check_dbc_names_the_file_and_the_missing_or_wrong_signal(dbc_path):
    check_dbc(dbc_path, "KIN.YAW_RATE", "WHEELS.WL,REAR.W3")
    with pytest.raises(InputError, match=r"test.dbc: signal WHEELS.NOPE is not in the DBC"):
        check_dbc(dbc_path, "KIN.YAW_RATE", "WHEELS.WL,WHEELS.NOPE")
    with pytest.raises(InputError, match=r"test.dbc: KIN.YAW_RATE is in rad/s, not m/s"):
        check_dbc(dbc_path, "KIN.YAW_RATE", "KIN.YAW_RATE")


def test_a_float_signal_decoded_as_nan_skips_its_frame(tmp_path):
    """A NaN or infinity from an IEEE float signal is no measurement: its frame is counted as
    undecodable and left out, since a SensorSeries refuses non-finite values."""
    dbc = tmp_path / "float.dbc"
    dbc.write_text(
        'VERSION ""\n\nBU_:\n\nBO_ 300 IMU: 8 Vector__XXX\n'
        ' SG_ YAW : 0|32@1- (1,0) [-10|10] "rad/s" Vector__XXX\n\n'
        "SIG_VALTYPE_ 300 YAW : 1;\n"
    )
    db = load_dbc(dbc)
    payloads = [struct.pack("<f", v) + bytes(4) for v in (0.1, math.nan, 0.3, math.inf)]
    frames = frames_from_arrays([1.0, 2.0, 3.0, 4.0], [300] * 4, payloads)
    report = CanDecodeReport()
    out = decode_signals(frames, db, parse_signal_list("IMU.YAW"), report=report)
    series = out[SignalRef("IMU", "YAW")]
    np.testing.assert_array_equal(series.t, [1.0, 3.0])
    np.testing.assert_allclose(series.value, [0.1, 0.3], rtol=1e-7)
    assert report.n_undecodable == 2 and report.undecodable_by_id == {300: 2}
