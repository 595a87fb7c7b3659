"""``run --heading FILE``: an absolute heading from elsewhere replaces the tight heading computed
from GNSS. An earlier run's heading.csv reproduces that run's corrected figures; a minimal
heading CSV runs the corrected pipelines on a recording without GNSS."""

from __future__ import annotations

import json
import re
import shutil

import numpy as np
import pytest
import yaml

from tests.conftest import require_shared
from vo_doppler.cli import main
from vo_doppler.io.trajectory import read_tum

pytestmark = pytest.mark.xdist_group("span_drive")

CORRECTED = ("vo_gps_conv", "vo_gps_tc", "dr_gps_conv", "dr_gps_tc")


def _summary(folder) -> dict:
    return json.loads((folder / "summary.json").read_text())


@pytest.mark.slow
def test_run_with_an_earlier_runs_heading_csv_reproduces_its_corrected_figures(
    span_drive, span_cut_run, tmp_path, capsys
):
    heading = tmp_path / "heading.csv"
    shutil.copy(span_cut_run / "heading.csv", heading)
    out = tmp_path / "again"
    argv = ["run", str(span_drive.cut), "-o", str(out), "--heading", str(heading)]
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert f"absolute heading given: {heading}, not computed from GNSS" in printed.replace("\n", "")
    before, after = _summary(span_cut_run), _summary(out)
    assert after["heading_source"].startswith(f"given: {heading}, not computed from GNSS")
    assert "heading_source" not in before
    assert set(after["evaluation"]) == set(before["evaluation"])
    for name, errors in before["evaluation"].items():
        for key in ("error_per_100m_m", "kitti_translation_pct", "final_position_error_m"):
            assert after["evaluation"][name][key] == pytest.approx(errors[key], abs=1e-3), (
                name,
                key,
            )
        assert after["evaluation"][name]["heading_rmse_deg"] == pytest.approx(
            errors["heading_rmse_deg"], abs=1e-3
        )
    for key in ("gnss_epochs", "tight_heading_used", "conventional_heading_availability"):
        assert after[key] == before[key], key
    # the heading file's precision: 6 decimals of the wheel scale, 5 of the gyro bias (deg/s)
    assert after["final_wheel_scale"] == pytest.approx(before["final_wheel_scale"], abs=1e-6)
    assert after["final_gyro_bias_dps"] == pytest.approx(before["final_gyro_bias_dps"], abs=1e-5)
    report = (out / "report.html").read_text()
    assert "absolute heading" in report and "not computed from GNSS" in report


@pytest.fixture(scope="module")
def no_gnss(span_drive, tmp_path_factory):
    """The cut drive without its gnss section, as an imported KITTI raw drive has none, and a
    minimal heading CSV (gps_time_s, course_deg, sigma_deg) of its true heading at 10 Hz
    with 0.3° of noise."""
    folder = tmp_path_factory.mktemp("no_gnss") / "drive"
    shutil.copytree(span_drive.cut, folder)
    manifest = yaml.safe_load((folder / "sequence.yaml").read_text())
    del manifest["gnss"]
    (folder / "sequence.yaml").write_text(yaml.safe_dump(manifest, sort_keys=False))
    truth = read_tum(folder / "ground_truth.tum")
    t = np.arange(truth.t[0], truth.t[-1], 0.1)
    course = (90.0 - np.degrees(truth.yaw_at(t))) % 360.0
    course += 0.3 * np.random.default_rng(5).standard_normal(len(t))
    rows = "".join(f"{ti:.3f},{c:.4f},0.3\n" for ti, c in zip(t, course, strict=True))
    heading = folder.parent / "ins_heading.csv"
    heading.write_text("gps_time_s,course_deg,sigma_deg\n" + rows)
    return folder, heading


@pytest.mark.slow
def test_run_with_a_minimal_heading_corrects_a_recording_without_gnss(no_gnss, tmp_path, capsys):
    folder, heading = no_gnss
    out = tmp_path / "out"
    assert main(["-q", "run", str(folder), "-o", str(out), "--heading", str(heading)]) == 0
    summary = _summary(out)
    assert summary["gnss_epochs"] == 0
    assert "its heading corrects the tightly coupled pipelines" in summary["heading_source"]
    assert "used as recorded (no calibration)" in summary["heading_source"]
    assert summary["tight_heading_used"] == 1.0
    assert set(summary["evaluation"]) == {"vo", "vo_gps_tc", "dr", "dr_gps_tc"}
    errors = summary["evaluation"]  # uncalibrated: the wheels read 2 % fast, the gyro 0.3°/s
    for alone, corrected in (("vo", "vo_gps_tc"), ("dr", "dr_gps_tc")):
        assert errors[corrected]["error_per_100m_m"] < errors[alone]["error_per_100m_m"]
    assert errors["dr_gps_tc"]["heading_rmse_deg"] < 0.3 < errors["dr"]["heading_rmse_deg"]
    assert (out / "heading.csv").is_file() and (out / "trajectory_corrected.tum").is_file()
    assert not (out / "trajectory_vo_gps_conv.tum").exists()
    without = tmp_path / "without"
    assert main(["-q", "run", str(folder), "-o", str(without)]) == 0
    assert set(_summary(without)["evaluation"]) == {"vo", "dr"}


