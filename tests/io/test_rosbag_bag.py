"""An open ROS bag: its kind from the path, its topics with types and counts, messages decoded
in order with their receive times, and errors naming the bag, topic and message."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.rosbag_writer import SmallBag, bag_path, ros_ns
from vo_doppler.errors import InputError
from vo_doppler.io.rosbag_bag import Bag, Topic, bag_kind

T0 = 1_400_000_000.0


@pytest.fixture(params=["ros1", "sqlite3", "mcap"])
def small_bag(request, tmp_path):
    """Three IMU messages 0.1 s apart (yaw rates 0.1, 0.2, 0.3) and two twists."""
    path = bag_path(tmp_path, request.param, "small")
    with SmallBag(path, request.param) as out:
        out.imu(T0 + np.array([0.0, 0.1, 0.2]), np.array([0.1, 0.2, 0.3]))
        out.twist(T0 + np.array([0.05, 0.15]), 7.5)
    return path


def test_the_topics_and_their_messages_in_order(small_bag):
    with Bag(small_bag) as bag:
        assert bag.topics() == [
            Topic("/imu/data", "sensor_msgs/msg/Imu", 3),
            Topic("/vehicle/twist", "geometry_msgs/msg/TwistStamped", 2),
        ]
        assert bag.start_s() == pytest.approx(ros_ns(T0) * 1e-9, abs=1e-9)
        imu = list(bag.messages("/imu/data"))
        assert [index for index, _, _ in imu] == [0, 1, 2]
        assert [t for _, t, _ in imu] == [ros_ns(T0 + dt) for dt in (0.0, 0.1, 0.2)]
        np.testing.assert_allclose([m.angular_velocity.z for _, _, m in imu], [0.1, 0.2, 0.3])
        (_, _, twist), _ = bag.messages("/vehicle/twist")
        assert twist.twist.linear.x == 7.5


def test_a_missing_topic_is_named_with_the_bags_topics(small_bag):
    with Bag(small_bag) as bag, pytest.raises(InputError) as missing:
        bag.msgtype("/gps/fix")
    assert str(missing.value) == (
        f"{small_bag}: no topic /gps/fix in the bag (topics: /imu/data, /vehicle/twist)"
    )
    with Bag(small_bag) as bag:
        error = bag.error("/imu/data", 4, "bad value")
    assert str(error) == f"{small_bag}: topic /imu/data, message 4: bad value"


def test_the_bag_kind_comes_from_the_paths_form(tmp_path):
    (tmp_path / "a.bag").write_bytes(b"x")
    (tmp_path / "b.db3").write_bytes(b"x")
    (tmp_path / "c.mcap").write_bytes(b"x")
    (tmp_path / "folder").mkdir()
    (tmp_path / "ros2").mkdir()
    (tmp_path / "ros2" / "metadata.yaml").write_text("x")
    (tmp_path / "d.txt").write_text("x")
    assert [bag_kind(tmp_path / n) for n in ("a.bag", "b.db3", "c.mcap", "ros2")] == [
        "ros1",
        "ros2",
        "ros2",
        "ros2",
    ]
    with pytest.raises(InputError, match=r"a folder without metadata\.yaml is not a ROS 2 bag"):
        bag_kind(tmp_path / "folder")
    with pytest.raises(InputError, match=r"unknown bag form '\.txt'"):
        bag_kind(tmp_path / "d.txt")
    with pytest.raises(InputError, match="no such bag"):
        bag_kind(tmp_path / "e.bag")


def test_a_file_that_is_no_bag_cannot_be_opened(tmp_path):
    path = tmp_path / "junk.bag"
    path.write_bytes(b"not a bag at all\n" * 10)
    with pytest.raises(InputError, match=r"junk\.bag: cannot open the ROS 1 bag: "), Bag(path):
        pass
