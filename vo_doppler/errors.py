"""Exceptions raised for bad input; each one names where the problem is.

Exit codes of the ``vo-doppler`` command (the one error contract):

* ``EXIT_OK`` (0): success;
* ``EXIT_FAILURE`` (1): bad input or failed processing — a :class:`VoDopplerError`, whose
  message names the file and line, epoch or key;
* ``EXIT_USAGE`` (2): the command line itself is wrong (argparse), or an option contradicts
  the data it applies to (a :class:`UsageError`, e.g. a ``--start`` after the recording's end);
* ``EXIT_INTERNAL`` (3): anything unexpected, i.e. a bug (``--debug`` shows the traceback).
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_USAGE = 2
EXIT_INTERNAL = 3


class VoDopplerError(Exception):
    """Base class of every error the toolkit raises on purpose.

    It pickles as what it is, its attributes (file, line, key) and notes included, whatever
    its constructor takes: an error raised in a child process (:mod:`vo_doppler.child_process`)
    keeps its class, and so its exit code, in the parent."""

    def __reduce__(self):
        return _restored, (type(self), self.args, self.__dict__)


def _restored(cls: type[VoDopplerError], args: tuple, state: dict) -> VoDopplerError:
    """An error of class ``cls`` with ``args`` and attributes ``state``, without calling its
    constructor (pickle's rebuilding of a :class:`VoDopplerError`)."""
    error = cls.__new__(cls)
    error.args = args
    error.__dict__.update(state)
    return error


class InputError(VoDopplerError):
    """An input file or value is unusable: the message names the file, line or epoch, or for
    a binary file the byte offset (``FILE, byte N``: ``FILE:N`` would read as a line)."""

    def __init__(
        self,
        message: str,
        path: str | Path | None = None,
        line: int | None = None,
        byte: int | None = None,
    ):
        self.path = None if path is None else Path(path)
        self.line = line
        self.byte = byte
        where = ""
        if path is not None:
            where = f"{path}"
            if line is not None:
                where += f":{line}"
            if byte is not None:
                where += f", byte {byte}"
            where += ": "
        super().__init__(where + message)


class ManifestError(InputError):
    """A ``sequence.yaml`` value is missing, of the wrong type or out of range; names the key."""

    def __init__(self, key: str, message: str, path: str | Path | None = None):
        self.key = key
        super().__init__(f"{key}: {message}", path)


class OutputError(VoDopplerError):
    """An output location is unusable (a file where a folder is wanted, not writable) or is
    one of the command's inputs (writing it would destroy the input)."""


STORAGE_ERRNOS = frozenset(
    getattr(errno, name)
    for name in ("ENOSPC", "EDQUOT", "EFBIG", "EROFS", "EIO")
    if hasattr(errno, name)
)
"""The system's refusals to store what is written (a full disk or quota, a file too large for
the file system, a read-only or failing device): the environment, not a bug."""


def storage_refused(exc: BaseException) -> bool:
    """Whether ``exc`` is the system refusing to store written data (:data:`STORAGE_ERRNOS`);
    such an error often names no file (a buffered write failing at its flush)."""
    return isinstance(exc, OSError) and exc.errno in STORAGE_ERRNOS


def shown(text: str | os.PathLike[str]) -> str:
    """``text`` (a path or a name taken from one) as text any UTF-8 output takes: the bytes of
    a name that is not UTF-8, which Python holds as lone surrogates (``os.fsdecode``), become
    ``\\xff`` escapes, so that a report, a JSON file or a figure title names it instead of
    failing with ``UnicodeEncodeError``."""
    text = os.fspath(text)
    try:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "backslashreplace")
    except UnicodeEncodeError:  # a surrogate no file name decodes to ('\\ud800')
        return text.encode("utf-8", "backslashreplace").decode("utf-8")


class UsageError(VoDopplerError):
    """An option's value that contradicts the data it applies to, which only reading them shows
    (a ``--start`` / ``--end`` outside the recording): a usage error, exit 2, as argparse's."""
