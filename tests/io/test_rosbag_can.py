"""Wheel speed and yaw rate from a CAN topic of a ROS bag: frames encoded with cantools from a
small DBC, written as ``can_msgs/Frame`` to ROS 1 and ROS 2 bags with rosbags' writers and
imported back exactly; frames that cannot be frames are errors naming the bag, topic and message
index."""

from __future__ import annotations

from pathlib import Path

import cantools
import numpy as np
import pytest

from tests.helpers.rosbag_writer import SmallBag, bag_path, frame_fields, ros_ns
from vo_doppler.cli import main
from vo_doppler.errors import InputError, UsageError
from vo_doppler.io.rosbag_import import RosbagOptions, import_rosbag, list_topics
from vo_doppler.io.sequence import read_manifest, read_sequence

DBC = """VERSION ""

NS_ :

BS_:

BU_: ABS

BO_ 416 WHEELS: 8 ABS
 SG_ RL : 0|16@1+ (0.01,0) [0|655.35] "km/h" Vector__XXX
 SG_ RR : 16|16@1+ (0.01,0) [0|655.35] "km/h" Vector__XXX
 SG_ COUNTER : 56|4@1+ (1,0) [0|15] "" Vector__XXX

BO_ 2566844926 BRAKE: 4 ABS
 SG_ PRESSURE : 0|16@1+ (0.1,0) [0|6553.5] "bar" Vector__XXX

BO_ 896 DYNAMICS: 4 ABS
 SG_ YAW_RATE : 0|16@1- (0.01,0) [-327.68|327.67] "deg/s" Vector__XXX
 SG_ LAT_ACCEL : 16|16@1- (0.001,0) [-32.768|32.767] "m/s^2" Vector__XXX
"""
WHEELS = "WHEELS.RL,WHEELS.RR"
YAW = "DYNAMICS.YAW_RATE"
ORIGIN = (22.3, 114.17, 10.0)
T0_GPS = 1_400_000_000.0
N_WHEEL = 50
PERIOD_S = 0.02


