"""The evaluation against a ground truth that covers part of the drive, none of it, or a path
that does not move: every other output is written, and the summary says what was not evaluated.
The map and the GeoJSON show the trajectories as written, and the summary their absolute errors.
Every scalar of the summary has a label for the report."""

from __future__ import annotations

import dataclasses
import html
import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from vo_doppler.eval import run_evaluation
from vo_doppler.geo import ecef_to_geodetic, geodetic_to_ecef
from vo_doppler.io.sequence import InputReport, read_sequence
from vo_doppler.io.trajectory import read_tum
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.model.visual_odometry import VoStats
from vo_doppler.report.run_outputs import (
    FACT_FORMATS,
    NOT_FACTS,
    SUMMARY_FILE,
    readable_facts,
    result_checks,
    summarise,
    write_run_outputs,
)
from vo_doppler.run import RunConfig, run_sequence
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon


@pytest.fixture(scope="module")
def drive_run(tmp_path_factory):
    """A 10 s generated drive without images, its inputs and its run (the stages only)."""
    folder = tmp_path_factory.mktemp("eval_drive") / "seq"
    simulate_urban_canyon(folder, UrbanCanyonConfig(duration_s=10.0, seed=3, render=False))
    sequence = read_sequence(folder)
    return sequence, run_sequence(sequence)


def _write(drive_run, out: Path, truth: Trajectory | None) -> dict:
    sequence, result = drive_run
    summary = write_run_outputs(
        dataclasses.replace(sequence, truth=truth), result, RunConfig(), out
    )
    written = (out / SUMMARY_FILE).read_text()
    assert json.loads(written, parse_constant=lambda word: 1 / 0) is not None
    for name in ("trajectory_dr.tum", "heading.csv", "trajectories.png", "report.html"):
        assert (out / name).stat().st_size > 0, name
    return summary


@pytest.mark.slow
def test_a_ground_truth_starting_late_is_evaluated_over_the_overlap(drive_run, tmp_path):
    truth = drive_run[0].truth
    late = truth.subset(np.flatnonzero(truth.t >= truth.t[0] + 0.46))
    summary = _write(drive_run, tmp_path, late)
    dr = summary["evaluation"]["dr"]
    assert dr["coverage"]["starts_after_s"] == pytest.approx(0.46, abs=0.05)
    assert dr["error_per_100m_m"] is not None and (tmp_path / "error_per_100m.png").is_file()
    (warning,) = [w for w in summary["warnings"] if "were evaluated" in w]
    assert warning.startswith("wheel + gyro DR alone, wheel + gyro DR + GPS (conventional)")
    assert "after its first pose" in warning
    assert html.escape(warning) in (tmp_path / "report.html").read_text()


@pytest.mark.slow
def test_a_ground_truth_from_another_time_skips_the_evaluation_and_keeps_the_rest(
    drive_run, tmp_path
):
    truth = drive_run[0].truth
    elsewhere = Trajectory(truth.t + 1000.0, truth.positions, truth.orientations)
    summary = _write(drive_run, tmp_path, elsewhere)
    assert "evaluation" not in summary and not (tmp_path / "error_per_100m.png").exists()
    assert any(w.startswith("not evaluated: wheel + gyro DR alone") for w in summary["warnings"])
    assert "The ground truth could not be used" in (tmp_path / "report.html").read_text()


@pytest.mark.slow
def test_a_static_ground_truth_has_no_figure_per_distance(drive_run, tmp_path):
    truth = drive_run[0].truth
    still = Trajectory(truth.t, np.repeat(truth.positions[:1], len(truth), 0), truth.orientations)
    summary = _write(drive_run, tmp_path, still)
    for figures in summary["evaluation"].values():
        assert figures["error_per_100m_m"] is None and figures["kitti_translation_pct"] is None
    assert any("shorter than the 5 m" in w for w in summary["warnings"])
    report = (tmp_path / "report.html").read_text()
    assert "too short for errors per distance" in report and "<td>—</td>" in report


@pytest.mark.slow
def test_a_failing_evaluation_becomes_a_warning(drive_run, tmp_path, monkeypatch):
    def broken(*_):
        raise RuntimeError("boom")

    monkeypatch.setattr(run_evaluation, "evaluate_pipelines", broken)
    summary = _write(drive_run, tmp_path, drive_run[0].truth)
    assert "evaluation" not in summary
    assert any(
        "evaluation against the ground truth failed (RuntimeError: boom" in w
        for w in summary["warnings"]
    )


