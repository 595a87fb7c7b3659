"""``vo-doppler run`` end to end on a short generated urban-canyon drive."""

from __future__ import annotations

import base64
import html
import io
import json
import re
from dataclasses import replace

import numpy as np
import pytest
from matplotlib.image import imread
from scipy.spatial.transform import Rotation

from tests.helpers.velocity import velocity_solution
from vo_doppler.cli import main
from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame, wrap_angle
from vo_doppler.io.heading_csv import COLUMNS as HEADING_COLUMNS
from vo_doppler.io.heading_csv import OPTIONAL_COLUMNS as HEADING_OPTIONAL
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.sequence import read_sequence
from vo_doppler.io.trajectory import read_tum
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report.provenance import config_rows
from vo_doppler.report.trajectory_map import lon_lat
from vo_doppler.run import (
    PLACEMENT_VERTICAL_SIGMA_M,
    AntennaTrack,
    RunConfig,
    antenna_track,
    initial_yaw_offset,
    level_with_yaw,
    run_sequence,
)
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    folder = tmp_path_factory.mktemp("canyon") / "seq"
    config = UrbanCanyonConfig(duration_s=25.0, seed=4, image_size_px=(480, 270))
    simulate_urban_canyon(folder, config)
    return folder


@pytest.fixture(scope="module")
def run_output(sequence, tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    assert main(["run", str(sequence), "-o", str(out)]) == 0
    return out


CAMERA_TRAJECTORIES = {
    "vo": "trajectory_vo.tum",
    "vo_gps_conv": "trajectory_vo_gps_conv.tum",
    "vo_gps_tc": "trajectory_corrected.tum",
}
DR_TRAJECTORIES = {
    "dr": "trajectory_dr.tum",
    "dr_gps_conv": "trajectory_dr_gps_conv.tum",
    "dr_gps_tc": "trajectory_dr_gps_tc.tum",
}
FIGURES = ("trajectories.png", "heading.png", "error_per_100m.png", "heading_error.png")


@pytest.mark.slow
def test_run_writes_every_output(sequence, run_output):
    recording = read_sequence(sequence)
    written = sorted(p.name for p in run_output.iterdir() if not p.name.startswith("."))
    expected = [*CAMERA_TRAJECTORIES.values(), *DR_TRAJECTORIES.values(), *FIGURES]
    expected += ["heading.csv", "report.html", "summary.json", "trajectories.geojson"]
    assert written == sorted(expected)
    manifest = json.loads((run_output / ".vo-doppler-output.json").read_text())
    assert manifest["command"] == "run" and manifest["entries"] == written
    summary = json.loads((run_output / "summary.json").read_text())

    # one pose per image, at the image times; one per vehicle-signal epoch for dead reckoning
    trajectories = {n: read_tum(run_output / f) for n, f in CAMERA_TRAJECTORIES.items()}
    for trajectory in trajectories.values():
        np.testing.assert_allclose(trajectory.t, recording.image_times, rtol=0, atol=1e-6)
    assert summary["vo_frames"] == len(recording.image_paths) == 375
    dead_reckoning = {n: read_tum(run_output / f) for n, f in DR_TRAJECTORIES.items()}
    dr_times = dead_reckoning["dr"].t
    assert len(dr_times) == summary["vehicle_signal_epochs"] > 0.9 * 20 * 25  # 20 Hz for 25 s
    assert np.all(np.diff(dr_times) > 0)
    begin, end = recording.vehicle_span
    assert begin <= dr_times[0] and dr_times[-1] <= end
    trajectories |= dead_reckoning
    truth = recording.truth
    for name, trajectory in trajectories.items():
        first = trajectories["vo" if name in CAMERA_TRAJECTORIES else "dr"]
        np.testing.assert_array_equal(trajectory.t, first.t)
        assert np.all(np.isfinite(trajectory.positions)), name
        # every pose within 3 m of the truth horizontally (0.8-1.2 m at most at 356e1ed)
        truth_xy = [np.interp(trajectory.t, truth.t, truth.positions[:, i]) for i in (0, 1)]
        error = np.hypot(*(trajectory.positions[:, :2] - np.column_stack(truth_xy)).T)
        assert error.max() < 3.0, name
        # the evaluation's truth path over the same span, as long as the estimate's within 2 %
        evaluation = summary["evaluation"][name]
        assert trajectory.path_length == pytest.approx(evaluation["path_length_m"], rel=0.02)
        assert evaluation["coverage"]["fraction"] == pytest.approx(1.0, abs=0.01)
        assert summary["absolute_position_error"][name]["poses"] == len(trajectory)

    # the heading table: one row per GNSS epoch, every column named
    with open(run_output / "heading.csv") as handle:
        assert handle.readline().strip().split(",") == [*HEADING_COLUMNS, *HEADING_OPTIONAL]
    table = read_heading_csv(run_output / "heading.csv")
    np.testing.assert_allclose(table.t, recording.observations.epoch_time, rtol=0, atol=5e-4)
    assert summary["gnss_epochs"] == len(table.t) == 501  # 20 Hz for 25 s and the last epoch
    assert summary["tight_heading_availability"] == pytest.approx(
        np.mean(np.isfinite(table.yaw_tc)), abs=1e-12
    )

    # the tracks on the map are the trajectories written, in longitude and latitude
    features = json.loads((run_output / "trajectories.geojson").read_text())["features"]
    assert [f["properties"]["name"] for f in features] == ["truth", *trajectories]
    for feature in features[1:]:
        coordinates = np.array(feature["geometry"]["coordinates"])
        positions = trajectories[feature["properties"]["name"]].positions
        np.testing.assert_allclose(coordinates, lon_lat(recording.enu, positions), atol=1e-8)

    # the figures: pictures, and the report embeds the very PNGs written beside it
    report = (run_output / "report.html").read_text()
    embedded = [base64.b64decode(b) for b in re.findall(r"data:image/png;base64,([^'\"]+)", report)]
    for name in FIGURES:
        png = (run_output / name).read_bytes()
        pixels = imread(io.BytesIO(png), format="png")
        assert pixels.shape[0] >= 300 and pixels.shape[1] >= 600, name
        assert len(np.unique(pixels.reshape(-1, pixels.shape[2]), axis=0)) > 10, name
        assert name == "trajectories.png" or png in embedded, name
    assert "VO + GPS (tightly coupled)" in report and "synthetic data" in report
    # the full configuration table: the run's RunConfig, every angle in degrees by its name
    start = report.index("Full configuration")
    table = report[start : report.index("</details>", start)]
    shown = dict(re.findall(r"<tr><th>(.*?)</th><td class='text'>(.*?)</td></tr>", table))
    assert shown == {
        name: html.escape(value) for name, value in config_rows(RunConfig().for_sequence(recording))
    }
    assert shown["heading.backfill_bias_sigma_deg_s"] == "0.05 deg/s"
    assert shown["heading.tight_calibration_max_sigma_deg"] == "5 deg"
    assert not [name for name in shown if "_rad" in name]
    available = f"{summary['tight_heading_availability']:.1%}"
    assert f"<th>tightly coupled heading available</th><td class='text'>{available}</td>" in report


@pytest.mark.slow
def test_run_recovers_calibration_and_heading(sequence, run_output):
    summary = json.loads((run_output / "summary.json").read_text())
    assert summary["tight_heading_availability"] >= summary["conventional_heading_availability"]
    assert summary["tight_heading_availability"] > 0.5
    assert summary["final_gyro_bias_dps"] == pytest.approx(0.3, abs=0.1)
    assert summary["final_wheel_scale"] == pytest.approx(1 / 1.02, abs=0.01)
    # the simulated CAN bus carries a longitudinal accelerometer, whose offset is calibrated
    # after the drive's first valid conventional velocities: the grade prior is then its own
    assert 0.0 < summary["grade_prior_from_accelerometer"] < 1.0
    assert summary["grade_prior_sigma_median"] <= 0.05
    table = read_heading_csv(run_output / "heading.csv")
    assert np.all(np.diff(table.t) > 0)
    assert summary["tight_heading_rejected_rows"] == int(table.rejected_rows.sum())
    evaluation = summary["evaluation"]
    tc = evaluation["vo_gps_tc"]
    assert tc["heading_rmse_deg"] < 3.0
    assert tc["error_per_100m_m"] < 2.0


@pytest.mark.slow
def test_every_trajectory_starts_where_the_vehicle_was(sequence, run_output):
    """The canyon's first valid fixes come 21 s into the drive: carried back along each
    trajectory they put its first pose 0.3-0.7 m from the truth's horizontally and 1.2-1.9 m
    vertically (the antenna 1.6 m up taken off); the median of the first 5 s of fixes put it
    118 m off, at the car's position 21 s later."""
    truth = read_tum(sequence / "ground_truth.tum")
    for path in sorted(run_output.glob("trajectory_*.tum")):
        first = read_tum(path)
        start = [np.interp(first.t[0], truth.t, truth.positions[:, i]) for i in range(3)]
        error = first.positions[0] - start
        assert np.linalg.norm(error[:2]) < 1.5 and abs(error[2]) < 2.5, path.name


@pytest.mark.slow
def test_corrected_trajectory_is_finite_and_covers_every_image(sequence, run_output):
    corrected = read_tum(run_output / "trajectory_corrected.tum")
    images = list((sequence / "image_0").iterdir())
    assert len(corrected) == len(images)
    assert np.all(np.isfinite(corrected.positions))


def test_missing_manifest_is_a_clear_error(tmp_path, capsys):
    (tmp_path / "seq").mkdir()
    assert main(["run", str(tmp_path / "seq"), "-o", str(tmp_path / "out")]) == 1
    assert "sequence.yaml" in capsys.readouterr().err


def test_heading_short_frame_policy_is_checked_by_the_parser(tmp_path):
    with pytest.raises(SystemExit) as exit_info:
        main(["heading", "x.obs", "--nav", "x.nav", "--can-short-frames", "guess", "-o", "h.csv"])
    assert exit_info.value.code == 2


def _heading_table(t, yaw_tc, tc_usable, yaw_conv=None, conv_valid=None) -> HeadingTable:
    n = len(t)
    return HeadingTable(
        t=np.asarray(t, dtype=float),
        yaw_tc=np.asarray(yaw_tc, dtype=float),
        sigma_tc=np.full(n, np.radians(0.5)),
        tc_reliable=np.asarray(tc_usable, dtype=bool),
        n_obs_window=np.full(n, 8),
        n_sat_epoch=np.full(n, 6),
        yaw_conv=np.full(n, np.nan) if yaw_conv is None else np.asarray(yaw_conv, dtype=float),
        conv_valid=np.zeros(n, dtype=bool) if conv_valid is None else np.asarray(conv_valid),
        gyro_bias=np.zeros(n),
        wheel_scale=np.ones(n),
    )


def _turning_trajectory(t: np.ndarray, yaw0: float, rate: float) -> Trajectory:
    yaw = yaw0 + rate * (t - t[0])
    return Trajectory(t, np.zeros((len(t), 3)), Rotation.from_euler("z", yaw[:, None]))


def test_the_initial_heading_is_the_median_of_the_first_seconds_not_the_first_heading():
    t = np.arange(0.0, 20.0, 0.5)
    trajectory = _turning_trajectory(t, yaw0=0.3, rate=0.02)
    truth_offset = np.radians(100.0)
    yaw_tc = 0.3 + 0.02 * t + truth_offset
    yaw_tc[2] += np.radians(40.0)  # the first usable heading is off (a reflected satellite)
    usable = t >= 1.0
    yaw_tc[~usable] = np.nan
    offset = initial_yaw_offset(_heading_table(t, yaw_tc, usable), usable, trajectory)
    assert offset == pytest.approx(truth_offset, abs=1e-12)


def test_the_initial_heading_median_is_circular():
    t = np.arange(5.0)
    trajectory = _turning_trajectory(t, yaw0=0.0, rate=0.0)
    yaw_tc = np.radians([-179.5, 179.0, 179.0, -178.0, 179.0])  # π + (0.5, -1, -1, 2, -1)°
    usable = np.ones(len(t), dtype=bool)
    offset = initial_yaw_offset(_heading_table(t, yaw_tc, usable), usable, trajectory)
    assert np.degrees(wrap_angle(offset - np.pi)) == pytest.approx(-1.0, abs=1e-9)


def test_the_initial_heading_takes_the_first_span_inside_the_trajectory():
    t = np.arange(0.0, 30.0, 1.0)
    trajectory = _turning_trajectory(t[10:], yaw0=0.5, rate=0.0)
    yaw_tc = np.where(t < 10.0, 2.0, 1.5)
    yaw_tc[t >= 16.0] = 2.5  # beyond 5 s from the first heading inside: not used
    usable = np.ones(len(t), dtype=bool)
    offset = initial_yaw_offset(_heading_table(t, yaw_tc, usable), usable, trajectory)
    assert offset == pytest.approx(1.0, abs=1e-12)


def test_without_tight_headings_the_conventional_ones_start_the_trajectory(caplog):
    t = np.arange(0.0, 10.0, 1.0)
    trajectory = _turning_trajectory(t, yaw0=0.25, rate=0.0)
    none = np.zeros(len(t), dtype=bool)
    table = _heading_table(t, np.full(len(t), np.nan), none, np.full(len(t), 1.25), ~none)
    assert initial_yaw_offset(table, none, trajectory) == pytest.approx(1.0, abs=1e-12)
    table = _heading_table(t, np.full(len(t), np.nan), none, np.full(len(t), np.nan), none)
    with caplog.at_level("WARNING"):
        assert initial_yaw_offset(table, none, trajectory) == pytest.approx(-0.25, abs=1e-12)
    assert "starts facing east" in caplog.text


def test_reliable_tight_headings_too_vague_to_correct_still_start_the_trajectory():
    """A canyon from the start: no conventional heading, tight headings reliable but at σ 3.4°
    (not usable); before the unreliable ones, after the conventional ones."""
    t = np.arange(0.0, 10.0, 1.0)
    trajectory = _turning_trajectory(t, yaw0=0.25, rate=0.0)
    none = np.zeros(len(t), dtype=bool)
    yaw_tc = np.where(t < 3.0, 2.0, 0.75)
    table = _heading_table(t, yaw_tc, t >= 3.0)
    table.sigma_tc[:] = np.radians(3.4)
    assert initial_yaw_offset(table, none, trajectory) == pytest.approx(0.5, abs=1e-12)
    with_conventional = _heading_table(t, yaw_tc, t >= 3.0, np.full(len(t), 1.25), ~none)
    assert initial_yaw_offset(with_conventional, none, trajectory) == pytest.approx(1.0, abs=1e-12)


ENU = EnuFrame(np.radians(37.7), np.radians(-122.5), 30.0)


def _gnss_solutions(t, fixes_enu, fix_sigma_m, velocity_enu, velocity_sigma_mps):
    """SPP and Doppler solutions (ECEF) from ENU fixes (NaN rows: no fix) and velocities."""
    n = len(t)
    fixes = ENU.enu_to_ecef(fixes_enu)
    valid = np.all(np.isfinite(fixes), axis=1)
    spp = SppSolution(
        t, fixes, {"G": np.zeros(n)}, np.full(n, 8), np.ones(n), np.full(n, 2.0), valid, 0,
        horizontal_sigma_m=np.full(n, np.sqrt(2.0) * fix_sigma_m),
    )  # fmt: skip
    velocity = VelocitySolution(
        t, velocity_enu @ ENU.rotation, velocity_enu, np.zeros(n),
        np.tile(np.eye(4) * velocity_sigma_mps**2, (n, 1, 1)), np.ones((n, 5)), np.full(n, 8),
        np.full(n, 8), np.zeros(n, dtype=int), np.zeros(n), np.ones(n, dtype=bool),
        untestable=np.zeros(n, dtype=bool),
    )  # fmt: skip
    return spp, velocity


def test_the_antenna_track_puts_a_moving_car_where_it_was_at_each_epoch_despite_a_bad_fix():
    """A car at a constant 20.6 m/s with fixes of σ 2 m per horizontal axis (4 m up) and exact
    Doppler velocities (σ 0.02 m/s): the track at the first epoch is the fixes carried back, a
    robust mean of N = 99 good fixes: σ/√(0.95 N) (the Cauchy weights' 95 % efficiency),
    0.21 m per horizontal axis and 0.41 m up, within 4 σ. The first fix, 200 m off, would move
    a plain mean by 2 m; the old median of the first 5 s of fixes lay 51.5 m ahead."""
    rng = np.random.default_rng(7)
    t = 1000.0 + np.arange(100) * 0.1
    velocity = np.tile([20.0, 5.0, 0.2], (t.size, 1))
    truth = np.array([30.0, -40.0, 12.0]) + (t - t[0])[:, None] * velocity[0]
    noise = rng.normal(size=truth.shape) * [2.0, 2.0, 4.0]
    fixes = truth + noise
    fixes[0, 0] += 200.0
    spp, doppler = _gnss_solutions(t, fixes, 2.0, velocity, 0.02)
    track = antenna_track(spp, doppler, None, ENU)
    np.testing.assert_array_equal(track.t, t)
    bound = 4.0 / np.sqrt(0.95 * 99) * np.array([2.0, 2.0, 4.0])
    assert np.all(np.abs(track.position[0] - truth[0]) < bound)
    assert np.all(np.abs(track.position - truth) < bound)


def test_the_antenna_track_falls_back_to_one_fix_then_the_approximate_position(caplog):
    t = np.arange(5.0)
    fixes = np.full((5, 3), np.nan)
    fixes[2] = [10.0, 20.0, 3.0]
    spp, doppler = _gnss_solutions(t, fixes, 2.0, np.zeros((5, 3)), 0.02)
    one = antenna_track(spp, doppler, None, ENU)
    np.testing.assert_array_equal(one.t, [2.0])
    np.testing.assert_allclose(one.position, [[10.0, 20.0, 3.0]], atol=1e-6)
    spp, doppler = _gnss_solutions(t, np.full((5, 3), np.nan), 2.0, np.zeros((5, 3)), 0.02)
    approx = ENU.enu_to_ecef(np.array([-5.0, 7.0, 1.0]))
    with caplog.at_level("WARNING"):
        header = antenna_track(spp, doppler, approx, ENU)
        origin = antenna_track(spp, doppler, None, ENU)
    assert header.t.size == 0 and origin.t.size == 0
    np.testing.assert_allclose(header.position, [[-5.0, 7.0, 1.0]], atol=1e-6)
    np.testing.assert_array_equal(origin.position, np.zeros((1, 3)))
    assert "RINEX approximate position" in caplog.text and "at the origin" in caplog.text


LEVER = (1.5, -0.3, 1.6)


def _placed_straight_drive(t_dr, t_gnss, heading):
    """A straight drive at 15 m/s along ``heading``: dead reckoning from its own origin facing
    x, placed by the exact antenna track; returns the placed trajectory and the truth."""
    direction = np.array([np.cos(heading), np.sin(heading), 0.0])

    def vehicle(t):
        return np.array([100.0, -50.0, 2.0]) + 15.0 * (t - 0.4)[:, None] * direction

    own = Trajectory(
        t_dr, 15.0 * (t_dr - t_dr[0])[:, None] * [1.0, 0.0, 0.0], Rotation.identity(t_dr.size)
    )
    antenna = vehicle(t_gnss) + Rotation.from_euler("z", heading).apply(LEVER)
    placed = level_with_yaw(own, heading, AntennaTrack(t_gnss, antenna), LEVER)
    return placed, vehicle(t_dr)


def test_a_trajectory_is_placed_where_the_vehicle_was_at_its_first_gnss_epoch():
    """The vehicle, not the antenna 1.5 m ahead, 0.3 m right and 1.6 m up, is on the truth at
    every pose: whether the trajectory starts between GNSS epochs or 0.5 s before the first
    (the dead reckoning carries it back), to rounding."""
    t_dr = 0.43 + np.arange(100) * 0.05
    for t_gnss in (np.arange(0.0, 6.0, 0.1), np.arange(0.93, 6.0, 1.0)):
        placed, truth = _placed_straight_drive(t_dr, t_gnss, np.radians(30.0))
        np.testing.assert_allclose(placed.positions, truth, atol=1e-9)
        assert np.degrees(placed.yaw()[0]) == pytest.approx(30.0, abs=1e-9)


def test_fixes_only_seconds_later_are_carried_back_along_the_trajectory():
    """A street canyon: the first valid fixes 20 s after the start (σ 1 m, one of the first
    eleven 100 m off) and a turning drive. The median of the eleven fixes carried back along
    the trajectory: 1.25 σ/√10 = 0.4 m per axis for the ten good ones, the bad one shifting it
    by at most half a gap between them; 1.5 m bounds it. (A track carried back along Doppler
    velocities there drifted by 37 m in the simulated canyon of ``run_output``.)"""
    rng = np.random.default_rng(3)
    t = np.arange(0.0, 30.0, 0.05)
    yaw = 0.4 + 0.03 * t
    truth = np.column_stack([np.cumsum(10.0 * np.cos(yaw)), np.cumsum(10.0 * np.sin(yaw))])
    truth = np.column_stack([truth * 0.05 + [200.0, -80.0], np.full(t.size, 3.0)])
    turn = Rotation.from_euler("z", (yaw - 0.4)[:, None])
    own = Trajectory(t, (truth - truth[0]) @ Rotation.from_euler("z", -0.4).as_matrix().T, turn)
    fixes = np.flatnonzero(t >= 20.0)[::10]
    antenna = truth[fixes] + Rotation.from_euler("z", yaw[fixes, None]).apply(LEVER)
    antenna += rng.normal(size=antenna.shape)
    antenna[3] += [100.0, -60.0, 20.0]
    placed = level_with_yaw(own, 0.4, AntennaTrack(t[fixes], antenna), LEVER)
    assert np.all(np.abs(placed.positions[0] - truth[0]) < 1.5)
    np.testing.assert_allclose(placed.positions - placed.positions[0], truth - truth[0], atol=1e-9)


def _canyon_heights(height_sigma):
    """A straight drive 3 m above the origin, placed by fixes exact horizontally whose heights
    are 46 m too high (σ_u 12 m, the sample's street canyon) except the ones of ``height_sigma``
    at most 5 m, which are right."""
    t = np.arange(0.0, 20.0, 0.1)
    truth = np.column_stack([12.0 * t, np.zeros(t.size), np.full(t.size, 3.0)])
    own = Trajectory(t, truth - truth[0], Rotation.identity(t.size))
    fixes = np.arange(0, t.size, 10)
    antenna = truth[fixes] + np.array(LEVER)
    antenna[:, 2] += np.where(height_sigma <= PLACEMENT_VERTICAL_SIGMA_M, 0.0, 46.0)
    track = AntennaTrack(t[fixes], antenna, height_sigma, "test")
    return level_with_yaw(own, 0.0, track, LEVER), truth


def test_heights_come_from_the_fixes_with_a_small_vertical_sigma_or_the_origin():
    """Before: every trajectory 46 m above the road, the height of the canyon's fixes."""
    sigma = np.full(20, 12.0)
    placed, truth = _canyon_heights(sigma)
    np.testing.assert_allclose(placed.positions[:, :2], truth[:, :2], atol=1e-9)
    np.testing.assert_allclose(placed.positions[:, 2], 0.0, atol=1e-9)  # the origin's height
    sigma[[3, 8, 15]] = [2.0, 4.0, 1.5]  # three good heights (beyond the first 5 s: carried)
    placed, truth = _canyon_heights(sigma)
    np.testing.assert_allclose(placed.positions, truth, atol=1e-9)


def test_the_antenna_track_says_what_placed_the_heights():
    t = np.arange(10.0)
    position = np.tile(EnuFrame(0.6, 2.4, 50.0).origin_ecef, (10, 1))
    spp = SppSolution(t, position, {}, np.full(10, 8), t, t, np.ones(10, bool), 0)
    velocity = velocity_solution(t, np.zeros((10, 3)))
    frame = EnuFrame(0.6, 2.4, 0.0)
    poor = replace(spp, horizontal_sigma_m=np.ones(10), vertical_sigma_m=np.full(10, 9.0))
    assert "the sequence origin" in antenna_track(poor, velocity, None, frame).height_source
    sigma = np.where(t < 4, 3.0, 9.0)
    good = replace(poor, vertical_sigma_m=sigma)
    track = antenna_track(good, velocity, None, frame)
    assert track.height_source.startswith("the valid fixes with a vertical σ of at most 5 m (4 of")
    np.testing.assert_array_equal(track.height_rows, np.arange(4))


def test_a_trajectory_without_a_gnss_epoch_is_placed_by_the_nearest_one_with_a_warning(caplog):
    t_dr = np.arange(100) * 0.05
    with caplog.at_level("WARNING"):
        placed, truth = _placed_straight_drive(t_dr, np.array([-3.0, 7.0]), 0.0)
    # the epoch 2.05 s after the end places the end: 30.75 m ahead, driven meanwhile
    np.testing.assert_allclose(placed.positions - truth, np.tile([30.75, 0, 0], (100, 1)))
    assert "antenna position 2.0 s outside it" in caplog.text
    untimed = AntennaTrack(np.zeros(0), np.array([[1.0, 2.0, 3.0]]))
    own = Trajectory(t_dr, np.zeros((100, 3)), Rotation.identity(100))
    np.testing.assert_allclose(level_with_yaw(own, 0.0, untimed).positions[0], [1.0, 2.0, 3.0])


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        ({"elevation_mask_rad": 10.0}, r"RunConfig.elevation_mask_rad = 10: .*looks like degrees"),
        ({"elevation_mask_rad": np.pi / 2}, r"RunConfig.elevation_mask_rad = 1.5708"),
        ({"dead_reckoning_rate_hz": 0.0}, "RunConfig.dead_reckoning_rate_hz = 0.0"),
    ],
)
def test_run_config_refuses_values_out_of_their_domain(arguments, message):
    """A mask of 10 (degrees for radians) left no tight heading at all, silently (QA round 3,
    finding 3)."""
    with pytest.raises(InputError, match=message):
        RunConfig(**arguments)
    assert RunConfig(elevation_mask_rad=0.0).elevation_mask_rad == 0.0