@pytest.fixture(scope="module")
def dbc(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("dbc") / "car.dbc"
    path.write_text(DBC)
    return path


def _raw_speeds() -> tuple[np.ndarray, np.ndarray]:
    """Raw wheel values (0.01 km/h steps) of the RL and RR wheels: 36 to 54 km/h, apart."""
    k = np.arange(N_WHEEL)
    return 1000 * 3.6 + 37 * k, 1000 * 3.6 + 41 * k + 3


def _raw_yaw_rates() -> np.ndarray:
    """Raw yaw-rate values (0.01 deg/s steps): a left turn easing into a right one, ±25 deg/s."""
    return np.round(2500 * np.cos(np.linspace(0.0, np.pi, N_WHEEL))).astype(int)


def write_can_bag(
    path: Path, flavour: str, dbc: Path, edit=None, yaw: bool = False, imu: bool = True
) -> Path:
    """A bag with ``/imu/data`` (unless not ``imu``) and ``/can/rx``: per wheel period a WHEELS
    frame, an extended BRAKE frame, (with ``yaw``) a DYNAMICS frame, and (every 10th) an RTR and
    an error frame, with ``edit(index, fields)`` applied to the CAN messages' fields."""
    database = cantools.database.load_file(dbc)
    rl, rr = _raw_speeds()
    with SmallBag(path, flavour) as bag:
        if imu:
            bag.imu(T0_GPS + np.arange(N_WHEEL) * PERIOD_S, 0.1)
        index = 0
        for k in range(N_WHEEL):
            t_ns = ros_ns(T0_GPS + k * PERIOD_S + 0.005)
            values = {"RL": rl[k] * 0.01, "RR": rr[k] * 0.01, "COUNTER": k % 16}
            wheels = database.encode_message("WHEELS", values)
            brake = database.encode_message("BRAKE", {"PRESSURE": 12.5})
            frames = [(416, {}, wheels), (0x18FF00FE, {"is_extended": True}, brake)]
            if yaw:
                turn = {"YAW_RATE": _raw_yaw_rates()[k] * 0.01, "LAT_ACCEL": 0.5}
                frames.append((896, {}, database.encode_message("DYNAMICS", turn)))
            if k % 10 == 0:
                frames += [(416, {"is_rtr": True}, b""), (0x1, {"is_error": True}, b"")]
            for frame_id, flags, data in frames:
                fields = frame_fields(bag, t_ns, frame_id, data, **flags)
                if edit is not None:
                    edit(index, fields)
                bag.can_frame("/can/rx", t_ns, fields)
                index += 1
    return path


def _options(dbc: Path, **extra) -> RosbagOptions:
    return RosbagOptions(**({"origin": ORIGIN, "dbc": dbc, "wheel_speed": WHEELS} | extra))


@pytest.mark.parametrize("flavour", ["ros1", "sqlite3", "mcap"])
def test_wheel_speed_from_the_can_topic_round_trips(tmp_path, dbc, flavour):
    bag = write_can_bag(bag_path(tmp_path, flavour, "can"), flavour, dbc)
    summary = import_rosbag(bag, tmp_path / "seq", _options(dbc))
    speed = read_sequence(tmp_path / "seq").wheel_speed
    rl, rr = _raw_speeds()
    np.testing.assert_allclose(speed.value, (rl + rr) * 0.01 / 2 / 3.6, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        speed.t, T0_GPS + np.arange(N_WHEEL) * PERIOD_S + 0.005, rtol=0, atol=1e-6
    )
    assert summary.speed_samples == N_WHEEL and not summary.warnings
    record = read_manifest(tmp_path / "seq")["rosbag"]
    assert record["speed"] == f"CAN topic /can/rx: {WHEELS} decoded with {dbc}"
    assert record["topics"]["can"] == "/can/rx" and "speed" not in record["topics"]


def test_the_listing_names_the_can_topic_only_with_a_dbc(tmp_path, dbc):
    bag = write_can_bag(bag_path(tmp_path, "ros1", "can"), "ros1", dbc)
    line = next(line for line in list_topics(bag, _options(dbc)) if "/can/rx" in line)
    assert "can_msgs/msg/Frame" in line and line.rstrip().endswith("can")
    line = next(line for line in list_topics(bag) if "/can/rx" in line)
    assert line.rstrip().endswith("-")
    hint = r"no TwistStamped.*; its CAN topic /can/rx gives one with --dbc FILE --wheel-speed"
    with pytest.raises(InputError, match=hint):
        import_rosbag(bag, tmp_path / "seq", RosbagOptions(origin=ORIGIN))


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"dlc": 9}, r"message 6: dlc 9 with 8 data bytes \(a classic CAN frame holds at most 8"),
        ({"id": 0x800}, r"message 6: CAN id 0x800 is beyond 11 \(is_extended is false\) bits"),
        (
            {"id": 0x2000_0000, "is_extended": True},
            r"message 6: CAN id 0x20000000 is beyond 29 bits",
        ),
    ],
)
def test_a_frame_that_cannot_be_one_names_topic_and_index(tmp_path, dbc, change, message):
    def edit(index, fields):
        if index == 6:
            fields.update(change)

    bag = write_can_bag(bag_path(tmp_path, "ros1", "bad"), "ros1", dbc, edit)
    with pytest.raises(InputError, match=rf"^{bag}: topic /can/rx, {message}"):
        import_rosbag(bag, tmp_path / "seq", _options(dbc))
    assert not (tmp_path / "seq").exists()


def test_short_wheel_frames_are_skipped_with_the_first_index(tmp_path, dbc):
    """Messages 6 and 8 (WHEELS frames 2 and 3 of the 50) carry 5 of their 8 bytes."""

    def edit(index, fields):
        if index in (6, 8):
            fields["dlc"] = 5

    bag = write_can_bag(bag_path(tmp_path, "mcap", "short"), "mcap", dbc, edit)
    summary = import_rosbag(bag, tmp_path / "seq", _options(dbc))
    assert summary.speed_samples == N_WHEEL - 2
    assert summary.warnings == [
        f"{bag}: topic /can/rx: 2 frames of WHEELS shorter than its DBC length of 8 bytes "
        "skipped (the first, message 6: dlc 5)"
    ]
    rl, rr = _raw_speeds()
    keep = np.ones(N_WHEEL, bool)
    keep[[2, 3]] = False
    speed = read_sequence(tmp_path / "seq").wheel_speed
    np.testing.assert_allclose(speed.value, (rl + rr)[keep] * 0.01 / 2 / 3.6, atol=1e-12)


