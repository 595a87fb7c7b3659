"""The project's ROS message types beside rosbags' stock stores, and field access that ignores
the drivers' spellings (rcvTOW, rcv_tow, rcvTow)."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.io.rosbag_types import field, has_field, project_types, typestore


@pytest.mark.parametrize("ros2", [False, True])
def test_the_stores_hold_stock_and_project_types(ros2):
    store = typestore(ros2)
    assert typestore(ros2) is store  # built once per process
    for name in (
        "sensor_msgs/msg/Imu",
        "gnss_comm/msg/GnssMeasMsg",
        "can_msgs/msg/Frame",
        "ublox_msgs/msg/RxmRAWX",
        "tf2_msgs/msg/TFMessage",
    ):
        assert name in store.types, name
    measurement = "ublox_msgs/msg/RxmRAWXMeas" if ros2 else "ublox_msgs/msg/RxmRAWX_Meas"
    assert measurement in project_types(ros2)


def test_a_can_frame_serialises_and_reads_back_in_both_encodings():
    for ros2 in (False, True):
        store = typestore(ros2)
        types = store.types
        stamp = types["builtin_interfaces/msg/Time"](sec=5, nanosec=7)
        header_fields = {"stamp": stamp, "frame_id": "can0"} | ({} if ros2 else {"seq": 1})
        frame = types["can_msgs/msg/Frame"](
            header=types["std_msgs/msg/Header"](**header_fields),
            id=0x1F4,
            is_rtr=False,
            is_extended=False,
            is_error=False,
            dlc=8,
            data=np.arange(8, dtype=np.uint8),
        )
        if ros2:
            back = store.deserialize_cdr(
                store.serialize_cdr(frame, "can_msgs/msg/Frame"), "can_msgs/msg/Frame"
            )
        else:
            back = store.deserialize_ros1(
                store.serialize_ros1(frame, "can_msgs/msg/Frame"), "can_msgs/msg/Frame"
            )
        assert back.id == 0x1F4 and back.dlc == 8
        np.testing.assert_array_equal(back.data, np.arange(8))


def test_fields_are_found_in_any_spelling():
    ros1 = typestore(False).types["ublox_msgs/msg/RxmRAWX"]
    ros2 = typestore(True).types["ublox_msgs/msg/RxmRAWX"]
    values = {"week": 2300, "num_meas": 0, "rec_stat": 1, "version": 1, "meas": []}
    one = ros1(rcvTOW=12.5, leapS=18, numMeas=0, recStat=1, week=2300, version=1,
               reserved1=np.zeros(2, np.uint8), meas=[])  # fmt: skip
    types = typestore(True).types
    header = types["std_msgs/msg/Header"](
        stamp=types["builtin_interfaces/msg/Time"](sec=0, nanosec=0), frame_id=""
    )
    two = ros2(header=header, rcv_tow=12.5, leap_s=18, reserved1=np.zeros(2, np.uint8), **values)
    for message in (one, two):
        assert field(message, "rcv_tow") == field(message, "rcvTOW") == 12.5
        assert field(message, "RcvTow") == 12.5 and field(message, "leap_s") == 18
        assert has_field(message, "numMeas") and has_field(message, "num_meas")
        assert not has_field(message, "pr_mes")
        assert field(message, "pr_mes", default=-1.0) == -1.0
