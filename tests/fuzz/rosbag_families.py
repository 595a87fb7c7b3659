"""Fuzz families of the ROS bag importer (``vo-doppler import rosbag``): a ROS 1 ``.bag`` and
a ROS 2 bag as one ``.mcap`` or ``.db3`` file, written with rosbags' writers from a slice of
the repository's sample sequence (3 images, 2 s of IMU and speed, 10 GNSS epochs with every
ephemeris and one GLONASS record added, the ground truth's fixes and poses), once with
gnss_comm and once with ublox_msgs raw GNSS (GLONASS strings in RxmSFRBX); and
``rosbag_can``: the slice's IMU and its wheel speeds as ``can_msgs/Frame`` frames of the
simulator's DBC (a ROS 1 ``.bag`` and a ROS 2 ``.mcap``), imported with that DBC.
``read`` imports the mutated bag into a temporary folder and reads that folder back
as ``run`` would, so whatever the importer accepts must also be a readable sequence. Registered
by ``families.py`` with::

    register_rosbag(register, Family, Seed, check_observations)
"""

from __future__ import annotations

import tempfile
from dataclasses import replace
from functools import cache
from pathlib import Path

import cantools
import numpy as np

from tests.conftest import REPO_ROOT
from tests.helpers.glonass_strings import example_at, tb_quarter_hour
from tests.helpers.rosbag_writer import SmallBag, frame_fields, ros_ns, write_sequence_bag
from vo_doppler.io.glonass_strings import GLONASS_NAMES
from vo_doppler.io.rosbag_import import RosbagOptions, import_rosbag
from vo_doppler.io.sequence import read_manifest, read_sequence
from vo_doppler.model.navigation import Navigation, NavRecords, concat_records
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.sim.can_bus import DBC_PATH, WHEEL_MESSAGE, WHEEL_SPEED_SIGNALS, WHEELS

SAMPLE = REPO_ROOT / "sample_sequences" / "urban_canyon_small"
SPAN_S = 2.0


@cache
def _slice():
    """The first seconds of the sample sequence."""
    seq = read_sequence(SAMPLE)
    start = float(seq.image_times[0])
    end = start + SPAN_S

    def series(s: SensorSeries | None) -> SensorSeries | None:
        if s is None:
            return None
        keep = (s.t >= start) & (s.t <= end)
        return SensorSeries(s.t[keep], s.value[keep])

    obs = seq.observations
    epochs = obs.epoch_time[(obs.epoch_time >= start) & (obs.epoch_time <= end)][:10]
    rows = np.isin(obs.time, epochs)
    observations = replace(
        obs.subset(rows), epoch_time=epochs, epoch_flag=np.zeros(epochs.size, np.int8)
    )
    truth = seq.truth
    keep = np.flatnonzero((truth.t >= start) & (truth.t <= end))
    return replace(
        seq,
        navigation=_with_glonass(seq.navigation, start),
        image_paths=seq.image_paths[:3],
        image_times=seq.image_times[:3],
        yaw_rate=series(seq.yaw_rate),
        wheel_speed=series(seq.wheel_speed),
        forward_acceleration=series(seq.forward_acceleration),
        observations=observations,
        truth=Trajectory(truth.t[keep], truth.positions[keep], truth.orientations[keep]),
    )


def _with_glonass(navigation: Navigation, start: float) -> Navigation:
    """The navigation with one GLONASS record (the test helper's, tb the quarter hour after
    ``start``): the sample has none, and the ublox seeds then carry GLONASS strings."""
    toc = tb_quarter_hour(start)
    params = example_at(toc) | {"channel": -3.0}
    record = NavRecords(
        np.array(["R"]),
        np.array([5], dtype=np.int16),
        np.array([toc]),
        {name: np.array([params.get(name, np.nan)]) for name in GLONASS_NAMES},
        np.zeros(1, dtype=np.int64),
    )
    return replace(navigation, glonass=concat_records(navigation.glonass, record))


def _bag_bytes(flavour: str, gnss: str, compressed: bool) -> bytes:
    with tempfile.TemporaryDirectory() as folder:
        target = Path(folder) / ("seed.bag" if flavour == "ros1" else "seed")
        write_sequence_bag(_slice(), target, flavour, gnss, compressed)
        if flavour == "ros1":
            return target.read_bytes()
        return next(p for p in target.iterdir() if p.suffix in (".mcap", ".db3")).read_bytes()


