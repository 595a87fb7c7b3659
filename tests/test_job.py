"""One recording's job as ``run`` and ``batch`` share it: the sequence read, run inside the
caller's context, every output written where the caller says, nothing left frozen; and the
verdict on a drive without any tightly coupled heading, saying plainly when the vehicle never
moved."""

from __future__ import annotations

import dataclasses
import gc
import json
from contextlib import contextmanager, nullcontext

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.job import require_tight_heading, run_recording
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
