"""The batch runner (vo_doppler.batch): naming, fingerprints, completion markers, failure
isolation across worker processes, a killed batch resumed without recomputing what finished,
and the Ray executor giving the local executor's aggregate."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path

import pytest

from tests.helpers.batch import (
    BLOCK_DIR_ENV,
    die_or_fail,
    imageless_drive,
    opencv_thread_count,
    tiny_drive,
    wait_while_blocked,
)
from vo_doppler.batch import (
    FAILED_LOG,
    MARKER,
    Failure,
    Listing,
    Status,
    _pool,
    fingerprint,
    finished,
    opencv_threads,
    output_names,
    plan,
    process_recording,
    read_list,
    run_batch,
)
from vo_doppler.errors import InputError, OutputError
from vo_doppler.io.output_folder import MARKER as OUTPUT_MARKER
from vo_doppler.io.output_folder import RUN, mark_output, open_output_folder, written_by
from vo_doppler.model.time_span import SpanBound, TimeSpan
from vo_doppler.run import RunConfig
from vo_doppler.vo.config import VoConfig

REPO_ROOT = Path(__file__).resolve().parents[1]
LIVENESS_S = 600.0
"""Upper bound on waiting for a subprocess (a hang fails the test instead of the suite)."""


def test_output_names_use_as_many_path_components_as_make_them_unique(tmp_path):
    sources = [tmp_path / "r1" / "10", tmp_path / "r2" / "10", tmp_path / "r2" / "11"]
    assert output_names(sources) == ["r1__10", "r2__10", "r2__11"]
    assert output_names([tmp_path / "a", tmp_path / "b"]) == ["a", "b"]


def test_read_list_skips_comments_and_resolves_relative_paths(tmp_path):
    listing = tmp_path / "lists" / "drives.txt"
    listing.parent.mkdir()
    listing.write_text("# fleet\nd1\n\n  /abs/d2  # second\n")
    assert read_list(listing) == {
        listing.parent / "d1": Listing(listing, 2),
        Path("/abs/d2"): Listing(listing, 4),
    }
    with pytest.raises(InputError, match=r"missing\.txt"):
        read_list(tmp_path / "missing.txt")


def test_read_list_names_repeated_entries_and_keeps_the_first(tmp_path, caplog):
    listing = tmp_path / "drives.txt"
    listing.write_text("s1\nd2\n./s1\n# s1\ns1/\n")
    with caplog.at_level("WARNING", logger="vo_doppler.batch"):
        listed = read_list(listing)
    assert listed == {tmp_path / "s1": Listing(listing, 1), tmp_path / "d2": Listing(listing, 2)}
    assert caplog.messages == [
        f"{listing}: lines 1, 3, 5 name the same recording (s1, ./s1, s1/); it runs once"
    ]


def test_plan_names_the_spellings_of_one_recording_and_runs_it_once(tmp_path, caplog):
    (tmp_path / "s1").mkdir()
    given = [tmp_path / "s1", tmp_path / "s1" / ".." / "s1", tmp_path / "d2"]
    with caplog.at_level("WARNING", logger="vo_doppler.batch"):
        jobs = plan(given, tmp_path / "out", RunConfig())
    assert [job.source for job in jobs] == [tmp_path / "s1", tmp_path / "d2"]
    assert caplog.messages == [
        f"{tmp_path / 's1'}, {tmp_path / 's1' / '..' / 's1'} name the same recording; it runs once"
    ]


def test_a_missing_recording_fails_naming_where_it_is_listed(tmp_path):
    listing = tmp_path / "drives.txt"
    listing.write_text("# fleet\n\nnot_there\n")
    out = tmp_path / "out"
    (listed,) = plan(read_list(listing), out, RunConfig(), listings=read_list(listing))
    (given,) = plan([tmp_path / "gone"], out, RunConfig())
    outcomes = [process_recording(job) for job in (listed, given)]
    assert [(o.status, o.category) for o in outcomes] == [(Status.FAILED, Failure.INPUT)] * 2
    assert outcomes[0].error == (
        f"{listing}:3: the recording {tmp_path / 'not_there'} does not exist"
    )
    assert outcomes[1].error == f"{tmp_path / 'gone'}: the recording does not exist"
    assert not out.exists()


def test_fingerprint_follows_files_and_config(tmp_path):
    (tmp_path / "sub").mkdir()
    data = tmp_path / "sub" / "x.txt"
    data.write_text("1")
    config = RunConfig()
    first = fingerprint(tmp_path, config, None)
    assert fingerprint(tmp_path, RunConfig(), None) == first
    assert fingerprint(tmp_path, replace(config, vo=VoConfig(window_size=10)), None) != first
    assert fingerprint(tmp_path, config, die_or_fail) != first
    assert fingerprint(tmp_path, config, None, TimeSpan()) == first
    span = TimeSpan(SpanBound(2.0), SpanBound(9.0))
    assert fingerprint(tmp_path, config, None, span) != first
    later = TimeSpan(SpanBound(2.0), SpanBound(9.5))
    assert fingerprint(tmp_path, config, None, later) != fingerprint(tmp_path, config, None, span)
    data.write_text("22")
    assert fingerprint(tmp_path, config, None) != first


def test_a_marker_counts_only_with_its_fingerprint_and_outputs(tmp_path):
    (job,) = plan([tmp_path / "rec"], tmp_path / "out", RunConfig())
    job.out.mkdir(parents=True)
    (job.out / "summary.json").write_text("{}")
    marker = {"fingerprint": job.fingerprint, "outputs": ["summary.json"], "seconds": 1.0}
    (job.out / MARKER).write_text(json.dumps(marker))
    assert finished(job) == marker
    (job.out / MARKER).write_text(json.dumps({**marker, "fingerprint": "other"}))
    assert finished(job) is None
    (job.out / MARKER).write_text(json.dumps(marker))
    assert finished(job) == marker
    (job.out / FAILED_LOG).write_text("the last run failed")
    assert finished(job) is None
    (job.out / FAILED_LOG).unlink()
    (job.out / "summary.json").unlink()
    assert finished(job) is None


@pytest.mark.slow
def test_failures_stay_with_their_recording(tmp_path):
    """A worker that dies fails only its own recording (the others lost with the pool run
    again alone); a plain exception is an internal error; bad input an input error."""
    sources = [tmp_path / name for name in ("crash", "bug", "not_a_sequence", "empty")]
    for source in sources:
        source.mkdir()
    result = run_batch(sources, tmp_path / "out", workers=2, prepare=die_or_fail)
    categories = {o.name: o.category for o in result.outcomes}
    assert categories == {
        "crash": Failure.WORKER_LOST,
        "bug": Failure.INTERNAL,
        "not_a_sequence": Failure.INPUT,
        "empty": Failure.INPUT,
    }
    assert "RuntimeError: bug in the importer of bug" in result.outcomes[1].error
    assert "sequence.yaml" in result.outcomes[2].error
    assert result.exit_code == 1
    assert "Traceback" in (tmp_path / "out" / "bug" / "run.log").read_text()
    assert not any((tmp_path / "out" / s.name / MARKER).exists() for s in sources)


@pytest.mark.slow
def test_a_rerun_leaves_no_stale_output_beside_the_new_ones(tmp_path):
    source = tmp_path / "bug"
    source.mkdir()
    stale = tmp_path / "out" / "bug" / "trajectories.png"
    stale.parent.mkdir(parents=True)
    stale.write_bytes(b"from an earlier run")
    mark_output(stale.parent, RUN)
    result = run_batch([source], tmp_path / "out", workers=1, prepare=die_or_fail)
    assert result.outcomes[0].category is Failure.INTERNAL
    assert sorted(p.name for p in stale.parent.iterdir()) == [OUTPUT_MARKER, "run.log"]
    assert written_by(stale.parent, RUN) == (True, [])


def test_a_batch_never_replaces_a_recording_or_a_folder_it_did_not_write(tmp_path, monkeypatch):
    """Every refusal comes before any work, with nothing touched: the output folder holding
    the recording (OUT/<name> would be the recording itself), one holding files of someone
    else's, a recording's folder with someone else's files, a recording's folder that is not
    a batch's, and the current directory as a recording's folder."""
    recording = tmp_path / "data" / "drive"
    recording.mkdir(parents=True)
    (recording / "sequence.yaml").write_text("precious")
    with pytest.raises(OutputError, match=r"contains the input .*drive"):
        run_batch([recording], recording.parent, workers=1, prepare=die_or_fail)
    out = tmp_path / "out"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match="not empty and was not written by 'vo-doppler batch'"):
        run_batch([recording], out, workers=1, prepare=die_or_fail)
    (out / "notes.txt").unlink()
    open_output_folder(out, "batch")
    (out / "drive").mkdir()
    (out / "drive" / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match=r"out/drive: .*not written by 'vo-doppler run' or"):
        run_batch([recording], out, workers=1, prepare=die_or_fail)
    mark_output(out / "drive", RUN)
    (out / "drive" / "later.txt").write_text("added after the run")
    with pytest.raises(OutputError, match=r"did not write \(later\.txt\)"):
        run_batch([recording], out, workers=1, prepare=die_or_fail)
    monkeypatch.chdir(out / "drive")
    (out / "drive" / "later.txt").unlink()
    with pytest.raises(OutputError, match="the current directory"):
        run_batch([recording], out, workers=1, prepare=die_or_fail)
    assert (recording / "sequence.yaml").read_text() == "precious"
    assert sorted(p.name for p in (out / "drive").iterdir()) == [OUTPUT_MARKER, "notes.txt"]
    assert sorted(p.name for p in out.iterdir()) == [OUTPUT_MARKER, "drive"]


@pytest.mark.slow
def test_a_rerun_that_fails_before_its_outputs_keeps_the_earlier_results(
    tmp_path_factory, tmp_path
):
    """A recording that succeeded, then fails (its RINEX cut short): the failure is listed, the
    earlier results stay as they were with the failed run's log beside them, and no staging
    folder is left. With the RINEX restored as it was (the first run's fingerprint again),
    ``resume`` runs the recording again instead of listing as skipped the results beside the
    failed run's log, and the log goes."""
    drive = tmp_path / "drive"
    shutil.copytree(imageless_drive(tmp_path_factory, 1), drive)
    out = tmp_path / "out"
    assert run_batch([drive], out, workers=1).outcomes[0].status is Status.DONE
    earlier = _mtimes(out / "drive")
    obs = drive / "gnss" / "rover.obs"
    original, original_stat = obs.read_text(), obs.stat()
    obs.write_text(original[:1000])
    result = run_batch([drive], out, workers=1)
    (outcome,) = result.outcomes
    assert (outcome.status, outcome.category) == (Status.FAILED, Failure.INPUT)
    assert outcome.error == (
        f"{obs}: no 'END OF HEADER' record: not a RINEX file or truncated header (the earlier "
        f"results in {out / 'drive'} are kept; this run's log is {FAILED_LOG})"
    )
    assert [r["status"] for r in result.rows] == ["failed", "1 failed"]
    now = _mtimes(out / "drive")
    assert now.keys() - earlier.keys() == {FAILED_LOG}
    del now[FAILED_LOG], now[OUTPUT_MARKER], earlier[OUTPUT_MARKER]
    assert now == earlier
    assert "END OF HEADER" in (out / "drive" / FAILED_LOG).read_text()
    assert written_by(out / "drive", RUN) == (True, [])
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == [OUTPUT_MARKER]
    obs.write_text(original)
    os.utime(obs, ns=(original_stat.st_atime_ns, original_stat.st_mtime_ns))
    (job,) = plan([drive], out, RunConfig())
    assert json.loads((out / "drive" / MARKER).read_text())["fingerprint"] == job.fingerprint
    resumed = run_batch([drive], out, workers=1, resume=True)
    assert [r["status"] for r in resumed.rows] == ["done", "1 done"]
    assert not (out / "drive" / FAILED_LOG).exists()
    assert finished(job) is not None


def test_an_output_that_is_a_file_fails_before_any_work(tmp_path):
    out = tmp_path / "out"
    out.write_text("a file")
    with pytest.raises(OutputError, match="exists and is not a folder"):
        run_batch([tmp_path], out, workers=1, prepare=die_or_fail)
    assert out.read_text() == "a file"


def _mtimes(folder: Path) -> dict[str, int]:
    return {p.name: p.stat().st_mtime_ns for p in folder.iterdir()}


def _wait_for(path: Path, process: subprocess.Popen) -> None:
    deadline = time.monotonic() + LIVENESS_S
    while not path.exists():
        assert process.poll() is None, f"the batch ended early ({process.returncode})"
        assert time.monotonic() < deadline, f"{path} did not appear"
        time.sleep(0.1)


def _start_batch(drives, out, block_dir) -> subprocess.Popen:
    script = (
        "import sys; from pathlib import Path; from vo_doppler.batch import run_batch; "
        "from tests.helpers.batch import wait_while_blocked; "
        "run_batch([Path(p) for p in sys.argv[2:]], Path(sys.argv[1]), workers=1, "
        "prepare=wait_while_blocked)"
    )
    return subprocess.Popen(
        [sys.executable, "-c", script, str(out), *map(str, drives)],
        cwd=REPO_ROOT,
        env={**os.environ, BLOCK_DIR_ENV: str(block_dir)},
        start_new_session=True,
    )


@pytest.mark.slow
def test_killed_batch_resumes_without_recomputing_finished_recordings(
    tmp_path_factory, tmp_path, monkeypatch
):
    """Kill the whole batch (SIGKILL to its process group: parent and workers) while the
    second of three recordings is running; resuming recomputes the second and third only."""
    drives = [imageless_drive(tmp_path_factory, seed) for seed in (1, 2, 3)]
    out, block_dir = tmp_path / "out", tmp_path / "block"
    block_dir.mkdir()
    for drive in drives[1:]:
        (block_dir / drive.name).touch()
    process = _start_batch(drives, out, block_dir)
    try:
        _wait_for(out / drives[0].name / MARKER, process)
        _wait_for(block_dir / f"{drives[1].name}.pid", process)
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait(LIVENESS_S)
    first = _mtimes(out / drives[0].name)
    assert not (out / drives[1].name / MARKER).exists()
    for drive in drives[1:]:
        (block_dir / drive.name).unlink()
    monkeypatch.setenv(BLOCK_DIR_ENV, str(block_dir))
    result = run_batch(drives, out, workers=1, resume=True, prepare=wait_while_blocked)
    assert [o.status for o in result.outcomes] == [Status.SKIPPED, Status.DONE, Status.DONE]
    assert _mtimes(out / drives[0].name) == first
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == [OUTPUT_MARKER]
    assert all((out / d.name / MARKER).exists() for d in drives)
    assert result.rows[0]["gnss_epochs"] == result.rows[1]["gnss_epochs"] > 0


@pytest.mark.slow
def test_terminated_batch_ends_its_workers(tmp_path):
    """SIGTERM to the batch (not its workers): it exits and its worker does not live on."""
    source, block_dir = tmp_path / "rec", tmp_path / "block"
    source.mkdir()
    block_dir.mkdir()
    (block_dir / "rec").touch()
    process = _start_batch([source], tmp_path / "out", block_dir)
    try:
        _wait_for(block_dir / "rec.pid", process)
        worker = int((block_dir / "rec.pid").read_text())
        process.send_signal(signal.SIGTERM)
        assert process.wait(LIVENESS_S) != 0
        deadline = time.monotonic() + LIVENESS_S
        while _alive(worker):
            assert time.monotonic() < deadline, "the worker outlived the batch"
            time.sleep(0.1)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return not Path(f"/proc/{pid}/stat").read_text().split(") ")[-1].startswith("Z")


@pytest.mark.slow
@pytest.mark.xdist_group("tiny_drives")
def test_ray_executor_gives_the_local_aggregate(tmp_path_factory, tmp_path):
    """One worker each (a local Ray instance of 1 CPU: its start costs the same whatever the
    work): the second recording waits for the first's task to end, as a larger batch would."""
    drives = [tiny_drive(tmp_path_factory, seed) for seed in (1, 2)]
    local = run_batch(drives, tmp_path / "local", workers=1)
    remote = run_batch(drives, tmp_path / "ray", executor="ray", workers=1)
    assert [o.status for o in remote.outcomes] == [Status.DONE, Status.DONE]
    drop = {"seconds"}
    assert [{k: v for k, v in row.items() if k not in drop} for row in remote.rows] == [
        {k: v for k, v in row.items() if k not in drop} for row in local.rows
    ]
    assert remote.rows[0]["vo_gps_tc_error_per_100m_m"] > 0


@pytest.mark.parametrize(
    ("cores", "workers", "threads"), [(8, 2, 4), (8, 3, 2), (2, 4, 1), (1, 1, 1)]
)
def test_opencv_threads_share_out_the_cores(monkeypatch, cores, workers, threads):
    monkeypatch.setattr(os, "cpu_count", lambda: cores)
    assert opencv_threads(workers) == threads


@pytest.mark.slow
def test_pool_workers_run_opencv_with_their_share_of_threads():
    with _pool(2) as pool:
        counts = set(pool.map(opencv_thread_count, range(4)))
    assert counts == {opencv_threads(2)}
