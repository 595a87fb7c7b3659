"""``vo-doppler batch`` end to end on tiny generated drives: each recording's outputs as
``vo-doppler run`` writes them, a failure listed with its category, the aggregate as CSV,
Parquet and HTML with each run's warnings, the exit status, and ``--resume``."""

from __future__ import annotations

import csv
import json

import numpy as np
import pyarrow.parquet as pq
import pytest
from rich.console import Console

from tests.conftest import require_shared
from tests.helpers.batch import tiny_drive
from vo_doppler.batch import MARKER, RecordingOutcome, Status
from vo_doppler.cli import main
from vo_doppler.commands.batch_command import outcome_table

pytestmark = pytest.mark.xdist_group("tiny_drives")


@pytest.fixture(scope="module")
def batch_run(tmp_path_factory):
    drives = [tiny_drive(tmp_path_factory, seed) for seed in (1, 2)]
    folder = tmp_path_factory.mktemp("batch_cli")
    listing = folder / "recordings.txt"
    listing.write_text(
        f"# two drives (one twice) and a folder that is not there\n{drives[1]}\nmissing\n"
        f"{drives[1]}/\n"
    )
    out = folder / "out"
    command = ["batch", str(drives[0]), "--list", str(listing), "-o", str(out), "--workers", "2"]
    assert main(command) == 1
    return drives, out, command, listing


def read_rows(out):
    with (out / "batch_summary.csv").open() as stream:
        return list(csv.DictReader(stream))


@pytest.mark.slow
def test_every_recording_is_listed_with_failures_categorised(batch_run):
    _, out, _, listing = batch_run
    rows = read_rows(out)
    assert [r["recording"] for r in rows] == ["drive1", "drive2", "missing", "all recordings"]
    assert [r["status"] for r in rows[:3]] == ["done", "done", "failed"]
    assert rows[2]["exit_category"] == "input-error"
    missing = f"{listing}:3: the recording {listing.parent / 'missing'} does not exist"
    assert rows[2]["error"] == missing
    assert rows[3]["status"] == "2 done, 1 failed"
    page = (out / "batch_summary.html").read_text()
    assert "drive1/report.html" in page and "does not exist" in page


@pytest.mark.slow
def test_rows_hold_each_runs_summary_and_the_overall_weights(batch_run):
    _, out, _, _ = batch_run
    rows = read_rows(out)
    for row in rows[:2]:
        summary = json.loads((out / row["recording"] / "summary.json").read_text())
        assert float(row["final_wheel_scale"]) == summary["final_wheel_scale"]
        assert float(row["tight_heading_availability"]) == summary["tight_heading_availability"]
        error = summary["evaluation"]["vo_gps_tc"]["error_per_100m_m"]
        assert float(row["vo_gps_tc_error_per_100m_m"]) == error
    lengths = np.array([float(r["path_length_m"]) for r in rows[:2]])
    errors = np.array([float(r["vo_error_per_100m_m"]) for r in rows[:2]])
    overall = float(rows[3]["vo_error_per_100m_m"])
    assert overall == pytest.approx(np.sum(errors * lengths) / np.sum(lengths), rel=1e-12)
    epochs = np.array([int(r["gnss_epochs"]) for r in rows[:2]])
    available = np.array([float(r["tight_heading_availability"]) for r in rows[:2]])
    expected = np.sum(available * epochs) / np.sum(epochs)
    assert float(rows[3]["tight_heading_availability"]) == pytest.approx(expected, rel=1e-12)


@pytest.mark.slow
def test_rows_and_the_terminal_table_carry_each_runs_warnings(batch_run):
    _, out, _, _ = batch_run
    rows = read_rows(out)
    for row in rows[:2]:
        warnings = json.loads((out / row["recording"] / "summary.json").read_text())["warnings"]
        assert int(row["warnings"]) == len(warnings)
        assert row["warning_texts"] == " | ".join(warnings)
    assert int(rows[3]["warnings"]) == sum(int(r["warnings"]) for r in rows[:2])
    warned = RecordingOutcome("kmh", out, Status.DONE, 1.0, {"warnings": ["wheel scale: 0.275"]})
    clean = RecordingOutcome("clean", out, Status.DONE, 1.0, {"warnings": []})
    console = Console(width=200, record=True)
    console.print(outcome_table([warned, clean]))
    text = console.export_text()
    assert "│ kmh       │ done, 1 warning │" in text and "│ clean     │ done            │" in text


