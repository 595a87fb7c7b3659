"""A step in a forked child process: its result, progress and log records come back; its
imports and changes stay in the child; its errors are raised here with the child's traceback;
a child that dies is reported, one that is no longer listened to is ended."""

from __future__ import annotations

import logging
import os
import signal
import sys
import threading
import warnings
from multiprocessing.connection import Pipe

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler import child_process
from vo_doppler.child_process import call_in_child
from vo_doppler.errors import InputError, ManifestError

STATE = {"touched": False}


def test_the_result_and_every_progress_call_come_back_in_order():
    seen = []

    def task(progress):
        for index in range(5):
            progress(index)
        return np.arange(6.0) / 7.0, os.getpid()

    values, pid = call_in_child(task, seen.append)
    assert seen == [0, 1, 2, 3, 4]
    np.testing.assert_array_equal(values, np.arange(6.0) / 7.0)
    assert pid != os.getpid()


def test_arrays_come_back_equal_writable_and_in_their_layout():
    rng = np.random.default_rng(7)
    big = rng.normal(size=(300_000, 4))
    fortran = np.asfortranarray(rng.normal(size=(50, 3)))
    records = np.array([(1, 2.5), (3, -1.0)], dtype=[("a", "i4"), ("b", "f8")])
    sent = {
        "big": big,
        "strided": big[::7, 1],
        "fortran": fortran,
        "records": records,
        "empty": np.zeros((0, 3)),
        "objects": np.array([{"x": 1}, None], dtype=object),
        "rotation": Rotation.from_quat(big[:1000] / np.linalg.norm(big[:1000], axis=1)[:, None]),
    }
    got = call_in_child(lambda _: sent)
    for name in ("big", "strided", "fortran", "records", "empty", "objects"):
        np.testing.assert_array_equal(got[name], sent[name], err_msg=name)
        assert got[name].dtype == sent[name].dtype
        assert got[name].flags.writeable, name
    assert got["fortran"].flags.f_contiguous
    np.testing.assert_array_equal(got["rotation"].as_quat(), sent["rotation"].as_quat())
    got["big"][0, 0] = 42.0
    assert big[0, 0] != 42.0


def test_a_results_arrays_travel_beside_its_pickle_not_in_it():
    receiver, sender = Pipe(duplex=False)
    poses = np.arange(4 * 4 * 20_000, dtype=float).reshape(-1, 4, 4)
    thread = threading.Thread(target=child_process._send_result, args=(sender, (poses, "VO")))
    thread.start()
    kind, header, sizes = receiver.recv()
    assert kind == "result"
    assert sizes == [poses.nbytes]
    assert len(header) < 1024
    got, label = child_process._receive_result(receiver, header, sizes)
    thread.join()
    np.testing.assert_array_equal(got, poses)
    assert label == "VO"


def test_without_a_progress_callback_the_task_gets_none():
    assert call_in_child(lambda progress: progress is None) is True


def test_what_the_child_imports_or_changes_stays_in_the_child(tmp_path, monkeypatch):
    (tmp_path / "only_in_the_child_xq7.py").write_text("VALUE = 41\n")
    monkeypatch.syspath_prepend(str(tmp_path))

    def task(_):
        import only_in_the_child_xq7

        STATE["touched"] = True
        return only_in_the_child_xq7.VALUE + 1

    assert call_in_child(task) == 42
    assert "only_in_the_child_xq7" not in sys.modules
    assert STATE["touched"] is False


def _raise(error: BaseException):
    def task(_):
        raise error

    return task


def test_an_error_in_the_child_is_raised_here_with_its_traceback():
    with pytest.raises(InputError) as raised:
        call_in_child(_raise(InputError("bad row", "seq/x.csv", 3)))
    assert str(raised.value) == "seq/x.csv:3: bad row"
    assert any(
        "in the child process" in note and "bad row" in note for note in raised.value.__notes__
    )
    with pytest.raises(ValueError) as raised:
        call_in_child(_raise(ValueError("not a number")))
    assert str(raised.value) == "not a number"


def test_a_project_error_comes_back_as_itself_and_a_foreign_unpicklable_one_as_its_text():
    """ManifestError's constructor takes two arguments, which plain exception pickling cannot
    give back: the project's errors pickle as themselves (class, so exit code, and key). An
    error of another library that will not pickle arrives as a RuntimeError with its text."""
    error = ManifestError("camera.fps", "not a number", "seq/sequence.yaml")
    with pytest.raises(ManifestError) as raised:
        call_in_child(_raise(error))
    assert str(raised.value) == str(error) and raised.value.key == "camera.fps"

    class TwoArgumentError(Exception):
        def __init__(self, first, second):
            super().__init__(f"{first}/{second}")

    with pytest.raises(RuntimeError) as foreign:
        call_in_child(_raise(TwoArgumentError("a", "b")))
    assert str(foreign.value) == "TwoArgumentError: a/b"


def test_a_child_that_dies_is_an_error_naming_the_signal():
    def task(_):
        os.kill(os.getpid(), signal.SIGKILL)

    with pytest.raises(
        RuntimeError, match=r"ended without a result \(killed by signal 9 \(SIGKILL\)\)"
    ):
        call_in_child(task)


class StopListeningError(Exception):
    pass


def test_a_child_no_longer_listened_to_is_ended_and_reaped():
    children = []

    def remember_and_stop(pid):
        children.append(pid)
        raise StopListeningError

    def task(progress):
        while True:
            progress(os.getpid())

    with pytest.raises(StopListeningError):
        call_in_child(task, remember_and_stop)
    with pytest.raises(ChildProcessError):
        os.waitpid(children[0], os.WNOHANG)


def test_log_records_and_warnings_of_the_child_are_handled_here_once(caplog):
    middle = logging.getLogger("vo_doppler.child_test")
    collected: list[logging.LogRecord] = []
    extra = logging.Handler()
    extra.emit = collected.append
    middle.addHandler(extra)
    try:

        def task(_):
            logging.getLogger("vo_doppler.child_test.stage").warning("%d frames %s", 3, "unread")
            warnings.warn("a warning of the child", UserWarning, stacklevel=1)
            return None

        with caplog.at_level(logging.INFO):
            call_in_child(task)
    finally:
        middle.removeHandler(extra)
    frames = [r for r in caplog.records if r.name == "vo_doppler.child_test.stage"]
    assert [r.getMessage() for r in frames] == ["3 frames unread"]
    assert frames[0].levelno == logging.WARNING
    assert [r.getMessage() for r in collected] == ["3 frames unread"]
    assert any("a warning of the child" in r.getMessage() for r in caplog.records)


def test_without_fork_the_task_runs_here(monkeypatch):
    monkeypatch.setattr(child_process, "can_fork", lambda: False)
    seen = []

    def task(progress):
        progress(7)
        return os.getpid()

    assert call_in_child(task, seen.append) == os.getpid()
    assert seen == [7]


@pytest.mark.parametrize(
    ("platform", "forks"), [("linux", True), ("darwin", False), ("win32", False)]
)
def test_only_linux_forks(monkeypatch, platform, forks):
    monkeypatch.setattr(sys, "platform", platform)
    assert child_process.can_fork() is (forks and hasattr(os, "fork"))
