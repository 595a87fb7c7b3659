"""The ``vo-doppler`` entry point: lazy subcommands, every option documented."""

from __future__ import annotations

import subprocess
import sys

import pytest

from vo_doppler.cli import SUBCOMMANDS, build_parser, chosen_command, main


def test_top_level_help_loads_none_of_the_library():
    probe = (
        "import sys\n"
        "from vo_doppler.cli import main\n"
        "try:\n"
        "    main(['--help'])\n"
        "except SystemExit:\n"
        "    pass\n"
        "heavy = ('numpy', 'scipy', 'cv2', 'matplotlib', 'pycolmap')\n"
        "print('LOADED:' + ','.join(m for m in heavy if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert "COMMAND" in out.stdout
    assert out.stdout.strip().splitlines()[-1] == "LOADED:"


def test_every_subcommand_is_listed_and_registers_its_options():
    parser = build_parser("*")
    actions = [a for a in parser._actions if a.dest == "command"]
    assert set(actions[0].choices) == set(SUBCOMMANDS)
    for name in SUBCOMMANDS:
        assert actions[0].choices[name].format_usage().startswith(f"usage: vo-doppler {name}")


@pytest.mark.parametrize(
    ("argv", "command"),
    [(["-v", "run", "x"], "run"), (["--help"], None), (["gnss", "velocity"], "gnss")],
)
def test_the_chosen_subcommand_is_the_first_known_name(argv, command):
    assert chosen_command(argv) == command


def test_a_subcommands_help_lists_its_own_options(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["correct", "--help"])
    assert exit_info.value.code == 0
    assert "--heading" in capsys.readouterr().out


@pytest.mark.parametrize(
    "argv",
    [
        ["run", "seq", "-o", "out"],
        ["batch", "a", "-o", "out"],
        ["vo", "img", "--calib", "c", "-o", "o"],
    ],
)
def test_the_vo_window_defaults_to_the_vo_configs(argv):
    from vo_doppler.vo.config import VoConfig

    assert build_parser(argv[0]).parse_args(argv).window == VoConfig().window_size
