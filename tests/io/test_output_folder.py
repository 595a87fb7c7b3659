"""Output folders written all at once, and never a folder whose content vo-doppler did not
write."""

from __future__ import annotations

import json
import os
import socket
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.helpers.staging import cut_off_staging
from vo_doppler.errors import OutputError
from vo_doppler.io.output_folder import (
    MARKER,
    RUN,
    STAGING_OWNER,
    _boot_id,
    _this_process,
    begin_staging,
    check_output_folder,
    mark_output,
    open_output_folder,
    remove_cut_off_staging,
    staged_output,
    untouched,
    write_files,
    written_by,
)

BATCH_LOG = "2026-11-24 09:00:00,123 INFO vo_doppler.batch: the recording started\n"
IMPORTED = "source: comma2k19 segment /data/seg (vo-doppler import comma2k19)\n"


def earlier_run(folder, *names):
    """A folder as an earlier ``run`` left it: ``names`` and the marker listing them."""
    folder.mkdir(parents=True)
    for name in names:
        (folder / name).write_text("old")
    mark_output(folder, RUN)
    return folder


def test_a_file_is_refused(tmp_path):
    target = tmp_path / "out"
    target.write_text("x")
    with pytest.raises(OutputError, match="the output exists and is not a folder"):
        check_output_folder(target, RUN)
    with pytest.raises(OutputError, match="is not a folder"):
        check_output_folder(target / "below", RUN)


def test_success_replaces_the_previous_folder_without_stale_files(tmp_path):
    out = earlier_run(tmp_path / "out", "stale.png")
    with staged_output(out, RUN) as staging:
        assert staging.parent == out.parent and staging != out
        (staging / "new.txt").write_text("new")
        assert (out / "stale.png").exists()  # the old results stay until the end
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "new.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    marker = json.loads((out / MARKER).read_text())
    assert marker == {"format": "vo-doppler-output/1", "command": "run", "entries": ["new.txt"]}


def test_failure_leaves_the_previous_folder_and_no_staging(tmp_path):
    out = earlier_run(tmp_path / "out", "old.txt")
    with pytest.raises(RuntimeError), staged_output(out, RUN) as staging:
        (staging / "half.txt").write_text("half")
        raise RuntimeError
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "old.txt"]
    assert untouched(out) == f"nothing written: {out} left as it was"
    assert untouched(tmp_path / "new") == f"nothing written: {tmp_path / 'new'} not created"


@pytest.mark.parametrize(
    ("umask", "mode"), [(0o022, 0o755), (0o027, 0o750), (0o002, 0o775)], ids=oct
)
def test_a_staged_folder_has_the_mode_mkdir_gives(tmp_path, umask, mode):
    """Others may read the results as the umask allows (mkdtemp made every run's folder 0700)."""
    previous = os.umask(umask)
    try:
        with staged_output(tmp_path / "out", RUN) as staging:
            (staging / "x").write_text("1")
        earlier_run(tmp_path / "again", "old.txt").chmod(0o700)
        with staged_output(tmp_path / "again", RUN) as staging:
            (staging / "x").write_text("1")
    finally:
        os.umask(previous)
    for out in (tmp_path / "out", tmp_path / "again"):
        assert stat.S_IMODE(out.stat().st_mode) == mode


def test_cut_off_staging_folders_of_one_output_are_removed(tmp_path):
    """A caller writing the output alone (a batch's recording) removes every staging folder of
    that output, owned or not; others only those whose owner has ended (none here)."""
    mine = [tmp_path / ".out.partial-1234abcd", tmp_path / ".out.partial-x"]
    others = [tmp_path / ".out2.partial-1", tmp_path / ".out.old-1", tmp_path / "out"]
    for folder in mine + others:
        folder.mkdir()
        (folder / "half.png").write_text("half")
    (tmp_path / ".out.partial-file").write_text("not a folder")
    remove_cut_off_staging(tmp_path / "out")
    assert all(folder.is_dir() for folder in mine)
    remove_cut_off_staging(tmp_path / "out", alone=True)
    left = {p.name for p in tmp_path.iterdir()}
    assert left == {p.name for p in others} | {".out.partial-file"}


