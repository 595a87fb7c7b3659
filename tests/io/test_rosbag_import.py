"""ROS bag import: a simulated drive written to ROS 1, ROS 2 sqlite3 and ROS 2 MCAP bags
(tests/helpers/rosbag_writer.py, rosbags' writers) and imported back, every field compared;
damaged bags give an InputError naming the bag, topic and message index."""

from __future__ import annotations

import shutil
from pathlib import Path

import cv2
import numpy as np
import pytest
import yaml

from tests.helpers.batch import tiny_drive
from tests.helpers.galileo_inav import quantised as galileo_quantised
from tests.helpers.lnav import quantised
from tests.helpers.rosbag_writer import GNSS_LATENCY_S, lnav_dict, write_bag
from vo_doppler.cli import main
from vo_doppler.errors import InputError
from vo_doppler.eval.pipelines import evaluate_pipelines
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.rosbag_bag import Bag
from vo_doppler.io.rosbag_gnss import read_gnss_comm
from vo_doppler.io.rosbag_import import (
    RosbagOptions,
    forward_axis,
    import_rosbag,
    list_topics,
    yaw_axis,
)
from vo_doppler.io.rosbag_types import typestore
from vo_doppler.io.sequence import read_manifest, read_sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.run import run_sequence

pytestmark = pytest.mark.xdist_group("tiny_drives")

BAGS = {  # name → (flavour, GNSS interface, compressed images)
    "ros1": ("ros1", "gnss_comm", False),
    "sqlite3": ("sqlite3", "gnss_comm", True),
    "mcap": ("mcap", "gnss_comm", False),
    "ublox_ros1": ("ros1", "ublox", False),
    "ublox_mcap": ("mcap", "ublox", True),
}


@pytest.fixture(scope="session")
def drive(tmp_path_factory) -> Path:
    return tiny_drive(tmp_path_factory, 1)  # shared with the batch tests


@pytest.fixture(scope="session")
def origin(drive) -> tuple[float, float, float]:
    o = read_manifest(drive)["origin"]
    return o["lat_deg"], o["lon_deg"], o["height_m"]


@pytest.fixture(scope="session")
def imported(drive, origin, tmp_path_factory) -> dict[str, tuple[Path, Path, object]]:
    """Each bag flavour written from the drive and imported: name → (sequence, bag, summary)."""
    base = tmp_path_factory.mktemp("rosbags")
    out = {}
    for name, (flavour, gnss, compressed) in BAGS.items():
        bag = base / (f"{name}.bag" if flavour == "ros1" else name)
        write_bag(drive, bag, flavour, gnss, compressed)
        options = RosbagOptions(origin=origin, ground_truth_topic="/ground_truth")
        out[name] = (base / f"{name}_seq", bag, import_rosbag(bag, base / f"{name}_seq", options))
    return out


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ros1", "sqlite3", "mcap"])
def test_gnss_comm_observations_and_ephemerides_identical(drive, imported, name):
    folder = imported[name][0]
    original, back = read_obs(drive / "gnss/rover.obs"), read_obs(folder / "gnss/rover.obs")
    assert back.codes == original.codes == ("C1C", "D1C", "S1C")
    for column in ("time", "system", "prn", "code", "value", "ssi"):
        np.testing.assert_array_equal(getattr(back, column), getattr(original, column))
    nav, nav_back = read_nav(drive / "gnss/brdc.nav"), read_nav(folder / "gnss/brdc.nav")
    np.testing.assert_array_equal(nav_back.kepler.prn, nav.kepler.prn)
    np.testing.assert_array_equal(nav_back.kepler.toc, nav.kepler.toc)
    for key, values in nav.kepler.params.items():
        np.testing.assert_array_equal(nav_back.kepler[key], values, err_msg=key)
    np.testing.assert_array_equal(nav_back.klobuchar, nav.klobuchar)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["ros1", "mcap", "ublox_ros1"])
