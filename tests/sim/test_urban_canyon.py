"""Simulator end to end: the sequence folder, its manifest, determinism per seed, the CLI."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from vo_doppler.cli import main
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.can import read_can_motion
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.trajectory import read_tum
from vo_doppler.sim.urban_canyon import (
    CityConfig,
    UrbanCanyonConfig,
    camera_frame_count,
    simulate_urban_canyon,
    too_few_frames,
)

SMALL = {"duration_s": 6.0, "fps": 5.0, "image_size_px": (160, 90)}


def _files(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()
    }


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    out = tmp_path_factory.mktemp("seq")
    config = UrbanCanyonConfig(
        seed=4, calib_focal_error=-0.01, calib_principal_offset_px=(3.0, -2.0), **SMALL
    )
    return out, simulate_urban_canyon(out, config)


@pytest.mark.slow
def test_manifest_paths_and_time_offsets(sequence):
    out, sim = sequence
    manifest = yaml.safe_load((out / "sequence.yaml").read_text())
    assert manifest["format"] == "vo-doppler-sequence/1"
    for path in (
        manifest["camera"]["times"],
        manifest["camera"]["calib"],
        manifest["gnss"]["obs"],
        *manifest["gnss"]["nav"],
        manifest["can"]["log"],
        manifest["can"]["dbc"],
        manifest["ground_truth"]["trajectory"],
    ):
        assert (out / path).is_file(), path
    times = np.loadtxt(out / manifest["camera"]["times"])
    images = sorted((out / manifest["camera"]["images"]).glob("*.png"))
    assert len(images) == len(times) == 30
    start = manifest["start_gps_s"]
    assert times[0] + manifest["camera"]["time_offset_s"] == pytest.approx(start + 0.02)
    camera = read_camera(out / manifest["camera"]["calib"])
    assert (camera.width, camera.height) == (160, 90)
    true_camera = manifest["truth"]["camera"]
    assert camera.fx == pytest.approx(true_camera["fx"] * 0.99)
    assert camera.cx - true_camera["cx"] == pytest.approx(3.0)
    assert camera.cy - true_camera["cy"] == pytest.approx(-2.0)
    obs = read_obs(out / manifest["gnss"]["obs"])
    assert obs.epoch_time[0] + manifest["gnss"]["time_offset_s"] == pytest.approx(start)
    assert obs.header.interval == pytest.approx(0.05)
    can = manifest["can"]
    motion = read_can_motion(
        out / can["log"],
        out / can["dbc"],
        can["yaw_rate"],
        can["wheel_speed"],
        can["yaw_rate_sign"],
        can["time_offset_s"],
        can["time_offset_s"],
    )
    assert start <= motion.speed.t[0] < start + 0.02
    truth = read_tum(out / manifest["ground_truth"]["trajectory"])
    assert truth.t[0] == pytest.approx(start)
    speed_truth = np.interp(
        motion.speed.t, truth.t[:-1], np.hypot(*np.diff(truth.positions[:, :2], axis=0).T) / 0.01
    )
    moving = speed_truth > 2.0
    ratio = np.median(motion.speed.value[moving] / speed_truth[moving])
    assert ratio == pytest.approx(1.0 + manifest["truth"]["wheel_scale_error"], abs=0.005)
    origin = manifest["origin"]
    assert np.degrees(sim.frame.lat_rad) == pytest.approx(origin["lat_deg"])
    assert manifest["stats"]["epochs"] == 121


@pytest.mark.slow
def test_same_seed_same_files_other_seed_differs(sequence, tmp_path):
    out, sim = sequence
    simulate_urban_canyon(tmp_path / "again", sim.config)
    first, second = _files(out), _files(tmp_path / "again")
    assert first.keys() == second.keys()
    assert [k for k in first if first[k] != second[k]] == ["sequence.yaml"]
    manifests = [yaml.safe_load(files["sequence.yaml"]) for files in (first, second)]
    assert manifests[0].pop("name") != manifests[1].pop("name")  # the folder names
    assert manifests[0] == manifests[1]
    simulate_urban_canyon(tmp_path / "other", UrbanCanyonConfig(seed=5, render=False, **SMALL))
    other = _files(tmp_path / "other")
    assert other["gnss/rover.obs"] != first["gnss/rover.obs"]
    assert other["can/vehicle.log"] != first["can/vehicle.log"]


@pytest.mark.slow
def test_cli_writes_a_sequence(tmp_path, capsys):
    out = tmp_path / "cli"
    code = main(
        [
            "simulate",
            "--duration",
            "3",
            "--seed",
            "2",
            "--no-images",
            "--street-width",
            "18",
            "--heights",
            "10,20",
            "-o",
            str(out),
        ]
    )
    assert code == 0
    manifest = yaml.safe_load((out / "sequence.yaml").read_text())
    assert "camera" not in manifest  # no images rendered: a recording without a camera
    assert manifest["city"]["street_width_m"] == 18.0
    assert manifest["city"]["height_range_m"] == [10.0, 20.0]
    assert manifest["command"].startswith("vo-doppler simulate --scenario urban-canyon")
    assert "--street-width 18 --heights 10,20" in manifest["command"]
    assert "satellites" in capsys.readouterr().out


def test_cli_rejects_unknown_system_as_a_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["simulate", "--duration", "3", "--systems", "GR", "-o", str(tmp_path / "x")])
    assert stop.value.code == 2
    assert "systems are letters of GE, got 'GR'" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


@pytest.mark.parametrize(
    ("fps", "duration", "message"),
    [
        (
            "0.01",
            "8",
            "--fps 0.01 with --duration 8 gives 1 camera frame (the first 0.02 s into the "
            "drive), and visual odometry needs at least 2: give --duration ≥ 100.02 s or "
            "--fps ≥ 0.12532 Hz",
        ),
        ("15", "0.01", "--fps 15 with --duration 0.01 gives 0 camera frames"),
    ],
)
def test_cli_refuses_a_drive_of_fewer_than_two_frames(fps, duration, message, tmp_path, capsys):
    """The QA case: --fps 0.01 --duration 8 wrote a one-frame sequence no VO can use."""
    argv = ["simulate", "--fps", fps, "--duration", duration, "--no-images"]
    with pytest.raises(SystemExit) as stop:
        main([*argv, "-o", str(tmp_path / "x")])
    assert stop.value.code == 2
    assert f"vo-doppler simulate: error: {message}" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_the_least_fps_and_duration_named_give_two_frames(tmp_path):
    problem = too_few_frames(8.0, 0.01)
    assert problem.endswith("give duration_s ≥ 100.02 s or fps ≥ 0.12532 Hz")
    assert camera_frame_count(100.02, 0.01) == 2 and camera_frame_count(8.0, 0.12532) == 2
    assert camera_frame_count(100.01, 0.01) == 1 and camera_frame_count(8.0, 0.1253) == 1
    assert too_few_frames(8.0, 0.12532) is None
    with pytest.raises(ValueError, match=r"fps 0\.01 with duration_s 8 gives 1 camera frame"):
        simulate_urban_canyon(tmp_path / "x", UrbanCanyonConfig(duration_s=8.0, fps=0.01))
    assert not (tmp_path / "x").exists()


@pytest.mark.slow
def test_route_has_turns_stops_and_a_speed_limit(tmp_path):
    config = UrbanCanyonConfig(
        duration_s=40.0,
        seed=3,
        render=False,
        initial_speed_mps=8.0,
        stops_per_lap=2,
        city=CityConfig(corner_streets=((1, 1), (2, 2))),
    )
    sim = simulate_urban_canyon(tmp_path, config)
    truth = read_tum(tmp_path / "ground_truth.tum")
    step = np.linalg.norm(np.diff(truth.positions, axis=0), axis=1)
    speed = step / np.diff(truth.t)
    assert speed.max() <= config.max_speed_mps + 1e-6
    first_stop = sim.vehicle.stops_m[0]
    at_stop = np.abs(np.concatenate([[0.0], np.cumsum(step)]) - first_stop) < 0.01
    standing = np.sum(at_stop) / 100.0
    assert standing == pytest.approx(config.stop_duration_s, abs=0.15)  # + creeping in and out
    assert sim.stats.stops >= 1 and sim.stats.turns >= 2
    assert sim.stats.path_length_m == pytest.approx(step.sum())


def _manifest(out: Path, *options: str) -> dict:
    assert main(["simulate", "--duration", "3", "--no-images", *options, "-o", str(out)]) == 0
    return yaml.safe_load((out / "sequence.yaml").read_text())


@pytest.mark.slow
def test_cli_effects_switch_off_one_by_one_and_clean_restores_the_old_camera(tmp_path):
    default = _manifest(tmp_path / "default")
    effects = default["truth"]["camera"]["effects"]
    assert effects["readout_s"] == pytest.approx(0.025)
    assert effects["exposure_s"] == pytest.approx(0.004)
    assert effects["distortion"][0] == pytest.approx(-0.30)
    assert default["truth"]["camera"]["focal_error"] == pytest.approx(-0.005)
    assert default["truth"]["traffic"]["vehicles_per_km"] > 0
    assert default["city"]["window_facades"] > 0 and default["city"]["ground_contrast"] < 1
    switched = _manifest(
        tmp_path / "switched",
        "--no-distortion",
        "--no-rolling-shutter",
        "--no-motion-blur",
        "--no-sensor-noise",
        "--no-exposure-changes",
        "--no-traffic",
        "--no-repetitive-facades",
        "--no-asphalt",
    )
    effects = switched["truth"]["camera"]["effects"]
    assert effects["distortion"] == [0.0] * 5 and effects["distortion_error"] == [0.0] * 5
    assert effects["readout_s"] == 0.0 and effects["exposure_s"] == 0.0
    assert effects["noise"] is False
    assert effects["sensor"]["light_variation"] == 0.0 and effects["sensor"]["exposure_rate"] == 0
    assert switched["truth"]["traffic"]["vehicles_per_km"] == 0.0
    assert switched["city"]["window_facades"] == 0 and switched["city"]["ground_contrast"] == 1
    assert "--no-traffic" in switched["command"] and "--no-asphalt" in switched["command"]
    clean = _manifest(tmp_path / "clean", "--clean")
    assert clean["truth"]["camera"]["effects"] is None
    assert clean["truth"]["camera"]["focal_error"] == 0.0
    assert clean["truth"]["camera"]["principal_offset_px"] == [0.0, 0.0]
    assert clean["city"]["window_facades"] == 0 and clean["city"]["ground_contrast"] == 1
    assert "--clean" in clean["command"]


@pytest.mark.slow
def test_cli_receives_reflections_unless_told_not_to(tmp_path):
    default = _manifest(tmp_path / "default")
    assert default["truth"]["gnss"]["nlos"] is True
    assert "--nlos" in default["command"].split()
    direct = _manifest(tmp_path / "direct", "--no-nlos")
    assert direct["truth"]["gnss"]["nlos"] is False
    assert "--no-nlos" in direct["command"].split()


@pytest.mark.slow
def test_cli_writes_only_into_a_new_empty_or_earlier_simulated_folder(tmp_path, capsys):
    """A second simulation into its own folder is fine; a folder with someone else's files is
    refused before any work, untouched."""
    out = tmp_path / "sim"
    _manifest(out)
    _manifest(out)
    other = tmp_path / "other"
    other.mkdir()
    (other / "sequence.yaml").write_text("a recording of someone else's")
    assert main(["simulate", "--duration", "3", "--no-images", "-o", str(other)]) == 1
    assert "not written by 'vo-doppler simulate'" in capsys.readouterr().err
    assert [p.name for p in other.iterdir()] == ["sequence.yaml"]


@pytest.mark.slow
def test_a_shorter_simulation_into_its_own_folder_leaves_no_stale_frames(tmp_path):
    """Frames of an earlier, longer simulation (or of its other image format) used to stay, and
    the new sequence's times no longer matched its images."""
    simulate_urban_canyon(tmp_path, UrbanCanyonConfig(seed=1, **SMALL))
    assert len(list((tmp_path / "image_0").iterdir())) == 30
    shorter = {**SMALL, "duration_s": 2.0}
    simulate_urban_canyon(tmp_path, UrbanCanyonConfig(seed=1, image_format="jpg", **shorter))
    frames = sorted(p.name for p in (tmp_path / "image_0").iterdir())
    times = (tmp_path / "times.txt").read_text().split()
    assert frames == [f"{k:06d}.jpg" for k in range(len(times))] and len(times) == 10