@pytest.mark.slow
def test_parquet_holds_the_csv_table(batch_run):
    _, out, _, _ = batch_run
    table = pq.read_table(out / "batch_summary.parquet").to_pylist()
    for from_parquet, from_csv in zip(table, read_rows(out), strict=True):
        assert from_parquet["recording"] == from_csv["recording"]
        assert from_parquet["gnss_epochs"] == (
            int(from_csv["gnss_epochs"]) if from_csv["gnss_epochs"] else None
        )
        scale = from_csv["final_wheel_scale"]
        assert from_parquet["final_wheel_scale"] == (float(scale) if scale else None)


@pytest.mark.slow
def test_outputs_are_those_of_vo_doppler_run(batch_run, tmp_path):
    drives, out, _, _ = batch_run
    alone = tmp_path / "run"
    assert main(["run", str(drives[0]), "-o", str(alone)]) == 0
    batch_files = {p.name for p in (out / "drive1").iterdir()}
    assert {p.name for p in alone.iterdir()} | {MARKER, "run.log"} == batch_files
    ours, theirs = (json.loads((d / "summary.json").read_text()) for d in (out / "drive1", alone))
    ours.pop("vo_fps"), theirs.pop("vo_fps")
    assert ours == theirs


@pytest.mark.slow
def test_resume_skips_finished_recordings(batch_run):
    drives, out, command, _ = batch_run
    markers = {d.name: (out / d.name / MARKER).stat().st_mtime_ns for d in drives}
    assert main([*command, "--resume"]) == 1
    rows = read_rows(out)
    assert [r["status"] for r in rows[:3]] == ["skipped", "skipped", "failed"]
    assert {d.name: (out / d.name / MARKER).stat().st_mtime_ns for d in drives} == markers


def test_no_recordings_is_a_usage_error_and_an_empty_list_bad_input(tmp_path, capsys):
    out = tmp_path / "out"
    with pytest.raises(SystemExit) as stop:
        main(["batch", "-o", str(out)])
    assert stop.value.code == 2
    assert "error: no recordings: give sequence folders or --list FILE" in capsys.readouterr().err
    listing = tmp_path / "empty.txt"
    listing.write_text("# nothing yet\n\n")
    assert main(["batch", "--list", str(listing), "-o", str(out)]) == 1
    message = f"{listing}: the list names no recording (only blank lines and comments)"
    assert message in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.slow
@pytest.mark.shared_data
def test_raw_comma2k19_segments_are_imported_then_run(tmp_path):
    segment = require_shared("comma2k19_example1")
    orbits = tmp_path / "orbits"
    orbits.mkdir()
    (orbits / "day.sp3").symlink_to(segment / "Sta20124_1400_1845.sp3")
    out = tmp_path / "out"
    command = ["batch", str(segment), "--comma2k19", str(orbits), "-o", str(out)]
    assert main(command) == 0
    with (out / "batch_summary.csv").open() as stream:
        row = next(csv.DictReader(stream))
    assert row["recording"] == "comma2k19_example1" and row["status"] == "done"
    assert abs(float(row["final_wheel_scale"]) - 1.0086) < 0.003  # global_pose: 1.0086
    prepared = out / "comma2k19_example1" / "prepared"
    assert (prepared / "sequence.yaml").is_file() and (prepared / "gnss" / "day.sp3").is_file()
    assert (
        main(["batch", str(segment), "--comma2k19", str(orbits), "-o", str(out), "--resume"]) == 0
    )
    with (out / "batch_summary.csv").open() as stream:
        assert next(csv.DictReader(stream))["status"] == "skipped"