def test_raw_images_bitwise(drive, imported, name):
    folder = imported[name][0]
    original = sorted((drive / "image_0").iterdir())
    back = sorted((folder / "image_0").iterdir())
    assert len(back) == len(original) > 10
    for a, b in zip(original[::7], back[::7], strict=True):
        np.testing.assert_array_equal(
            cv2.imread(str(b), cv2.IMREAD_UNCHANGED), cv2.imread(str(a), cv2.IMREAD_GRAYSCALE)
        )


@pytest.mark.slow
@pytest.mark.parametrize("name", ["sqlite3", "ublox_mcap"])
def test_compressed_images_as_sent_and_decodable(drive, imported, name):
    original = sorted((drive / "image_0").iterdir())
    back = sorted((imported[name][0] / "image_0").iterdir())
    assert [p.suffix for p in back] == [p.suffix for p in original]
    for a, b in zip(original, back, strict=True):
        assert b.read_bytes() == a.read_bytes()
    assert cv2.imread(str(back[-1])) is not None


@pytest.mark.slow
@pytest.mark.parametrize("name", list(BAGS))
def test_vehicle_signals_camera_and_truth(drive, imported, name):
    seq, back = read_sequence(drive), read_sequence(imported[name][0])
    pairs = [(seq.yaw_rate, back.yaw_rate), (seq.wheel_speed, back.wheel_speed)]
    for a, b in pairs:
        np.testing.assert_allclose(b.t, a.t, rtol=0, atol=1e-6)
        np.testing.assert_array_equal(b.value, a.value)
    accel = seq.forward_acceleration
    if accel is None:  # the IMU's x then reads 0: no axis follows the speed, none written
        assert back.forward_acceleration is None
    else:
        np.testing.assert_array_equal(
            back.forward_acceleration.value, np.interp(seq.yaw_rate.t, accel.t, accel.value)
        )
    np.testing.assert_allclose(back.image_times, seq.image_times, rtol=0, atol=1e-6)
    np.testing.assert_allclose(back.truth.t, seq.truth.t, rtol=0, atol=1e-6)
    np.testing.assert_array_equal(back.truth.positions, seq.truth.positions)
    a, b = seq.camera, back.camera
    assert (b.fx, b.fy, b.cx, b.cy, b.width, b.height) == (
        a.fx,
        a.fy,
        a.cx,
        a.cy,
        a.width,
        a.height,
    )
    np.testing.assert_array_equal(b.distortion, a.distortion)
    np.testing.assert_allclose(b.T_vehicle_camera, a.T_vehicle_camera, atol=1e-12)
    np.testing.assert_allclose(back.antenna_lever_arm_m, seq.antenna_lever_arm_m, atol=1e-12)


@pytest.mark.slow
def test_manifest_states_times_and_axes(drive, imported):
    manifest = read_manifest(imported["ros1"][0])
    has_acceleration = read_sequence(drive).forward_acceleration is not None
    record = manifest["rosbag"]
    assert manifest["camera"]["time_offset_s"] == manifest["vehicle"]["time_offset_s"] == 0.0
    assert record["gps_minus_ros_s"] == -315964782.0  # Unix → GPS, 18 leap seconds
    assert "Unix time (UTC)" in record["clock"]
    assert record["times"]["/imu/data"] == "header stamp"
    assert record["imu_yaw_axis"].startswith("z: estimated")
    assert record["imu_forward_axis"].startswith("x: estimated" if has_acceleration else "none")
    assert record["camera_extrinsic"] == "tf: base_link → camera"


def _rows(obs, code: str) -> dict[tuple[float, str], float]:
    rows = obs.select(code=code)
    return dict(zip(zip(rows.time, rows.satellites(), strict=True), rows.value, strict=True))