def owned_staging(tmp_path: Path, name: str, **owner) -> Path:
    """A staging folder of ``tmp_path/out`` whose owner file says ``owner`` over this
    process's own record."""
    folder = tmp_path / f".out.partial-{name}"
    folder.mkdir()
    record = {**_this_process(), **owner}
    (folder / STAGING_OWNER).write_text(json.dumps(record))
    return folder


def test_only_staging_folders_whose_owner_has_ended_are_removed(tmp_path):
    """A run killed before its swap left its staging folder: the next run into the same output
    removes it, and leaves the one of a run still writing, of another host, of a process that
    cannot be checked, or without an owner file (older versions, or created a moment ago)."""
    dead = cut_off_staging(tmp_path / "out")
    assert json.loads((dead / STAGING_OWNER).read_text())["host"] == socket.gethostname()
    live = begin_staging(tmp_path / "out", RUN)
    kept = [
        live,
        owned_staging(tmp_path, "host", host="another-host", pid=1 << 22),
        owned_staging(tmp_path, "pid", pid="12"),
        owned_staging(tmp_path, "unknown"),
    ]
    (kept[-1] / STAGING_OWNER).unlink()
    gone = [dead]
    if _boot_id() is not None:
        gone += [
            owned_staging(tmp_path, "boot", boot_id="an earlier boot"),
            owned_staging(tmp_path, "reused", start="1"),  # this PID, another process
        ]
    remove_cut_off_staging(tmp_path / "out")
    assert [folder.is_dir() for folder in kept] == [True] * len(kept)
    assert [folder.exists() for folder in gone] == [False] * len(gone)
    assert (live / STAGING_OWNER).is_file()


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs /proc")
def test_a_zombie_owner_has_ended(tmp_path):
    """A killed run its parent has not reaped yet still has its PID: it counts as ended."""
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    try:
        deadline = time.monotonic() + 60
        while Path(f"/proc/{child.pid}/stat").read_text().rpartition(")")[2].split()[0] != "Z":
            assert time.monotonic() < deadline
            time.sleep(0.01)
        zombie = owned_staging(tmp_path, "zombie", pid=child.pid, start=None)
        remove_cut_off_staging(tmp_path / "out")
        assert not zombie.exists()
    finally:
        child.wait()


def test_a_run_removes_a_killed_runs_staging_and_swaps_in_without_its_owner_file(tmp_path):
    """What ``run`` does (staged_output): the killed run's staging folder goes, a concurrent
    live run's stays, and the owner file is not among the results."""
    out = earlier_run(tmp_path / "out", "old.txt")
    dead = cut_off_staging(out)
    live = begin_staging(out, RUN)
    with staged_output(out, RUN) as staging:
        assert (staging / STAGING_OWNER).is_file()
        assert not dead.exists()
        (staging / "new.txt").write_text("new")
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "new.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([live.name, "out"])


def test_nested_new_folder_is_created(tmp_path):
    out = tmp_path / "a" / "b"
    with staged_output(out, RUN) as staging:
        (staging / "x").write_text("1")
    assert (out / "x").read_text() == "1"


