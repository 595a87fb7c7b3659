"""``--start`` / ``--end`` on ``run``, ``batch``, ``heading``, ``gnss`` and ``vo``: the results on
a span are those on the recording cut to it (as text, :mod:`tests.helpers.cut_recording`);
bounds outside the recording are usage errors (exit 2; in a batch, of that recording only), a
span without data a clear error (exit 1)."""

from __future__ import annotations

import csv
import json

import pytest

from tests.cli.conftest import SPAN_END_S, SPAN_START_S
from vo_doppler.cli import main

pytestmark = pytest.mark.xdist_group("span_drive")

TRAJECTORIES = (
    "trajectory_vo.tum",
    "trajectory_vo_gps_conv.tum",
    "trajectory_corrected.tum",
    "trajectory_dr.tum",
    "trajectory_dr_gps_conv.tum",
    "trajectory_dr_gps_tc.tum",
    "heading.csv",
)


def _span(drive) -> list[str]:
    """The span in both forms: seconds from the first epoch, and a GPS time."""
    return ["--start", f"{SPAN_START_S}", "--end", f"gps:{drive.end!r}"]


@pytest.fixture(scope="module")
def run_outputs(span_drive, span_cut_run, tmp_path_factory):
    """``run`` on the whole drive with the span, and on the cut drive."""
    out = tmp_path_factory.mktemp("span_runs") / "span"
    assert main(["-q", "run", str(span_drive.full), "-o", str(out), *_span(span_drive)]) == 0
    return out, span_cut_run


@pytest.mark.slow
def test_run_on_a_span_gives_the_run_on_the_recording_cut_to_it(run_outputs):
    span, cut = run_outputs
    for name in TRAJECTORIES:
        assert (span / name).read_bytes() == (cut / name).read_bytes(), name
    on_span, on_cut = (json.loads((o / "summary.json").read_text()) for o in run_outputs)
    assert on_span["evaluation"] == on_cut["evaluation"]
    for key in ("gnss_epochs", "tight_heading_used", "final_wheel_scale", "vo_frames"):
        assert on_span[key] == on_cut[key], key
    assert on_span["gnss_epochs"] == 8 * 20  # 20 Hz from 4.05 to 12.0 s
    assert on_span["span"]["start_from_first_epoch_s"] == pytest.approx(SPAN_START_S)
    assert on_span["span"]["end_from_first_epoch_s"] == pytest.approx(SPAN_END_S)
    assert "span" not in on_cut


@pytest.mark.slow
def test_batch_runs_each_recording_on_the_span_as_run_does(span_drive, run_outputs, tmp_path):
    """The whole drive gives run's outputs on the span; the cut drive, which ends before the
    span's end, fails with run's usage error (category usage-error) and the batch exits 2."""
    out = tmp_path / "batch"
    argv = ["-q", "batch", str(span_drive.full), str(span_drive.cut), "-o", str(out)]
    assert main([*argv, "--workers", "1", *_span(span_drive)]) == 2
    span = run_outputs[0]
    for name in TRAJECTORIES:
        assert (out / "full" / name).read_bytes() == (span / name).read_bytes(), name
    on_span, in_batch = (json.loads((o / "summary.json").read_text()) for o in (span, out / "full"))
    assert in_batch["span"] == on_span["span"]
    assert in_batch["evaluation"] == on_span["evaluation"]
    with (out / "batch_summary.csv").open() as stream:
        rows = {row["recording"]: row for row in csv.DictReader(stream)}
    assert rows["full"]["status"] == "done"
    assert rows["cut"]["status"] == "failed"
    assert rows["cut"]["exit_category"] == "usage-error"
    assert f"--end gps:{span_drive.end:.3f} lies outside the recording" in rows["cut"]["error"]
    assert "the recording's GNSS epochs run from gps:" in rows["cut"]["error"]


def _heading_argv(folder, output, *extra):
    return [
        "-q",
        "heading",
        str(folder / "gnss" / "rover.obs"),
        "--nav",
        str(folder / "gnss" / "brdc.nav"),
        "--yaw-rate-csv",
        str(folder / "vehicle" / "yaw_rate.csv"),
        "--speed-csv",
        str(folder / "vehicle" / "wheel_speed.csv"),
        "--gt",
        str(folder / "ground_truth.tum"),
        "-o",
        str(output),
        *extra,
    ]


@pytest.mark.slow
def test_heading_on_a_span_gives_the_heading_of_the_cut_recording(span_drive, tmp_path, capsys):
    assert main(_heading_argv(span_drive.full, tmp_path / "span.csv", *_span(span_drive))) == 0
    assert main(_heading_argv(span_drive.cut, tmp_path / "cut.csv")) == 0
    assert (tmp_path / "span.csv").read_bytes() == (tmp_path / "cut.csv").read_bytes()
    first, second = (json.loads(s) for s in capsys.readouterr().out.strip().splitlines()[-2:])
    assert first["epochs"] == second["epochs"] == 160
    for key in ("tc_available", "wheel_scale", "gyro_bias_dps", "calibration"):
        assert first[key] == second[key], key


