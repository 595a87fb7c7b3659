"""``vo-doppler run`` end to end on a short generated urban-canyon drive."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.cli import main
from vo_doppler.geo import wrap_angle
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.trajectory import read_tum
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.run import _malloc_trim, initial_yaw_offset, release_free_heap
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon


@pytest.fixture(scope="module")
def sequence(tmp_path_factory):
    folder = tmp_path_factory.mktemp("canyon") / "seq"
    config = UrbanCanyonConfig(duration_s=25.0, seed=4, image_size=(480, 270))
    simulate_urban_canyon(folder, config)
    return folder


@pytest.fixture(scope="module")
def run_output(sequence, tmp_path_factory):
    out = tmp_path_factory.mktemp("run")
    assert main(["run", str(sequence), "-o", str(out)]) == 0
    return out


def test_run_writes_every_output(run_output):
    for name in (
        "trajectory_vo.tum",
        "trajectory_corrected.tum",
        "trajectory_vo_gps_conv.tum",
        "trajectory_dr.tum",
        "trajectory_dr_gps_conv.tum",
        "trajectory_dr_gps_tc.tum",
        "heading.csv",
        "trajectories.png",
        "heading.png",
        "error_per_100m.png",
        "report.html",
        "summary.json",
    ):
        assert (run_output / name).stat().st_size > 0, name
    report = (run_output / "report.html").read_text()
    assert "VO + GPS (tightly coupled)" in report and "data:image/png;base64," in report
    assert "synthetic data" in report and (run_output / "trajectories.geojson").is_file()
    summary = json.loads((run_output / "summary.json").read_text())
    available = f"{summary['tight_heading_availability']:.1%}"
    assert f"<th>tightly coupled heading available</th><td class='text'>{available}</td>" in report


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


def test_corrected_trajectory_is_finite_and_covers_every_image(sequence, run_output):
    corrected = read_tum(run_output / "trajectory_corrected.tum")
    images = list((sequence / "image_0").iterdir())
    assert len(corrected) == len(images)
    assert np.all(np.isfinite(corrected.positions))


def test_missing_manifest_is_a_clear_error(tmp_path, capsys):
    assert main(["run", str(tmp_path), "-o", str(tmp_path / "out")]) == 1
    assert "sequence.yaml" in capsys.readouterr().err


def test_heading_short_frame_policy_is_checked_by_the_parser(tmp_path):
    with pytest.raises(SystemExit) as exit_info:
        main(["heading", "x.obs", "--nav", "x.nav", "--can-short-frames", "guess", "-o", "h.csv"])
    assert exit_info.value.code == 2


def resident_mib() -> float:
    with open("/proc/self/status") as status:
        return next(int(line.split()[1]) for line in status if line.startswith("VmRSS:")) / 1024


def test_release_free_heap_returns_freed_memory_the_heap_kept():
    if _malloc_trim() is None:
        pytest.skip("the C library has no malloc_trim (not glibc): release_free_heap does nothing")
    # 32-KiB heap blocks, each followed by a kept 1.6-KB one: freed, they leave holes inside the
    # heap that glibc does not return by itself (only its top is trimmed on free)
    pairs = [(np.ones(4096), np.ones(200)) for _ in range(1024)]
    kept = [small for _, small in pairs]
    del pairs
    before = resident_mib()
    release_free_heap()
    assert before - resident_mib() > 16.0, "32 MiB freed between kept blocks stayed resident"
    assert len(kept) == 1024


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