def test_signals_and_options_are_checked(tmp_path, dbc):
    bag = write_can_bag(bag_path(tmp_path, "ros1", "can"), "ros1", dbc)
    with pytest.raises(InputError, match=rf"^{dbc}: signal WHEELS.RX is not in the DBC"):
        import_rosbag(bag, tmp_path / "a", _options(dbc, wheel_speed="WHEELS.RX"))
    with pytest.raises(InputError, match=rf"^{dbc}: .*BRAKE.PRESSURE.*bar"):
        import_rosbag(bag, tmp_path / "b", _options(dbc, wheel_speed="BRAKE.PRESSURE"))
    with pytest.raises(UsageError, match="--speed-topic and --wheel-speed both give the speed"):
        import_rosbag(bag, tmp_path / "c", _options(dbc, speed_topic="/x"))
    with pytest.raises(InputError, match=r"fewer than 2 decodable frames of WHEELS"):
        import_rosbag(
            write_can_bag(
                bag_path(tmp_path, "ros1", "none"),
                "ros1",
                dbc,
                lambda i, f: f.update(id=0x123) if f["id"] == 416 else None,
            ),
            tmp_path / "d",
            _options(dbc),
        )


@pytest.mark.slow
def test_cli_takes_the_dbc_and_refuses_half_of_it(tmp_path, dbc, capsys):
    bag = write_can_bag(bag_path(tmp_path, "sqlite3", "can"), "sqlite3", dbc)
    argv = ["import", "rosbag", str(bag), "--origin", "22.3,114.17,10", "-o"]
    assert main([*argv, str(tmp_path / "s"), "--dbc", str(dbc), "--wheel-speed", WHEELS]) == 0
    assert len(read_sequence(tmp_path / "s").wheel_speed) == N_WHEEL
    for extra in (["--dbc", str(dbc)], ["--wheel-speed", WHEELS], ["--can-topic", "/can/rx"]):
        with pytest.raises(SystemExit) as exit_info:
            main([*argv, str(tmp_path / "t"), *extra])
        assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert "--dbc FILE needs the signals to decode: --wheel-speed MSG.SIG[,MSG.SIG] and/or" in err
    assert "--wheel-speed and --yaw-rate are signals of a DBC: give --dbc FILE" in err
    assert "--can-topic needs --dbc FILE and its signals (--wheel-speed, --yaw-rate)" in err


@pytest.mark.parametrize(("flavour", "sign"), [("ros1", 1.0), ("sqlite3", -1.0), ("mcap", 1.0)])
def test_yaw_rate_from_the_can_topic_round_trips(tmp_path, dbc, flavour, sign):
    """DYNAMICS.YAW_RATE in deg/s, counter-clockwise positive on this bus (sign 1) or read as a
    clockwise-positive one (sign −1): rad/s, times the sign, at the frames' times; the IMU's
    yaw rate (0.1 rad/s) is not used, the wheel speed comes from the same topic."""
    bag = write_can_bag(bag_path(tmp_path, flavour, "yaw"), flavour, dbc, yaw=True)
    options = _options(dbc, yaw_rate=YAW, yaw_rate_sign=sign)
    summary = import_rosbag(bag, tmp_path / "seq", options)
    seq = read_sequence(tmp_path / "seq")
    want = sign * np.radians(_raw_yaw_rates() * 0.01)
    np.testing.assert_allclose(seq.yaw_rate.value, want, rtol=0, atol=1e-12)
    times = T0_GPS + np.arange(N_WHEEL) * PERIOD_S + 0.005
    np.testing.assert_allclose(seq.yaw_rate.t, times, rtol=0, atol=1e-6)
    assert seq.yaw_rate.value[0] == pytest.approx(sign * np.radians(25.0), abs=1e-12)
    rl, rr = _raw_speeds()
    np.testing.assert_allclose(seq.wheel_speed.value, (rl + rr) * 0.01 / 2 / 3.6, atol=1e-12)
    assert summary.yaw_rate_samples == N_WHEEL and not summary.warnings
    flipped = " × −1 (clockwise positive on the bus)" if sign < 0 else ""
    source = f"CAN topic /can/rx: {YAW}{flipped} decoded with {dbc}"
    assert summary.yaw_rate_source == source
    assert read_manifest(tmp_path / "seq")["rosbag"]["yaw_rate"] == source