def test_an_empty_folder_is_accepted_and_a_foreign_one_refused_untouched(tmp_path):
    (tmp_path / "empty").mkdir()
    assert check_output_folder(tmp_path / "empty", RUN, replace=True) == tmp_path / "empty"
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("precious")
    for replace in (False, True):
        with pytest.raises(OutputError, match="other: the output folder is not empty and was not"):
            check_output_folder(other, RUN, replace=replace)
    with pytest.raises(OutputError, match="not written by"), staged_output(other, RUN):
        pytest.fail("the body must not run")
    assert [p.name for p in other.iterdir()] == ["notes.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["empty", "other"]


def test_an_entry_added_after_the_run_makes_replacing_refused(tmp_path):
    out = earlier_run(tmp_path / "out", "summary.json")
    (out / "notes.txt").write_text("mine")
    assert written_by(out, RUN) == (True, ["notes.txt"])
    with pytest.raises(OutputError, match=r"did not write \(notes\.txt\), which replacing"):
        check_output_folder(out, RUN, replace=True)
    check_output_folder(out, RUN)  # writing in place deletes nothing


def test_another_commands_folder_is_refused(tmp_path):
    sequence = open_output_folder(tmp_path / "sim", "simulate")
    (sequence / "sequence.yaml").write_text("format: vo-doppler-sequence/1\n")
    assert written_by(sequence, "simulate") == (True, [])
    assert written_by(sequence, RUN) == (False, [])
    with pytest.raises(OutputError, match="not written by 'vo-doppler run' or 'vo-doppler batch'"):
        check_output_folder(sequence, RUN, replace=True)
    check_output_folder(sequence, "simulate")


def test_the_inputs_and_what_holds_them_are_refused(tmp_path):
    recording = tmp_path / "par" / "seq"
    (recording / "gnss").mkdir(parents=True)
    obs = recording / "gnss" / "rover.obs"
    obs.write_text("o")
    inputs = [recording, obs, None]
    for output, relation in ((recording, "is"), (tmp_path / "par", "contains")):
        with pytest.raises(OutputError, match=f"the output folder {relation} the input "):
            check_output_folder(output, RUN, inputs)
    with pytest.raises(OutputError, match=r"contains the input .*rover\.obs"):
        check_output_folder(recording / "gnss", RUN, [obs])
    with pytest.raises(OutputError, match=r"out: the output folder is inside the input folder"):
        check_output_folder(recording / "out", RUN, inputs)
    assert check_output_folder(tmp_path / "out", RUN, inputs) == tmp_path / "out"
    assert check_output_folder(recording / "gnss" / "out", RUN, [obs]) == recording / "gnss" / "out"
    link = tmp_path / "link"
    link.symlink_to(recording, target_is_directory=True)
    with pytest.raises(OutputError, match="the output folder is the input"):
        check_output_folder(link, RUN, inputs)


def test_the_current_directory_and_its_parents_are_never_replaced(tmp_path, monkeypatch):
    here = tmp_path / "a" / "here"
    here.mkdir(parents=True)
    monkeypatch.chdir(here)
    for output in (".", "..", here, tmp_path):
        with pytest.raises(OutputError, match="the current directory or contains it"):
            check_output_folder(output, RUN, replace=True)
    assert check_output_folder(".", "vo") == Path(".")  # in place: empty is fine


@pytest.mark.parametrize(
    ("files", "folders", "replaceable"),
    [
        (
            {
                "summary.json": {
                    "gnss_epochs": 1,
                    "tight_heading_availability": 0.5,
                    "final_wheel_scale": 1.0,
                },
                "heading.png": None,
            },
            (),
            True,
        ),
        (
            {"batch_done.json": {"fingerprint": "f", "outputs": []}, "run.log": BATCH_LOG},
            ["prepared"],
            True,
        ),
        ({"run.log": BATCH_LOG}, (), True),
        ({"run.log": "my own notes\n"}, (), False),
        ({"summary.json": {"gnss_epochs": 1}, "heading.png": None}, (), False),
        (
            {
                "summary.json": {
                    "gnss_epochs": 1,
                    "tight_heading_availability": 0.5,
                    "final_wheel_scale": 1.0,
                },
                "notes.txt": None,
            },
            (),
            False,
        ),
        ({"run.log": BATCH_LOG}, ["gnss"], False),
        ({"run.log": BATCH_LOG, "sequence.yaml": None}, (), False),
        (
            {
                "summary.json": {
                    "gnss_epochs": 1,
                    "tight_heading_availability": 0.5,
                    "final_wheel_scale": 1.0,
                }
            },
            ["prepared:mine"],
            False,
        ),
    ],
)
def test_an_unmarked_earlier_run_is_recognised_by_its_own_files(
    tmp_path, files, folders, replaceable
):
    out = tmp_path / "out"
    out.mkdir()
    for name, content in files.items():
        text = content if isinstance(content, str) else json.dumps(content)
        (out / name).write_text("x" if content is None else text)
    for name in folders:
        name, _, mine = name.partition(":")
        (out / name).mkdir()
        if name == "prepared":  # a batch's imported sequence, or (":mine") a user's files
            (out / name / ("notes.txt" if mine else "sequence.yaml")).write_text(IMPORTED)
    assert written_by(out, RUN) == (replaceable, [])


def test_links_and_dotted_paths_are_checked_as_what_they_are(tmp_path):
    """A link to nothing is refused before any work (a folder command failed at its very end,
    exit 3); a link to an earlier run is refused where the folder is replaced as a whole (the
    link was replaced by a plain folder, an '.old' link left behind); ``out/y/..`` is ``out``
    (staging created ``out/y`` and then refused its own folder)."""
    dangling = tmp_path / "dangling"
    dangling.symlink_to(tmp_path / "nowhere")
    for command, replace in ((RUN, True), ("vo", False), ("simulate", False)):
        with pytest.raises(OutputError, match="a symbolic link to nothing"):
            check_output_folder(dangling, command, replace=replace)
    out = earlier_run(tmp_path / "out", "summary.json")
    link = tmp_path / "link"
    link.symlink_to(out)
    with pytest.raises(OutputError, match="a symbolic link, and the output folder is replaced"):
        check_output_folder(link, RUN, replace=True)
    empty = tmp_path / "empty"
    empty.mkdir()
    (tmp_path / "to_empty").symlink_to(empty)
    # written into in place, a link's target is the folder
    assert check_output_folder(tmp_path / "to_empty", "vo") == tmp_path / "to_empty"
    (out / "notes.txt").write_text("mine")
    with pytest.raises(OutputError, match="the output folder holds what"):
        check_output_folder(out / "y" / "..", RUN, replace=True)  # refused before any work
    (out / "notes.txt").unlink()
    with staged_output(out / "y" / "..", RUN) as staging:
        (staging / "summary.json").write_text("new")
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "summary.json"]
    assert (out / "summary.json").read_text() == "new"