@pytest.mark.parametrize("action", ["velocity", "spp"])
def test_gnss_on_a_span_gives_the_solutions_of_the_cut_recording(span_drive, tmp_path, action):
    for name, folder, extra in (
        ("span", span_drive.full, _span(span_drive)),
        ("cut", span_drive.cut, []),
    ):
        argv = ["-q", "gnss", action, str(folder / "gnss" / "rover.obs")]
        argv += ["--nav", str(folder / "gnss" / "brdc.nav"), "-o", str(tmp_path / f"{name}.csv")]
        assert main([*argv, *extra]) == 0
    assert (tmp_path / "span.csv").read_bytes() == (tmp_path / "cut.csv").read_bytes()


@pytest.mark.slow
def test_vo_on_a_span_gives_the_vo_of_the_cut_recording(span_drive, tmp_path):
    """``vo`` counts from its first image and reads GPS times in the image times' own base
    (times.txt from 0 s, 20 ms after the first GNSS epoch: no image between the two spans)."""
    bounds = ["--start", f"{SPAN_START_S}", "--end", f"gps:{SPAN_END_S}"]
    for name, folder, extra in (("span", span_drive.full, bounds), ("cut", span_drive.cut, [])):
        argv = ["-q", "vo", str(folder / "image_0"), "--calib", str(folder / "calib.yaml")]
        argv += ["--times", str(folder / "times.txt"), "-o", str(tmp_path / name)]
        assert main([*argv, *extra]) == 0
    for file in ("trajectory.tum", "trajectory.kitti"):
        assert (tmp_path / "span" / file).read_bytes() == (tmp_path / "cut" / file).read_bytes()
    assert len((tmp_path / "cut" / "trajectory.kitti").read_text().splitlines()) == 80


@pytest.mark.parametrize(
    ("bounds", "message"),
    [
        (["--start", "17"], "--start 17 s lies outside the recording"),
        (["--end", "gps:1"], "--end gps:1.000 lies outside the recording"),
        (["--start", "gps:1e9"], "--start gps:1000000000.000 lies outside the recording"),
        (["--start", "10", "--end", "gps:SPAN_FIRST_PLUS_5"], "is not before --end"),
    ],
)
def test_a_span_outside_the_recording_is_a_usage_error(
    span_drive, tmp_path, capsys, bounds, message
):
    bounds = [b.replace("SPAN_FIRST_PLUS_5", f"{span_drive.first + 5!r}") for b in bounds]
    argv = ["gnss", "velocity", str(span_drive.full / "gnss" / "rover.obs")]
    argv += ["--nav", str(span_drive.full / "gnss" / "brdc.nav"), "-o", str(tmp_path / "v.csv")]
    assert main([*argv, *bounds]) == 2
    err = capsys.readouterr().err
    assert "usage error" in err and message in err
    assert "the recording's observation epochs run from gps:" in err and "(0 to 16.000 s" in err
    assert not (tmp_path / "v.csv").exists()


@pytest.mark.parametrize(
    ("bounds", "message"),
    [
        (["--start", "10", "--end", "5"], "--start 10 s is not before --end 5 s"),
        (["--start", "gps:20", "--end", "gps:10"], "--start gps:20.000 is not before --end"),
        (["--start", "-3"], "seconds from the first epoch must be >= 0"),
        (["--end", "later"], "'later' is not a time: expected seconds from the recording's"),
        (["--end", "gps:nan"], "'gps:nan' is not a time"),
    ],
)
@pytest.mark.parametrize("command", ["run", "batch", "heading", "gnss", "vo"])
def test_bounds_wrong_alone_are_refused_before_reading(tmp_path, capsys, command, bounds, message):
    argv = {
        "run": ["run", str(tmp_path / "missing")],
        "batch": ["batch", str(tmp_path / "missing")],
        "heading": [
            "heading",
            "x.obs",
            "--nav",
            "x.nav",
            "--yaw-rate-csv",
            "y",
            "--speed-csv",
            "s",
        ],
        "gnss": ["gnss", "velocity", "x.obs", "--nav", "x.nav"],
        "vo": ["vo", str(tmp_path), "--calib", "c.yaml"],
    }[command]
    with pytest.raises(SystemExit) as exit_info:
        main([*argv, "-o", str(tmp_path / "out"), *bounds])
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err


def test_a_span_without_data_says_so(span_drive, tmp_path, capsys):
    """A span inside the recording that holds no GNSS epoch (a gap: the cut drive has none
    between its first and last epoch, so a span inside one 50-ms step) is an error naming it."""
    argv = ["gnss", "velocity", str(span_drive.cut / "gnss" / "rover.obs")]
    argv += ["--nav", str(span_drive.cut / "gnss" / "brdc.nav"), "-o", str(tmp_path / "v.csv")]
    assert main([*argv, "--start", "0.01", "--end", "0.04"]) == 1
    err = capsys.readouterr().err
    assert "holds no observation epochs: choose --start / --end around data" in err
