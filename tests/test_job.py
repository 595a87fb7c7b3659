"""One recording's job as ``run`` and ``batch`` share it: the sequence read, run inside the
caller's context, every output written where the caller says, nothing left frozen; and the
verdict on a drive without any tightly coupled heading, saying plainly when the vehicle never
moved."""

from __future__ import annotations

import dataclasses
import gc
import json
import subprocess
import sys
from contextlib import contextmanager, nullcontext

import numpy as np
import pytest

from vo_doppler import job as job_module
from vo_doppler.errors import InputError
from vo_doppler.io.sequence import read_sequence
from vo_doppler.job import require_tight_heading, run_recording
from vo_doppler.model.time_span import SpanBound, TimeSpan, trim_sequence
from vo_doppler.report.run_outputs import SUMMARY_FILE
from vo_doppler.run import RunConfig

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def job_run(turning_drive_folder, tmp_path_factory):
    """The 20-s turning drive's job into a folder of its own, and the sequences the context
    around the run was entered with."""
    out = tmp_path_factory.mktemp("job")
    entered = []

    @contextmanager
    def running(sequence):
        entered.append(sequence)
        yield None

    output = run_recording(
        turning_drive_folder, RunConfig(), lambda: nullcontext(out), running=running
    )
    return output, out, entered


@pytest.fixture(scope="module")
def job(job_run):
    return job_run[0]


def test_the_job_writes_every_output_where_the_caller_says(job_run):
    output, out, entered = job_run
    assert entered == [output.sequence] and output.sequence.name == "s1"
    assert json.loads((out / SUMMARY_FILE).read_text()) == json.loads(json.dumps(output.summary))
    for name in ("trajectory_dr_gps_tc.tum", "trajectory_dr.tum", "heading.csv", "report.html"):
        assert (out / name).stat().st_size > 0, name
    assert set(output.result.trajectories) == {"dr", "dr_gps_conv", "dr_gps_tc"}
    assert "span" not in output.summary  # the whole recording
    assert gc.get_freeze_count() == 0


def _without_heading(result, wheel_factor: float, gnss_factor: float):
    """``result`` with no tightly coupled heading, its wheel and GNSS speeds scaled."""
    gnss = result.gnss
    velocity = dataclasses.replace(
        gnss.velocity, velocity_enu=gnss.velocity.velocity_enu * gnss_factor
    )
    speed = result.calibrated_speed
    return dataclasses.replace(
        result,
        heading=dataclasses.replace(result.heading, yaw_tc=np.full(len(result.heading), np.nan)),
        calibrated_speed=dataclasses.replace(speed, value=speed.value * wheel_factor),
        gnss=dataclasses.replace(gnss, velocity=velocity),
    )


def test_a_parked_car_fails_saying_it_never_moved(job, tmp_path):
    result = job.result
    peak_gnss = np.nanmax(np.hypot(*result.gnss.velocity.velocity_enu[:, :2].T))
    parked = _without_heading(result, 0.0, 0.4 / peak_gnss)
    with pytest.raises(InputError) as raised:
        require_tight_heading(parked, tmp_path / "seq", tmp_path / "out")
    message = str(raised.value)
    assert message.startswith(f"{tmp_path / 'seq'}: the vehicle never moved: the wheel speed ")
    assert "below 0.2 m/s throughout (at most 0.00)" in message
    assert "GNSS Doppler speed below 0.5 m/s at every valid epoch" in message
    assert message.endswith(
        f"so no Doppler heading exists (the other results are in {tmp_path / 'out'})"
    )


def test_wheels_still_while_gnss_moves_and_a_moving_drive_keep_their_own_messages(job, tmp_path):
    result = job.result
    with pytest.raises(
        InputError, match=r"the wheels never moved: .* while the GNSS Doppler speed reaches"
    ):
        require_tight_heading(_without_heading(result, 0.0, 1.0), tmp_path, tmp_path)
    with pytest.raises(InputError, match="unavailable at every epoch") as raised:
        require_tight_heading(_without_heading(result, 1.0, 1.0), tmp_path, tmp_path)
    assert "never moved" not in str(raised.value)
    require_tight_heading(result, tmp_path, tmp_path)


def _same_poses(got, expected) -> None:
    np.testing.assert_array_equal(got.t, expected.t)
    np.testing.assert_array_equal(got.positions, expected.positions)
    np.testing.assert_array_equal(got.orientations.as_quat(), expected.orientations.as_quat())


def test_the_ground_truth_left_out_of_the_run_is_back_for_the_outputs(job, turning_drive_folder):
    truth = read_sequence(turning_drive_folder).truth
    assert len(truth) > 1000
    _same_poses(job.sequence.truth, truth)
    assert "evaluation" in job.summary


def test_a_cut_runs_ground_truth_is_cut_as_the_sequence_read_and_cut_here(
    turning_drive_folder, tmp_path
):
    span = TimeSpan(SpanBound(4.0), SpanBound(12.0))
    output = run_recording(turning_drive_folder, RunConfig(), lambda: nullcontext(tmp_path), span)
    expected, _ = trim_sequence(read_sequence(turning_drive_folder), span)
    _same_poses(output.sequence.truth, expected.truth)
    assert 0 < len(expected.truth) < len(read_sequence(turning_drive_folder).truth)
    cut = output.summary["span"]
    assert (cut["start_from_first_epoch_s"], cut["end_from_first_epoch_s"]) == pytest.approx(
        (4.0, 12.0), abs=1e-6
    )


def test_the_jobs_process_reads_no_can_log_itself(turning_drive_folder, tmp_path):
    """The sequence is read in a child process: python-can and cantools (8 MiB) load there,
    not in the process that runs the job and holds its results."""
    code = (
        "import sys\nfrom contextlib import nullcontext\nfrom pathlib import Path\n"
        "from vo_doppler.job import run_recording\nfrom vo_doppler.run import RunConfig\n"
        f"output = run_recording(Path({str(turning_drive_folder)!r}), RunConfig(), "
        f"lambda: nullcontext(Path({str(tmp_path)!r})))\n"
        "print(output.sequence.vehicle_source.sensor, len(output.sequence.wheel_speed), "
        "'cantools' in sys.modules, 'can' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    sensor, samples, cantools_loaded, can_loaded = done.stdout.split()
    assert (sensor, cantools_loaded, can_loaded) == ("CAN", "False", "False")
    assert int(samples) > 100


def test_a_ground_truth_gone_by_the_outputs_costs_the_evaluation_not_the_run(
    turning_drive_folder, tmp_path, monkeypatch
):
    """The truth is read again after the run: a file changed or gone since is a warning, and
    every other output is written."""

    def gone(folder, allow_outside=False):
        raise InputError("no such file", turning_drive_folder / "ground_truth.tum")

    monkeypatch.setattr(job_module, "read_ground_truth", gone)
    output = run_recording(turning_drive_folder, RunConfig(), lambda: nullcontext(tmp_path))
    assert output.sequence.truth is None and "evaluation" not in output.summary
    said = [text for text in output.summary["warnings"] if "ground truth" in text]
    assert said == [
        f"the ground truth could not be read again for the outputs "
        f"({turning_drive_folder / 'ground_truth.tum'}: no such file): no evaluation"
    ]
    assert (tmp_path / "trajectory_dr_gps_tc.tum").stat().st_size > 0