def test_the_in_place_commands_are_recognised_by_their_own_files(tmp_path):
    vo = tmp_path / "vo"
    vo.mkdir()
    (vo / "vo_stats.json").write_text('{"metric_scale": true}')
    assert written_by(vo, "vo") == (True, [])
    assert written_by(vo, "deadreckon") == (False, [])
    imported = tmp_path / "imported"
    imported.mkdir()
    (imported / "sequence.yaml").write_text(
        "format: vo-doppler-sequence/1\nsource: comma2k19 segment s (vo-doppler import comma2k19)\n"
    )
    assert written_by(imported, "import") == (True, [])
    assert written_by(imported, "simulate") == (False, [])


def test_a_folder_filled_meanwhile_is_not_replaced_at_the_end(tmp_path):
    out = tmp_path / "out"
    with pytest.raises(OutputError, match="not written by"), staged_output(out, RUN) as staging:
        (staging / "result.txt").write_text("new")
        out.mkdir()
        (out / "notes.txt").write_text("someone else's")
    assert [p.name for p in out.iterdir()] == ["notes.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_a_batch_cut_off_before_its_aggregate_is_recognised_by_its_recordings(tmp_path):
    out = tmp_path / "out"
    earlier_run(out / "drive1", "summary.json")
    assert written_by(out, "batch") == (True, [])
    (out / "drive2").mkdir()
    assert written_by(out, "batch") == (False, [])
    (out / "drive2").rmdir()
    (out / "batch_summary.csv").write_text("recording\n")
    (out / "notes").mkdir()
    assert written_by(out, "batch") == (True, [])


def test_write_files_moves_every_file_in_only_once_all_are_written(tmp_path):
    earlier = tmp_path / "a.csv"
    earlier.write_text("earlier")

    def refused(path):
        path.write_text("half")
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError):
        write_files([(earlier, lambda path: path.write_text("new")), (tmp_path / "b.csv", refused)])
    assert earlier.read_text() == "earlier"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.csv"]
    nested = tmp_path / "c" / "d.csv"
    write_files(
        [(earlier, lambda path: path.write_text("new")), (nested, lambda p: p.write_text(p.suffix))]
    )
    assert earlier.read_text() == "new"
    assert nested.read_text() == ".csv"
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["a.csv", "c", "d.csv"]
