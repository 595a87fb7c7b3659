"""The toolkit's errors name where the problem is and pickle as themselves; exit codes; storage
refusals; names that are not UTF-8 shown as escapes."""

from __future__ import annotations

import errno
import pickle
from pathlib import Path

from vo_doppler.errors import (
    EXIT_FAILURE,
    EXIT_INTERNAL,
    EXIT_OK,
    EXIT_USAGE,
    InputError,
    ManifestError,
    OutputError,
    UsageError,
    VoDopplerError,
    shown,
    storage_refused,
)


def test_the_exit_codes():
    assert (EXIT_OK, EXIT_FAILURE, EXIT_USAGE, EXIT_INTERNAL) == (0, 1, 2, 3)


def test_an_input_error_names_the_file_and_the_line_or_byte():
    assert str(InputError("no header")) == "no header"
    error = InputError("bad value", Path("a/b.csv"), line=12)
    assert str(error) == "a/b.csv:12: bad value"
    assert (error.path, error.line, error.byte) == (Path("a/b.csv"), 12, None)
    assert str(InputError("bad frame", "log.ubx", byte=4096)) == "log.ubx, byte 4096: bad frame"
    assert isinstance(error, VoDopplerError)


def test_a_manifest_error_names_the_key():
    error = ManifestError("camera.fps", "must be positive", "seq/sequence.yaml")
    assert str(error) == "seq/sequence.yaml: camera.fps: must be positive"
    assert error.key == "camera.fps" and isinstance(error, InputError)


def test_storage_refusals_are_the_systems_not_bugs():
    assert storage_refused(OSError(errno.ENOSPC, "No space left on device"))
    assert storage_refused(OSError(errno.EROFS, "Read-only file system"))
    assert not storage_refused(OSError(errno.ENOENT, "No such file"))
    assert not storage_refused(ValueError("x"))


def test_names_that_are_not_utf8_are_shown_as_escapes():
    assert shown(Path("plain/é.csv")) == "plain/é.csv"
    assert shown("bad\udcffname") == "bad\\xffname"  # the byte 0xFF of a non-UTF-8 name
    assert shown("lone\ud800") == "lone\\ud800"


def test_every_error_pickles_as_itself_with_its_attributes_and_notes():
    """What a child process raises reaches the parent whole (vo_doppler.child_process): the
    class (so the exit code), the message, the file, line, byte or key, the notes."""
    errors = [
        InputError("bad row", "seq/a.csv", line=3),
        InputError("bad frame", "seq/b.ubx", byte=17),
        ManifestError("camera.fps", "not a number", "seq/sequence.yaml"),
        UsageError("--start after the end"),
        OutputError("out is a file"),
    ]
    errors[0].add_note("while reading the wheel speed")
    for error in errors:
        copy = pickle.loads(pickle.dumps(error))
        assert type(copy) is type(error)
        assert str(copy) == str(error) and copy.args == error.args
        assert vars(copy) == vars(error)
    assert errors[0].__notes__ == ["while reading the wheel speed"]
    assert pickle.loads(pickle.dumps(errors[0])).__notes__ == errors[0].__notes__
