"""One step of a job in a forked child process, so that the libraries it loads leave with it.

An extension module cannot be unloaded: once the VO has imported OpenCV and pycolmap (about 70
MiB resident) the process keeps them through the correction and the outputs, where the main job
peaks. A child forked for the step shares every page of the parent until it writes one, loads
the libraries itself and gives back only its result, so the machine holds them only while the
step runs (docs/design.md, "Packages"; the figures in docs/benchmarks.md, "Memory").

The child writes nothing to the terminal: its progress and its log records come back over the
pipe with its result and are shown by the parent (a thread of the parent, a progress bar's,
may hold the terminal's lock at the fork), and it ends with ``os._exit``, flushing nothing it
inherited. An exception in the child is raised again in the parent, with the child's traceback
as a note.

The result is pickled with protocol 5 and its arrays sent out of band (PEP 574), each straight
from the child's memory into a buffer of the parent: pickled whole, a result would be copied
once more in the child as it ends, where the job's memory peaks (the VO's poses of a 30-min
drive: 7 MiB).
"""

from __future__ import annotations

import logging
import os
import pickle
import signal
import sys
import traceback
from collections.abc import Callable
from multiprocessing.connection import Connection, Pipe
from typing import TypeVar

T = TypeVar("T")
Progress = Callable[[int], None]

_PROGRESS, _LOG, _RESULT, _ERROR = "progress", "log", "result", "error"


def can_fork() -> bool:
    """Whether :func:`call_in_child` forks here: on Linux only. Windows has no ``fork``, and on
    macOS system libraries may start threads, so a forked child can crash (Python's own
    ``multiprocessing`` spawns there since 3.8); elsewhere the task runs in-process."""
    return hasattr(os, "fork") and sys.platform.startswith("linux")


def call_in_child(task: Callable[[Progress | None], T], on_progress: Progress | None = None) -> T:
    """``task(progress)`` run in a forked child process, its result returned here.

    ``progress`` is None when ``on_progress`` is None, else a callable that forwards each call
    to ``on_progress`` in this process. Log records of the child go to this process's loggers
    of the same names. Where it does not fork (:func:`can_fork`), ``task(on_progress)`` runs
    here."""
    if not can_fork():
        return task(on_progress)
    receiver, sender = Pipe(duplex=False)
    pid = os.fork()
    if pid == 0:
        receiver.close()
        _child(task, sender, on_progress is not None)
    sender.close()
    try:
        return _receive(receiver, on_progress, pid)
    finally:
        receiver.close()
        _reap(pid)


def _child(task: Callable[[Progress | None], object], sender: Connection, progress: bool) -> None:
    status = 0
    try:
        _log_to(sender)
        forward = (lambda index: sender.send((_PROGRESS, index))) if progress else None
        _send_result(sender, task(forward))
    except BaseException as error:
        status = 1
        try:
            sender.send((_ERROR, _portable(error), traceback.format_exc()))
        except BaseException:
            status = 2
    finally:
        os._exit(status)


def _send_result(sender: Connection, result: object) -> None:
    """``result`` as a pickle of protocol 5 whose contiguous arrays follow it, one message
    each, uncopied (:func:`_receive_result` puts it together again)."""
    buffers: list[pickle.PickleBuffer] = []
    header = pickle.dumps(result, protocol=5, buffer_callback=buffers.append)
    views = [buffer.raw() for buffer in buffers]
    sender.send((_RESULT, header, [view.nbytes for view in views]))
    for view in views:
        sender.send_bytes(view)


def _receive_result(receiver: Connection, header: bytes, sizes: list[int]) -> object:
    """The result :func:`_send_result` sent, its arrays in writable buffers of their own."""
    buffers = []
    for size in sizes:
        buffer = bytearray(size)
        receiver.recv_bytes_into(buffer)
        buffers.append(buffer)
    return pickle.loads(header, buffers=buffers)


def _log_to(sender: Connection) -> None:
    """Every logger that has handlers, the root's included, sends its records to the parent
    instead (once per record: the parent's loggers propagate it again); so do warnings."""
    handler = _PipeHandler(sender)
    for logger in logging.Logger.manager.loggerDict.values():
        if isinstance(logger, logging.Logger) and logger.handlers:
            logger.handlers = [handler]
    logging.getLogger().handlers = [handler]
    logging.captureWarnings(True)


def _portable(error: BaseException) -> BaseException:
    """``error`` if it survives pickling (the project's errors do, as they are), else a
    ``RuntimeError`` naming its class and giving its text."""
    try:
        pickle.loads(pickle.dumps(error))
    except Exception:
        return RuntimeError(f"{type(error).__name__}: {error}")
    return error


def _receive(receiver: Connection, on_progress: Progress | None, pid: int) -> T:
    while True:
        try:
            message = receiver.recv()
        except EOFError:
            status = _reap(pid)
            raise RuntimeError(
                f"the child process (pid {pid}) ended without a result ({_describe(status)})"
            ) from None
        kind = message[0]
        if kind == _PROGRESS and on_progress is not None:
            on_progress(message[1])
        elif kind == _LOG:
            logging.getLogger(message[1].name).handle(message[1])
        elif kind == _RESULT:
            return _receive_result(receiver, message[1], message[2])
        elif kind == _ERROR:
            error = message[1]
            error.add_note(f"in the child process (pid {pid}):\n{message[2]}")
            raise error


def _reap(pid: int) -> int | None:
    """Wait for the child (killed first if it still runs: the parent stopped listening);
    its wait status, or None when it was reaped already."""
    try:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done == 0:
            os.kill(pid, signal.SIGKILL)
            done, status = os.waitpid(pid, 0)
    except ChildProcessError:
        return None
    return status


def _describe(status: int | None) -> str:
    if status is None:
        return "its exit status is unknown"
    if os.WIFSIGNALED(status):
        number = os.WTERMSIG(status)
        return f"killed by signal {number} ({signal.Signals(number).name})"
    return f"exit status {os.WEXITSTATUS(status)}"


class _PipeHandler(logging.Handler):
    """Sends each record, its message formatted (arguments may not pickle), to the parent,
    once however many loggers it passes."""

    def __init__(self, sender: Connection) -> None:
        super().__init__()
        self.sender = sender

    def emit(self, record: logging.LogRecord) -> None:
        if getattr(record, "forwarded_to_parent", False):
            return
        record.forwarded_to_parent = True
        record.msg = record.getMessage()
        record.args = None
        if record.exc_info:
            record.exc_text = logging.Formatter().formatException(record.exc_info)
            record.exc_info = None
        self.sender.send((_LOG, record))