def _can_bag_bytes(flavour: str) -> bytes:
    """The slice's IMU and its wheel speeds (km/h, every wheel alike) as WHEEL_SPEEDS frames."""
    seq = _slice()
    database = cantools.database.load_file(DBC_PATH)
    message = database.get_message_by_name(WHEEL_MESSAGE)
    with tempfile.TemporaryDirectory() as folder:
        target = Path(folder) / ("seed.bag" if flavour == "ros1" else "seed")
        with SmallBag(target, flavour) as bag:
            bag.imu(seq.yaw_rate.t, seq.yaw_rate.value)
            for t, v in zip(seq.wheel_speed.t, seq.wheel_speed.value, strict=True):
                speeds = {f"WHEEL_SPEED_{w}": round(float(v) * 3.6, 2) for w in WHEELS}
                data = database.encode_message(WHEEL_MESSAGE, speeds)
                t_ns = ros_ns(float(t))
                bag.can_frame("/can/rx", t_ns, frame_fields(bag, t_ns, message.frame_id, data))
        if flavour == "ros1":
            return target.read_bytes()
        return next(p for p in target.iterdir() if p.suffix == ".mcap").read_bytes()


def read_bag(path: Path, can: bool = False):
    """Import the bag (its CAN topic's wheel speed decoded with the simulator's DBC when
    ``can``) and read the sequence back: (summary, sequence)."""
    origin = read_manifest(SAMPLE)["origin"]
    place = (origin["lat_deg"], origin["lon_deg"], origin["height_m"])
    if can:
        options = RosbagOptions(origin=place, dbc=DBC_PATH, wheel_speed=WHEEL_SPEED_SIGNALS)
    else:
        options = RosbagOptions(origin=place, ground_truth_topic="/ground_truth")
    with tempfile.TemporaryDirectory() as folder:
        summary = import_rosbag(path, Path(folder) / "seq", options)
        return summary, read_sequence(Path(folder) / "seq")


def read_can_bag(path: Path):
    """:func:`read_bag` of a ``rosbag_can`` bag."""
    return read_bag(path, can=True)


def make_check(check_observations):
    def check(result, path: Path) -> list[str]:
        summary, seq = result
        bad = []
        for name in ("yaw_rate", "wheel_speed", "forward_acceleration"):
            series = getattr(seq, name)
            if series is not None and len(series) and not np.all(np.diff(series.t) > 0):
                bad.append(f"{name}: times not increasing")
        if seq.image_times.size and not np.all(np.diff(seq.image_times) > 0):
            bad.append("image times not increasing")
        if seq.image_times.size != len(seq.image_paths):
            bad.append(f"{seq.image_times.size} times for {len(seq.image_paths)} images")
        if seq.observations is not None:
            bad += check_observations(seq.observations, path)
        if summary.images != len(seq.image_paths):
            bad.append(
                f"summary says {summary.images} images, the folder has {len(seq.image_paths)}"
            )
        return bad

    return check


SEEDS = {  # family → (seed file, bag flavour, GNSS interface, compressed images)
    "rosbag1": (
        ("gnss_comm.bag", "ros1", "gnss_comm", False),
        ("ublox.bag", "ros1", "ublox", True),
    ),
    "rosbag2": (
        ("gnss_comm.mcap", "mcap", "gnss_comm", True),
        ("ublox.db3", "sqlite3", "ublox", False),
    ),
}


def register_rosbag(register, family_cls, seed_cls, check_observations) -> None:
    """The ROS 1 and ROS 2 families (the sample sequence is in the repository)."""
    check = make_check(check_observations)

    def seed(name: str, flavour: str, gnss: str, compressed: bool):
        def load() -> bytes:
            return _bag_bytes(flavour, gnss, compressed)

        return seed_cls(name, load, suffix=Path(name).suffix)

    for family, seeds in SEEDS.items():
        register(family_cls(family, lambda seeds=seeds: [seed(*s) for s in seeds], read_bag, check))

    def can_seeds():
        return [
            seed_cls(
                name, lambda flavour=flavour: _can_bag_bytes(flavour), suffix=Path(name).suffix
            )
            for name, flavour in (("can.bag", "ros1"), ("can.mcap", "mcap"))
        ]

    register(family_cls("rosbag_can", can_seeds, read_can_bag, check))