def test_yaw_rate_alone_from_can_in_a_bag_without_imu(tmp_path, dbc):
    """A bag of a twist topic and CAN frames only: the yaw rate from CAN, the speed from the
    twist, no forward acceleration (no accelerometer); without --yaw-rate the error says how."""
    bag = _can_and_twist_bag(tmp_path / "both.bag", dbc)
    hint = "no sensor_msgs/Imu topic; its CAN topic /can/rx gives one with --dbc FILE --yaw-rate"
    with pytest.raises(InputError, match=hint):
        import_rosbag(bag, tmp_path / "a", RosbagOptions(origin=ORIGIN))
    options = RosbagOptions(origin=ORIGIN, dbc=dbc, yaw_rate=YAW)
    summary = import_rosbag(bag, tmp_path / "b", options)
    seq = read_sequence(tmp_path / "b")
    want = np.radians(_raw_yaw_rates() * 0.01)
    np.testing.assert_allclose(seq.yaw_rate.value, want, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(seq.wheel_speed.value, np.full(N_WHEEL, 7.5))
    assert seq.forward_acceleration is None
    assert summary.speed_source == "topic /vehicle/twist: twist linear.x"
    record = read_manifest(tmp_path / "b")["rosbag"]
    assert record["imu_yaw_axis"] == "none: no IMU topic" and "imu" not in record["topics"]
    no_speed = write_can_bag(
        bag_path(tmp_path, "mcap", "nospeed"), "mcap", dbc, yaw=True, imu=False
    )
    hint = "needs a speed: .*; its CAN topic /can/rx gives one with --dbc FILE --wheel-speed"
    with pytest.raises(InputError, match=hint):
        import_rosbag(no_speed, tmp_path / "c", options)


def _can_and_twist_bag(path: Path, dbc: Path) -> Path:
    """``/vehicle/twist`` at 7.5 m/s and DYNAMICS frames on ``/can/rx``, no IMU."""
    database = cantools.database.load_file(dbc)
    times = T0_GPS + np.arange(N_WHEEL) * PERIOD_S
    with SmallBag(path, "ros1") as bag:
        bag.twist(times, 7.5)
        for k, t in enumerate(times):
            t_ns = ros_ns(t + 0.005)
            turn = {"YAW_RATE": _raw_yaw_rates()[k] * 0.01, "LAT_ACCEL": 0.0}
            data = database.encode_message("DYNAMICS", turn)
            bag.can_frame("/can/rx", t_ns, frame_fields(bag, t_ns, 896, data))
    return path


def test_yaw_rate_signal_and_options_are_checked(tmp_path, dbc):
    bag = write_can_bag(bag_path(tmp_path, "ros1", "yaw"), "ros1", dbc, yaw=True)
    with pytest.raises(InputError, match=rf"^{dbc}: .*DYNAMICS.LAT_ACCEL.*m/s"):
        import_rosbag(bag, tmp_path / "a", _options(dbc, yaw_rate="DYNAMICS.LAT_ACCEL"))
    with pytest.raises(InputError, match=rf"^{dbc}: signal DYNAMICS.YAW is not in the DBC"):
        import_rosbag(bag, tmp_path / "b", _options(dbc, yaw_rate="DYNAMICS.YAW"))
    with pytest.raises(UsageError, match=r"--yaw-rate-sign needs --yaw-rate MSG\.SIG"):
        import_rosbag(bag, tmp_path / "c", _options(dbc, yaw_rate_sign=-1.0))
    with pytest.raises(UsageError, match="--wheel-speed and --yaw-rate are signals of a DBC"):
        import_rosbag(bag, tmp_path / "d", RosbagOptions(origin=ORIGIN, yaw_rate=YAW))
    no_yaw = write_can_bag(bag_path(tmp_path, "ros1", "noyaw"), "ros1", dbc)
    with pytest.raises(InputError, match=r"fewer than 2 decodable frames of DYNAMICS"):
        import_rosbag(no_yaw, tmp_path / "e", _options(dbc, yaw_rate=YAW))


@pytest.mark.slow
def test_cli_takes_the_yaw_rate_and_its_sign(tmp_path, dbc):
    bag = write_can_bag(bag_path(tmp_path, "ros1", "yaw"), "ros1", dbc, yaw=True)
    argv = ["import", "rosbag", str(bag), "--origin", "22.3,114.17,10", "--dbc", str(dbc)]
    argv += ["--wheel-speed", WHEELS, "--yaw-rate", YAW, "--yaw-rate-sign", "-1", "-o"]
    assert main([*argv, str(tmp_path / "s")]) == 0
    want = -np.radians(_raw_yaw_rates() * 0.01)
    np.testing.assert_allclose(read_sequence(tmp_path / "s").yaw_rate.value, want, atol=1e-12)