def _shifted(heading, path, start_s: float, keep: float = 1.0):
    """The minimal heading CSV ``heading`` with its times moved to start at ``start_s`` and
    only the first ``keep`` share of its span kept, written to ``path``."""
    table = np.loadtxt(heading, delimiter=",", skiprows=1)
    t = table[:, 0]
    table = table[t <= t[0] + keep * (t[-1] - t[0])]
    table[:, 0] += start_s - t[0]
    np.savetxt(path, table, fmt="%.3f", delimiter=",", header="gps_time_s,course_deg,sigma_deg")
    path.write_text(path.read_text().removeprefix("# "))
    return path


@pytest.mark.slow
def test_a_heading_on_another_clock_is_refused_naming_the_file_and_the_fix(
    no_gnss, tmp_path, capsys
):
    """Issue 30: the heading file checked against the recording's times as ``correct`` checks
    it against the trajectory's: times in seconds from the start are an error naming the file
    and the offset to add (they were refused only by the heading stage, for no valid row)."""
    folder, heading = no_gnss
    other = _shifted(heading, tmp_path / "from_start.csv", 0.0)
    out = tmp_path / "out"
    assert main(["run", str(folder), "-o", str(out), "--heading", str(other)]) == 1
    err = " ".join(capsys.readouterr().err.split())
    said = re.search(
        r"from_start\.csv: the recording times \((\d+\.\d{3})\.\.\d+\.\d{3} s\) and the "
        r"heading epochs \(0\.000\.\.7\.900 s, GPS time\) do not overlap; the file's times must "
        r"be GPS seconds, as the recording's are: add the GPS time of its first row to each "
        r"\(about (\d+) s if it starts with the recording\)",
        err,
    )
    assert said, err
    assert abs(float(said[2]) - float(said[1])) <= 0.5
    assert not out.exists()


@pytest.mark.slow
def test_a_heading_of_part_of_the_recording_is_warned(no_gnss, tmp_path, caplog):
    """A heading file covering a third of the recording: the run goes on, warned as
    ``correct`` warns, in the log and in the summary."""
    folder, heading = no_gnss
    first = read_tum(folder / "ground_truth.tum").t[0]
    part = _shifted(heading, tmp_path / "part.csv", first, keep=0.35)
    out = tmp_path / "out"
    assert main(["run", str(folder), "-o", str(out), "--heading", str(part)]) == 0
    warned = [w for w in _summary(out)["warnings"] if w.startswith(f"{part}: the recording times")]
    assert len(warned) == 1
    assert re.search(r"meet over 3\d% of the recording only: the rest is joined", warned[0])
    assert warned[0] in [r.getMessage() for r in caplog.records]


def test_a_heading_method_with_a_given_heading_is_a_usage_error(tmp_path, capsys):
    argv = ["run", str(tmp_path), "-o", str(tmp_path / "out"), "--heading", "h.csv"]
    with pytest.raises(SystemExit) as exit_info:
        main([*argv, "--heading-method", "robust"])
    assert exit_info.value.code == 2
    assert "--heading-method robust has no effect with --heading" in capsys.readouterr().err


@pytest.mark.slow
def test_the_heading_file_is_not_overwritten_by_the_run(span_drive, span_cut_run, capsys):
    """An earlier run's heading.csv given back to a run into the same folder is an input the
    output would replace: refused before anything is written (the folder is another test's
    too: every file of it stays as it was)."""
    heading = span_cut_run / "heading.csv"
    before = {p: p.read_bytes() for p in sorted(span_cut_run.rglob("*")) if p.is_file()}
    argv = ["run", str(span_drive.cut), "-o", str(span_cut_run), "--heading", str(heading)]
    assert main(argv) == 1
    assert {p: p.read_bytes() for p in sorted(span_cut_run.rglob("*")) if p.is_file()} == before
    assert "heading.csv" in capsys.readouterr().err


@pytest.mark.shared_data
def test_run_with_a_heading_on_an_imported_kitti_raw_drive(tmp_path, capsys):
    """Issue 31: a KITTI raw drive has no GNSS; with the OXTS unit's heading as a minimal CSV
    (an INS's heading, σ 0.2°) the corrected pipelines run on it."""
    drive = require_shared("kitti_raw_mini/2011_09_26/2011_09_26_drive_0001_sync")
    folder = tmp_path / "seq"
    assert main(["-q", "import", "kitti-raw", str(drive), "-o", str(folder)]) == 0
    truth = read_tum(folder / "ground_truth.tum")
    course = (90.0 - np.degrees(truth.yaw())) % 360.0
    rows = "".join(f"{t:.6f},{c:.4f},0.2\n" for t, c in zip(truth.t, course, strict=True))
    heading = tmp_path / "oxts_heading.csv"
    heading.write_text("gps_time_s,heading_deg,sigma_deg\n" + rows)
    out = tmp_path / "out"
    assert main(["-q", "run", str(folder), "-o", str(out), "--heading", str(heading)]) == 0
    summary = _summary(out)
    assert summary["gnss_epochs"] == 0 and "given: " in summary["heading_source"]
    assert summary["tight_heading_used"] == 1.0
    for name in ("trajectory_vo.tum", "trajectory_corrected.tum", "trajectory_dr_gps_tc.tum"):
        assert (out / name).is_file(), name
    assert "has no GNSS: the trajectories start at the ENU origin" in " ".join(summary["warnings"])