@pytest.fixture(scope="module")
def turning_drive(turning_drive_folder):
    """The 20-s simulated canyon drive with one left turn of 90° (13–16 s), read."""
    return read_sequence(turning_drive_folder)


@pytest.mark.slow
def test_the_library_run_checks_the_inputs_and_returns_its_warnings(turning_drive):
    result = run_sequence(turning_drive)
    assert result.warnings == [] and result.heading.warnings == []
    assert result.heading.clock_residual_offset_s == pytest.approx(0.0, abs=0.15)
    # a gyro 5 °/s off (beyond a car's sensor; the true bias is 0.3 °/s)
    offset = SensorSeries(turning_drive.yaw_rate.t, turning_drive.yaw_rate.value + np.radians(5))
    warnings = run_sequence(replace(turning_drive, yaw_rate=offset)).warnings
    (warning,) = [w for w in warnings if w.startswith("gyro bias")]
    assert warning.startswith("gyro bias: the calibration gives +5.3")
    # turning 5 °/s more than the course, the gyro confirms no turn: its sign is unchecked
    assert any("its sign could not be checked" in w for w in warnings)


@pytest.mark.slow
def test_the_library_run_refuses_a_yaw_rate_of_the_wrong_sign_or_in_deg_per_s(turning_drive):
    negated = replace(turning_drive, yaw_rate=_scaled(turning_drive.yaw_rate, -1.0))
    with pytest.raises(InputError, match=r"wrong sign: over 1 turn\(s\) totalling 9") as info:
        run_sequence(negated)
    assert "CAN signal VEHICLE_DYNAMICS.YAW_RATE (can.yaw_rate)" in str(info.value)
    assert str(info.value).endswith(
        "set can.yaw_rate_sign in "
        + str(turning_drive.vehicle_source.yaw_rate_sign_fix.split(" in ", 1)[1])
    )
    degrees = replace(turning_drive, yaw_rate=_scaled(turning_drive.yaw_rate, np.degrees(1.0)))
    with pytest.raises(InputError, match=r"can.yaw_rate\): implausibly large for a moving car"):
        run_sequence(degrees)


def _scaled(series: SensorSeries, factor: float) -> SensorSeries:
    return SensorSeries(series.t, series.value * factor, series.name, series.unit)