@pytest.mark.slow
def test_ublox_observations_at_message_precision(drive, imported):
    """RxmRAWX carries the Doppler as float32 and C/N0 as whole dB-Hz; GPS and Galileo
    ephemerides come back as LNAV subframes and I/NAV pages carry them."""
    original = read_obs(drive / "gnss/rover.obs")
    for name in ("ublox_ros1", "ublox_mcap"):
        back = read_obs(imported[name][0] / "gnss/rover.obs")
        np.testing.assert_array_equal(back.epoch_time, original.epoch_time)  # empty ones too
        for code, expected in (
            ("C1C", lambda v: v),
            ("D1C", lambda v: round(float(np.float32(v)), 3)),
            ("S1C", round),
        ):
            want = {key: expected(v) for key, v in _rows(original, code).items()}
            assert _rows(back, code) == want, code
        nav = read_nav(drive / "gnss/brdc.nav").kepler
        nav_back = read_nav(imported[name][0] / "gnss/brdc.nav").kepler
        gps, galileo = np.flatnonzero(nav.system == "G"), np.flatnonzero(nav.system == "E")
        assert len(nav_back) == gps.size + galileo.size and gps.size > 0 and galileo.size > 0
        assert nav_back.system.tolist() == ["G"] * gps.size + ["E"] * galileo.size
        for k, row in zip(gps, range(gps.size), strict=True):
            want = quantised(lnav_dict(nav, k))
            for key in ("sqrt_a", "e", "m0", "omega0", "af0", "toe_sow"):
                assert nav_back[key][row] == pytest.approx(want[key], rel=1e-12, abs=1e-20)
        for k, row in zip(galileo, range(gps.size, len(nav_back)), strict=True):
            want = galileo_quantised({key: float(v[k]) for key, v in nav.params.items()})
            assert (nav_back.prn[row], nav_back.toc[row]) == (nav.prn[k], nav.toc[k])
            for key in ("sqrt_a", "e", "m0", "omega0", "af0", "toe_sow", "tgd", "iodc"):
                assert nav_back[key][row] == pytest.approx(want[key], rel=1e-12, abs=1e-20)
        assert (imported[name][0] / "gnss/doppler_sigma.csv").is_file()


@pytest.mark.slow
def test_run_gives_the_same_error_per_100m(drive, imported):
    """Acceptance: `run` on the imported sequence within 1 % of the original per pipeline."""
    errors = {}
    for label, folder in (("original", drive), ("imported", imported["ros1"][0])):
        seq = read_sequence(folder)
        result = run_sequence(seq)
        evaluated = evaluate_pipelines(
            result.trajectories, result.heading, result.tc_usable, seq.truth
        )[0]
        errors[label] = {k: v.error_per_100m_m for k, v in evaluated.items()}
    assert set(errors["imported"]) == set(errors["original"]) and len(errors["original"]) >= 4
    for pipeline, value in errors["original"].items():
        assert errors["imported"][pipeline] == pytest.approx(value, rel=0.01), pipeline


@pytest.mark.slow
def test_list_topics_and_clock_from_gnss(imported, origin, tmp_path):
    bag = imported["ros1"][1]
    lines = list_topics(bag)
    assert any("/gnss/meas" in line and line.rstrip().endswith("gnss") for line in lines)
    assert any("/ground_truth" in line and line.rstrip().endswith("-") for line in lines)
    options = RosbagOptions(origin=origin, clock="gnss")
    summary = import_rosbag(bag, tmp_path / "seq", options)
    assert summary.gps_minus_ros_s == pytest.approx(-315964782.0 - GNSS_LATENCY_S, abs=1e-5)
    assert "estimated from" in summary.clock


