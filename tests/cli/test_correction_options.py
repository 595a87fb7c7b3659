"""The heading-correction options of ``correct``, ``run`` and ``batch``: an option the chosen
method ignores is a usage error (exit 2) naming both, before any file is read; the options
that take effect give the configuration they say."""

from __future__ import annotations

import pytest

from vo_doppler.cli import build_parser, main
from vo_doppler.commands.correction_options import correction_config
from vo_doppler.fusion.correction import CorrectionConfig

CORRECT = ["correct", "t.tum", "--heading", "h.csv", "-o", "c.tum"]
RUN = ["run", "seq", "-o", "out"]
BATCH = ["batch", "seq", "-o", "out"]


@pytest.mark.parametrize(
    ("argv", "options"),
    [
        ([*CORRECT, "--correction", "window", "--causal"], ("--causal", "--correction kalman")),
        ([*CORRECT, "--correction", "kalman", "--window-s", "5"], ("--window-s", "kalman")),
        ([*CORRECT, "--window-s", "5"], ("--window-s", "--correction kalman")),
        ([*RUN, "--correction", "window", "--causal"], ("--causal", "--correction kalman")),
        ([*BATCH, "--causal", "--correction", "window"], ("--causal", "--correction kalman")),
    ],
)
def test_an_option_the_method_ignores_is_exit_2(argv, options, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as stop:
        main(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert all(option in err for option in options), err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "argv",
    [
        CORRECT,
        [*CORRECT, "--causal"],
        [*CORRECT, "--correction", "window", "--window-s", "5"],
        [*RUN, "--correction", "window", "--reference", "orientation"],
    ],
)
def test_options_that_take_effect_give_their_configuration(argv):
    args = build_parser(argv[0]).parse_args(argv)
    config = correction_config(args, max_gap_s=0.5)
    assert config.method == args.correction
    assert config.reference == args.reference
    assert config.window_s == (5.0 if "--window-s" in argv else CorrectionConfig().window_s)
    assert config.blend.smooth == ("--causal" not in argv)
    assert config.blend.max_gap_s == 0.5


def test_the_window_help_states_the_default_it_has_when_not_given(capsys):
    with pytest.raises(SystemExit):
        main(["correct", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "window method's W (s), [TK18] Eq. 11-13 (default: 2)" in help_text
    assert CorrectionConfig().window_s == 2.0
