"""The error contract of ``vo-doppler``: 0 success, 1 bad input or failed processing, 2 usage,
3 internal error; one line on stderr, the traceback only with ``--debug``."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.cli import build_parser, main
from vo_doppler.commands import eval_command
from vo_doppler.errors import EXIT_FAILURE, EXIT_INTERNAL, EXIT_OK, EXIT_USAGE
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.trajectory import Trajectory


@pytest.fixture
def tum(tmp_path):
    t = np.arange(20.0)
    positions = np.column_stack([t, np.zeros(20), np.zeros(20)])
    path = tmp_path / "straight.tum"
    write_tum(path, Trajectory(t, positions, Rotation.identity(20)))
    return path


def cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "vo_doppler.cli", *args], capture_output=True, text=True, timeout=120
    )


def test_codes_are_distinct_and_documented_in_help():
    assert (EXIT_OK, EXIT_FAILURE, EXIT_USAGE, EXIT_INTERNAL) == (0, 1, 2, 3)
    text = build_parser().format_help()
    for code, words in ((0, "success"), (1, "bad input"), (2, "usage"), (3, "internal error")):
        assert f"  {code}  " in text and words in text


def test_success_is_0(tum, capsys):
    assert main(["eval", str(tum), str(tum)]) == EXIT_OK


def test_bad_input_is_1_with_one_line_naming_the_file(tmp_path, capsys):
    missing = tmp_path / "missing.tum"
    assert main(["eval", str(missing), str(missing)]) == EXIT_FAILURE
    err = capsys.readouterr().err.strip()
    assert "missing.tum" in err and "Traceback" not in err and len(err.splitlines()) == 1


@pytest.mark.slow
def test_usage_is_2_as_a_process():
    result = cli("run")
    assert result.returncode == EXIT_USAGE
    assert "usage:" in result.stderr


def test_internal_error_is_3_with_one_line_and_traceback_under_debug(tum, monkeypatch, capsys):
    def broken(args):
        return 1 / 0

    monkeypatch.setattr(eval_command, "run", broken)
    assert main(["eval", str(tum), str(tum)]) == EXIT_INTERNAL
    err = capsys.readouterr().err
    assert "internal error: ZeroDivisionError" in err and "--debug" in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert main(["--debug", "eval", str(tum), str(tum)]) == EXIT_INTERNAL
    err = capsys.readouterr().err
    assert "Traceback" in err and "1 / 0" in err


def test_a_file_operation_the_system_refuses_is_1_naming_the_file(tum, monkeypatch, capsys):
    def disk_full(args):
        raise OSError(28, "No space left on device", "/data/out/summary.json")

    monkeypatch.setattr(eval_command, "run", disk_full)
    assert main(["eval", str(tum), str(tum)]) == EXIT_FAILURE
    err = capsys.readouterr().err
    assert "/data/out/summary.json: No space left on device" in err
    assert len(err.strip().splitlines()) == 1 and "internal error" not in err


def test_an_os_error_without_a_file_stays_internal(tum, monkeypatch, capsys):
    def broken(args):
        raise OSError("bad file descriptor")

    monkeypatch.setattr(eval_command, "run", broken)
    assert main(["eval", str(tum), str(tum)]) == EXIT_INTERNAL
    assert "internal error: OSError" in capsys.readouterr().err


@pytest.mark.slow
def test_bad_input_as_a_process_exits_1_and_debug_shows_the_traceback(tmp_path):
    png = tmp_path / "picture.png"
    png.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(64))
    result = cli("eval", str(png), str(png))
    assert result.returncode == EXIT_FAILURE
    assert "picture.png: trajectory file is a PNG image, not a text file" in result.stderr
    assert "Traceback" not in result.stderr
    assert "Traceback" in cli("--debug", "eval", str(png), str(png)).stderr