@pytest.mark.slow
def test_cli_lists_topics_and_imports(imported, tmp_path, capsys):
    bag = imported["mcap"][1]
    assert main(["import", "rosbag", str(bag), "--list-topics"]) == 0
    listing = capsys.readouterr().out
    assert "/gnss/meas" in listing and "GnssMeasMsg" in listing
    args = ["import", "rosbag", str(bag), "-o", str(tmp_path / "s"), "--imu-yaw-axis", "-z"]
    code = main(args)
    assert code == 0
    yaw = read_sequence(tmp_path / "s").yaw_rate
    assert np.allclose(yaw.value, -read_sequence(imported["mcap"][0]).yaw_rate.value)
    args = ["import", "rosbag", str(bag), "-o", str(tmp_path / "r"), "--stamps", "receive"]
    assert main(args) == 0
    assert read_manifest(tmp_path / "r")["rosbag"]["times"]["/imu/data"] == "receive time"
    np.testing.assert_array_equal(read_sequence(tmp_path / "r").yaw_rate.t, yaw.t)
    assert main([*args[:4], str(tmp_path / "x"), "--imu-topic", "/gnss/meas"]) == 1
    assert (
        f"{bag}: topic /gnss/meas is gnss_comm/msg/GnssMeasMsg, not one of the imu types"
        in capsys.readouterr().err
    )


def test_axis_estimates():
    rng = np.random.default_rng(3)
    t = np.arange(500) * 0.01
    gyro = rng.normal(0, 0.1, (500, 3))
    accel = np.zeros((500, 3))
    accel[:, 1] = -9.81  # y points down
    speed = SensorSeries(t, 5 + np.sin(t))
    accel[:, 0] = -np.cos(t) + rng.normal(0, 0.05, 500)  # -x points forward
    assert yaw_axis(gyro, accel, "auto")[0] == "-y"
    assert forward_axis(t, accel, "-y", speed, "auto")[0] == "-x"
    assert forward_axis(t, accel, "-y", None, "auto")[0] == "none"
    assert yaw_axis(gyro * [1, 1, 5], np.full((500, 3), np.nan), "auto")[0] == "z"


def _rewrite(source: Path, target: Path, edit, topics: set[str] | None = None) -> Path:
    """A ROS 1 copy of ``source`` (of ``topics`` only, when given) with ``edit(topic,
    message)`` applied to each message."""
    from rosbags.rosbag1 import Reader, Writer

    store = typestore(False)
    with Reader(source) as reader, Writer(target) as writer:
        kept = [c for c in reader.connections if topics is None or c.topic in topics]
        connections = {}
        for connection in kept:
            connections[connection.id] = writer.add_connection(
                connection.topic, connection.msgtype, typestore=store
            )
        for connection, t, raw in reader.messages(connections=kept):
            message = store.deserialize_ros1(raw, connection.msgtype)
            message = edit(connection.topic, message)
            raw = store.serialize_ros1(message, connection.msgtype)
            writer.write(connections[connection.id], t, raw)
    return target


@pytest.mark.slow
def test_a_bag_without_camera_or_raw_gnss(drive, imported, tmp_path):
    """IMU, speed and fixes only: the origin from the first fix, no camera, no GNSS section;
    run reads the folder."""
    bag = _rewrite(
        imported["ros1"][1],
        tmp_path / "few.bag",
        lambda t, m: m,
        {"/imu/data", "/vehicle/twist", "/fix"},
    )
    summary = import_rosbag(bag, tmp_path / "seq")
    seq = read_sequence(tmp_path / "seq")
    assert not seq.has_camera and not seq.has_gnss and summary.images == 0
    first_fix = read_manifest(tmp_path / "seq")["origin"]
    assert first_fix["lat_deg"] == pytest.approx(
        read_manifest(drive)["origin"]["lat_deg"], abs=1e-3
    )
    assert (tmp_path / "seq" / "gnss" / "fixes.csv").is_file()
    np.testing.assert_array_equal(seq.yaw_rate.value, read_sequence(drive).yaw_rate.value)


