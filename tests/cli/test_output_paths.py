"""The output checks of every command that writes files: an output that is an input, a folder,
under a file or unwritable is refused before any work, and the input is left as it was."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import pytest

from vo_doppler.cli import main
from vo_doppler.commands.output_paths import check_output_files
from vo_doppler.errors import OutputError

CONTENT = "precious input\n"


@pytest.fixture
def source(tmp_path) -> Path:
    path = tmp_path / "input.obs"
    path.write_text(CONTENT)
    return path


def test_an_output_that_is_an_input_by_any_spelling_is_refused(source, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    link = tmp_path / "link.obs"
    link.symlink_to(source)
    hard = tmp_path / "hard.obs"
    os.link(source, hard)
    for output in (source, Path("input.obs"), tmp_path / "sub" / ".." / "input.obs", link, hard):
        with pytest.raises(OutputError, match=rf"the output {output} is the input {source}"):
            check_output_files({"output": output}, [None, [source]])
    assert source.read_text() == CONTENT


def test_a_figure_beside_the_output_that_is_an_input_is_refused(source, tmp_path):
    figure = source.with_suffix(".png")
    figure.write_text(CONTENT)
    outputs = {"output": tmp_path / "input.csv", "figure": figure}
    with pytest.raises(OutputError, match=r"the figure .*input\.png is the input"):
        check_output_files(outputs, [figure])
    with pytest.raises(OutputError, match="the output and the figure are the same file"):
        check_output_files({"output": figure, "figure": figure}, [])


def test_unusable_output_locations_are_refused(source, tmp_path):
    (tmp_path / "adir").mkdir()
    too_long = "x" * (os.pathconf(tmp_path, "PC_NAME_MAX") + 1)
    cases = {
        tmp_path / "adir": "is a folder",
        source / "x.csv": "input.obs is a file, not a folder",
        source / "deeper" / "x.csv": "input.obs is a file, not a folder",
        tmp_path / f"{too_long}.csv": r"cannot write the output \(File name too long\)",
        tmp_path / too_long / "x.csv": r"cannot write the output \(File name too long\)",
    }
    for output, message in cases.items():
        with pytest.raises(OutputError, match=message):
            check_output_files({"output": output}, [])


NOBODY = 65534
"""The unprivileged user and group id that root gives up to (root may write anywhere)."""


def _messages_as_a_user(outputs: list[Path]) -> list[str]:
    """What checking each output says ("accepted" when nothing) to an ordinary user: in a
    forked child that gives up root first, as permissions do not bind root."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: reports through the pipe, never returns into pytest
        try:
            os.close(read)
            if os.geteuid() == 0:
                os.setgid(NOBODY)
                os.setuid(NOBODY)
            said = []
            for output in outputs:
                try:
                    check_output_files({"output": output}, [])
                    said.append("accepted")
                except OutputError as exc:
                    said.append(str(exc))
            os.write(write, "\n".join(said).encode())
        finally:
            os._exit(0)
    os.close(write)
    with os.fdopen(read) as stream:
        said = stream.read().splitlines()
    os.waitpid(pid, 0)
    return said


def test_unwritable_places_are_refused_by_their_permissions():
    """A read-only folder and a read-only file are refused, judged from their permissions
    (nothing is created to try); a writable folder is accepted."""
    with tempfile.TemporaryDirectory(prefix="vo-doppler-test-") as name:
        folder = Path(name)
        folder.chmod(0o777)  # reachable and writable by the unprivileged user
        locked = folder / "locked"
        locked.mkdir(mode=0o555)
        frozen = folder / "frozen.csv"
        frozen.write_text(CONTENT)
        frozen.chmod(0o444)
        outputs = [locked / "x.csv", locked / "new" / "x.csv", frozen, folder / "new.csv"]
        said = _messages_as_a_user(outputs)
        assert said == [
            f"{locked / 'x.csv'}: no permission to write in {locked}",
            f"{locked / 'new' / 'x.csv'}: no permission to write in {locked}",
            f"{frozen}: no permission to write the existing file",
            "accepted",
        ]
        assert sorted(p.name for p in folder.iterdir()) == ["frozen.csv", "locked"]
        locked.chmod(0o755)


def test_checking_creates_and_changes_nothing(source, tmp_path):
    """Not even for a moment: the folder's modification time stays (a probe file created and
    deleted again changed it)."""
    new = tmp_path / "new.csv"
    later = tmp_path / "not" / "yet" / "made.csv"
    long_ago = 1_000_000_000_000_000_000
    os.utime(tmp_path, ns=(long_ago, long_ago))
    os.utime(source, ns=(long_ago, long_ago))
    check_output_files({"output": new, "figure": later, "other": None}, [])
    assert not new.exists() and not (tmp_path / "not").exists()
    check_output_files({"output": source}, [])  # an existing file that is no input: replaced later
    assert source.read_text() == CONTENT
    assert tmp_path.stat().st_mtime_ns == source.stat().st_mtime_ns == long_ago


def _commands(tmp_path: Path, victim: Path) -> dict[str, list[str]]:
    """Each command with ``victim`` as one of its inputs and as (or beside) its output."""
    other = str(tmp_path / "other.txt")
    png = victim.with_suffix(".png")
    png.write_text(CONTENT)
    v = str(victim)
    nav = ["--nav", other]
    return {
        "gnss spp -o obs": ["gnss", "spp", v, *nav, "-o", v],
        "gnss velocity figure": ["gnss", "velocity", str(png), *nav, "-o", str(victim)],
        "heading -o speed": [
            *("heading", other, *nav, "--speed-csv", v, "--yaw-rate-csv", other, "-o", v),
        ],
        "correct -o trajectory": ["correct", v, "--heading", other, "-o", v],
        "correct -o heading": ["correct", other, "--heading", v, "-o", v],
        "kitti-speed -o poses": ["kitti-speed", v, "--times", other, "-o", v],
        "kitti-speed -o times": ["kitti-speed", other, "--times", v, "-o", v],
        "deadreckon": [
            "deadreckon",
            *("--gyro1", other, "--gyro2", other, "--gps", v, "-o", str(victim.parent)),
        ],
        "import": [
            "import",
            "comma2k19",
            str(victim.parent),
            *("--orbits", other, "-o", str(tmp_path)),
        ],
    }


@pytest.mark.parametrize(
    "name",
    [
        "gnss spp -o obs",
        "gnss velocity figure",
        "heading -o speed",
        "correct -o trajectory",
        "correct -o heading",
        "kitti-speed -o poses",
        "kitti-speed -o times",
        "deadreckon",
        "import",
    ],
)
def test_every_command_refuses_to_overwrite_its_input(name, tmp_path, capsys):
    """The QA report's cases (gnss spp -o the RINEX, correct -o the trajectory, kitti-speed -o
    the poses) and the same for every command writing files: exit 1, the input untouched."""
    victim = tmp_path / "seq" / "drift_table.csv"  # also a file name deadreckon writes
    victim.parent.mkdir()
    victim.write_text(CONTENT)
    argv = _commands(tmp_path, victim)[name]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "is the input" in err or "contains the input" in err
    assert victim.read_text() == CONTENT and victim.with_suffix(".png").read_text() == CONTENT