@pytest.mark.slow
def test_geojson_and_map_show_the_trajectories_as_written(drive_run, tmp_path):
    sequence, _ = drive_run
    summary = _write(drive_run, tmp_path, sequence.truth)
    features = json.loads((tmp_path / "trajectories.geojson").read_text())["features"]
    by_name = {f["properties"]["name"]: f["geometry"]["coordinates"] for f in features}
    assert set(by_name) == {"truth", "dr", "dr_gps_conv", "dr_gps_tc"}
    for name in ("dr", "dr_gps_conv", "dr_gps_tc"):
        written = read_tum(tmp_path / f"trajectory_{name}.tum")
        lon, lat = np.radians(np.array(by_name[name])).T
        assert len(lon) == len(written)
        # GeoJSON has no height: back to ENU at the written position's ellipsoidal height.
        _, _, height = ecef_to_geodetic(sequence.enu.enu_to_ecef(written.positions))
        east_north = sequence.enu.ecef_to_enu(geodetic_to_ecef(lat, lon, height))[:, :2]
        # 1e-8 degrees of the written coordinates is 1.1 mm.
        np.testing.assert_allclose(east_north, written.positions[:, :2], atol=2e-3)
    # The absolute errors: the written track against the truth interpolated at its times.
    truth = sequence.truth
    for name, found in summary["absolute_position_error"].items():
        written = read_tum(tmp_path / f"trajectory_{name}.tum")
        inside = (written.t >= truth.t[0]) & (written.t <= truth.t[-1])
        reference = np.column_stack(
            [np.interp(written.t[inside], truth.t, truth.positions[:, k]) for k in range(3)]
        )
        difference = written.positions[inside] - reference
        horizontal = np.linalg.norm(difference[:, :2], axis=1)
        vertical = np.abs(difference[:, 2])
        expected = {
            "start_horizontal_m": horizontal[0],
            "start_vertical_m": vertical[0],
            "end_horizontal_m": horizontal[-1],
            "end_vertical_m": vertical[-1],
            "median_horizontal_m": np.median(horizontal),
            "median_vertical_m": np.median(vertical),
            "poses": inside.sum(),
        }
        # The TUM file keeps positions to 0.1 mm.
        assert found == pytest.approx(expected, abs=2e-4), name
    # Placed by SPP, not on the truth (evaluated, it would start at 0 m).
    assert summary["absolute_position_error"]["dr"]["start_horizontal_m"] > 0.1
    page = (tmp_path / "report.html").read_text()
    assert "Positions against ground truth, as written" in page
    assert "<g id='evaluated-tracks' display='none'>" in page
    assert "trajectories.png" in page


@pytest.mark.slow
def test_the_report_of_a_drive_without_camera_names_no_vo_setting(drive_run, tmp_path):
    """Issue 30: "VO window 20 frames" and the VO's definitions on a drive without camera."""
    assert not drive_run[0].has_camera
    _write(drive_run, tmp_path, drive_run[0].truth)
    page = html.unescape((tmp_path / "report.html").read_text())
    assert "VO window" not in page and "vo.window_size" not in page
    assert "VO alone / + GPS" not in page and "wheel + gyro DR alone / + GPS" in page
    assert "dead-reckoning heading compared as" in page


@pytest.mark.slow
def test_heading_use_is_a_share_of_the_epochs_with_vehicle_signals(drive_run, tmp_path):
    """Issue 30: the share of GNSS epochs whose tightly coupled heading was used counted the
    epochs without vehicle signals. Vehicle signals kept over the middle of the drive only."""
    sequence, result = drive_run
    t = sequence.observations.epoch_time
    begin, end = t[0] + 3.0, t[-1] - 3.0

    def middle(series):
        inside = (series.t >= begin) & (series.t <= end)
        return dataclasses.replace(series, t=series.t[inside], value=series.value[inside])

    partial = dataclasses.replace(
        sequence, wheel_speed=middle(sequence.wheel_speed), yaw_rate=middle(sequence.yaw_rate)
    )
    summary = write_run_outputs(partial, result, RunConfig(), tmp_path)
    covered = (result.heading.t >= partial.vehicle_span[0]) & (
        result.heading.t <= partial.vehicle_span[1]
    )
    assert 0 < summary["vehicle_signal_epochs"] == covered.sum() < summary["gnss_epochs"]
    share = summary["tight_heading_used_with_vehicle_signals"]
    assert share == pytest.approx(result.tc_usable[covered].mean())
    for name in ("dr_gps_tc", "dr_gps_conv"):
        assert summary["evaluation"][name]["heading_availability"] == pytest.approx(
            np.mean(
                (
                    result.tc_usable
                    if name.endswith("tc")
                    else result.heading.published_conventional[0]
                )[
                    covered
                    & (result.heading.t >= result.trajectories[name].t[0])
                    & (result.heading.t <= result.trajectories[name].t[-1])
                ]
            )
        )


@pytest.mark.slow
def test_every_summary_key_has_a_label_and_units(drive_run, tmp_path):
    """Every key a run's summary can hold, with and without a camera: a new key without a
    label in ``FACT_FORMATS`` would show in the report as its raw name."""
    sequence, result = drive_run
    checks = result_checks(sequence, InputReport(), result, [])
    summary = write_run_outputs(sequence, result, RunConfig(), tmp_path, checks)
    with_camera = dataclasses.replace(
        result, vo=SimpleNamespace(stats=VoStats(frames=10, wall_seconds=2.0))
    )
    keys = set(summary) | set(summarise(with_camera))
    assert {"camera", "vo_frames", "can_clock_residual_offset_s", "evaluation"} <= keys
    assert not keys - set(FACT_FORMATS) - set(NOT_FACTS)
    assert not [label for label, _ in FACT_FORMATS.values() if "_" in label]


def test_facts_read_not_available_for_missing_figures_and_round_the_rest():
    facts = readable_facts(
        {
            "can_clock_residual_offset_s": -0.007521175152330629,
            "grade_prior_sigma_median": 0.05,
            "vo_fps": float("nan"),
            "final_wheel_scale": None,
        }
    )
    assert facts == {
        "wheel-speed clock offset left (CAN/vehicle signals against the GNSS Doppler speed)": (
            "-0.008 s"
        ),
        "road-grade prior σ, median (rise over run)": "5.0%",
        "VO speed": "not available",
        "wheel scale at the end": "not available",
    }