@pytest.mark.slow
def test_bad_bags_name_bag_topic_and_index(imported, origin, tmp_path, capsys):
    bag = imported["ros1"][1]
    options = RosbagOptions(origin=origin)
    count = {"n": 0}

    def short_psr(topic, message):
        if topic == "/gnss/meas":
            count["n"] += 1
            if count["n"] == 4:
                message.meas[0].psr = np.zeros(3)
        return message

    bad = _rewrite(bag, tmp_path / "psr.bag", short_psr)
    with pytest.raises(InputError, match=r"psr\.bag: topic /gnss/meas, message 3: .*psr"):
        import_rosbag(bad, tmp_path / "a", options)

    def bad_step(topic, message):
        if topic == "/camera/image_raw":
            message.step = 3
        return message

    bad = _rewrite(bag, tmp_path / "step.bag", bad_step)
    with pytest.raises(InputError, match=r"topic /camera/image_raw, message 0: .*step 3"):
        import_rosbag(bad, tmp_path / "b", options)
    cut = tmp_path / "cut.bag"
    cut.write_bytes(bag.read_bytes()[: bag.stat().st_size // 2])
    assert main(["import", "rosbag", str(cut), "-o", str(tmp_path / "c")]) == 1
    assert "cut.bag" in capsys.readouterr().err
    folder = tmp_path / "ros2_without_metadata"
    shutil.copytree(imported["sqlite3"][1], folder)
    (folder / "metadata.yaml").unlink()
    with pytest.raises(InputError, match=r"without metadata\.yaml"):
        import_rosbag(folder, tmp_path / "d", options)
    assert yaml.safe_load((imported["ros1"][0] / "sequence.yaml").read_text())["format"]


def test_ros2_bag_without_definitions_uses_the_project_types(tmp_path):
    """A bag that carries no message definitions (rosbag2 before Iron) is read with the
    project's gnss_comm definitions."""
    from rosbags.rosbag2 import Writer

    store = typestore(True)
    name = "gnss_comm/msg/GnssMeasMsg"
    types = store.types
    obs = types["gnss_comm/msg/GnssObsMsg"](
        time=types["gnss_comm/msg/GnssTimeMsg"](week=2358, tow=439200.0),
        sat=60 + 2,
        freqs=np.array([1575.42e6]),
        CN0=np.array([45.0]),
        LLI=np.zeros(1, np.uint8),
        code=np.ones(1, np.uint8),
        psr=np.array([2.2e7]),
        psr_std=np.zeros(1),
        cp=np.zeros(1),
        cp_std=np.zeros(1),
        dopp=np.array([-850.25]),
        dopp_std=np.array([0.1]),
        status=np.ones(1, np.uint8),
    )
    with Writer(tmp_path / "old", version=8) as writer:
        connection = writer.add_connection("/gnss/meas", name, msgdef="", rihs01="RIHS01_0")
        writer.write(connection, 1, store.serialize_cdr(types[name](meas=[obs]), name))
    with Bag(tmp_path / "old") as bag:
        gnss = read_gnss_comm(bag, "/gnss/meas", [], None)
    obs = gnss.observations
    rows = {obs.codes[c]: v for c, v in zip(obs.code, obs.value, strict=True)}
    assert rows == {"C1C": 2.2e7, "D1C": -850.25, "S1C": 45.0}
    assert obs.satellites().tolist() == ["E03"] * 3
    assert gnss.doppler_sigma.sigma_mps[0] == pytest.approx(0.1 * 299792458.0 / 1575.42e6)


def test_a_repeated_measurement_keeps_one_sigma():
    """A measurement repeated in the bag (the observations keep the first) leaves one σ row,
    or doppler_sigma.csv would be refused (make fuzz: rosbag1 case 476, swap_lines)."""
    from vo_doppler.io.rosbag_gnss import _sigma

    sigma = _sigma([(1.0, "G01", "D1C", 0.1), (1.0, "G01", "D1C", 0.2), (1.2, "G01", "D1C", 0.3)])
    assert sigma.sigma_mps.tolist() == [0.1, 0.3]
