"""Every option of every subcommand has help and shows its default; help names the paper."""

from __future__ import annotations

import argparse
import importlib
import pkgutil
from enum import StrEnum

import pytest

import vo_doppler
from vo_doppler.choices import values
from vo_doppler.cli import build_parser
from vo_doppler.commands.help_format import (
    OptionsParser,
    has_default,
    joined_dash_choices,
    shown_default,
)
from vo_doppler.io.trajectory import AUTO_FORMAT_RULE


def _parsers(parser: argparse.ArgumentParser, name: str = "vo-doppler"):
    """``(name, parser)`` of the parser and of every sub-parser below it."""
    yield name, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from _parsers(sub, f"{name} {sub_name}")


PARSERS = dict(_parsers(build_parser("*")))


def _options(parser: argparse.ArgumentParser):
    return [
        a
        for a in parser._actions
        if not isinstance(a, argparse._HelpAction | argparse._SubParsersAction)
    ]


@pytest.mark.parametrize("name", sorted(PARSERS))
def test_every_option_has_help_and_shows_its_default(name):
    parser = PARSERS[name]
    for action in _options(parser):
        assert action.help and action.help.strip(), f"{name} {action.option_strings} has no help"
        if has_default(action) and "%(default" in action.help:
            assert "default" in parser._get_formatter()._expand_help(action)
        elif has_default(action):
            rendered = parser._get_formatter()._expand_help(action)
            expected = f"default: {shown_default(action.default)}"
            assert expected in rendered or f"default {shown_default(action.default)}" in rendered, (
                f"{name} {action.option_strings}: {rendered!r}"
            )


@pytest.mark.parametrize("name", sorted(PARSERS))
def test_no_option_states_its_default_twice(name):
    parser = PARSERS[name]
    for action in _options(parser):
        rendered = parser._get_formatter()._expand_help(action)
        assert rendered.lower().count("(default") <= 1, (
            f"{name} {action.option_strings}: {rendered!r}"
        )


@pytest.mark.parametrize("name", sorted(PARSERS))
def test_help_prints_no_escapes_and_names_the_paper(name):
    text = PARSERS[name].format_help()
    assert "%%" not in text
    assert "seed's" not in text
    assert "as written" not in text or "[TK18]" in text
    if "Eq. 11" in text:
        assert "[TK18]" in text


def test_the_walk_covers_the_options_the_issue_names():
    options = {
        name: {o for a in _options(p) for o in a.option_strings} for name, p in PARSERS.items()
    }
    assert {"--nav", "--systems", "--calibration"} <= options["vo-doppler heading"]
    assert {"--source", "--world", "--body", "--max-gap-s", "--format"} <= options[
        "vo-doppler correct"
    ]
    assert "--format" in options["vo-doppler eval"]


@pytest.mark.parametrize("name", ["vo-doppler correct", "vo-doppler eval"])
def test_trajectory_format_help_states_the_rule_auto_follows(name):
    """The help said "from the extension and the number of columns"; only the columns count."""
    (action,) = [a for a in _options(PARSERS[name]) if "--format" in a.option_strings]
    assert f"auto: {AUTO_FORMAT_RULE}; the extension is not used" in action.help
    assert "from the extension" not in action.help


def test_defaults_are_shown_as_typed():
    assert shown_default((640, 360)) == "640,360"
    assert shown_default(((1, 1), (4, 3))) == "1,1,4,3"
    assert shown_default(2.0) == "2.0"


def _up_parser() -> OptionsParser:
    parser = OptionsParser(prog="p")
    parser.add_argument("--up", choices=("z", "-y", "y"), default="z", help="up axis")
    parser.add_argument("-y", "--yes", action="store_true", help="a flag spelt like a choice")
    parser.add_argument("rest", nargs="*", help="anything")
    return parser


@pytest.mark.parametrize(
    ("words", "up", "yes", "rest"),
    [
        (["--up", "-y"], "-y", False, []),
        (["--up=-y"], "-y", False, []),
        (["--up", "y", "-y"], "y", True, []),
        (["-y", "--up", "z"], "z", True, []),
        (["--", "--up", "-y"], "z", False, ["--up", "-y"]),
    ],
)
def test_a_choice_starting_with_a_dash_is_the_options_value(words, up, yes, rest):
    args = _up_parser().parse_args(words)
    assert (args.up, args.yes, args.rest) == (up, yes, rest)


def test_only_exact_choices_are_joined():
    parser = _up_parser()
    assert joined_dash_choices(parser, ["--up", "-x", "--up", "-y"]) == ["--up", "-x", "--up=-y"]
    assert joined_dash_choices(parser, ["--up"]) == ["--up"]


def test_a_failed_check_is_a_usage_error_after_parsing(capsys):
    parser = _up_parser()
    seen = []
    parser.add_check(lambda args: seen.append(args.up) or None)

    def yes_with_y(args):
        return "--yes contradicts --up y" if args.yes and args.up == "y" else None

    parser.add_check(yes_with_y)
    assert parser.parse_args(["--up", "-y", "-y"]).yes
    with pytest.raises(SystemExit) as stop:
        parser.parse_args(["--up", "y", "--yes"])
    assert stop.value.code == 2
    assert "p: error: --yes contradicts --up y" in capsys.readouterr().err
    assert seen == ["-y", "y"]


AXIS_CHOICES = {"--up", "--imu-yaw-axis", "--imu-forward-axis"}
"""Options whose choices are axis names (``-y``, ``z``, ...) of an axis table, with ``auto``."""


def _choice_sets() -> dict[tuple[str, ...], type[StrEnum]]:
    """The values of every ``StrEnum`` of the package, to the enum."""
    sets = {}
    for info in pkgutil.walk_packages(vo_doppler.__path__, "vo_doppler."):
        for value in vars(importlib.import_module(info.name)).values():
            if isinstance(value, type) and issubclass(value, StrEnum) and value is not StrEnum:
                sets[values(value)] = value
    return sets


def test_every_choice_of_words_is_an_enums_values_and_its_default_a_member():
    sets = _choice_sets()
    from_enums, missing = set(), []
    for name, parser in PARSERS.items():
        for action in _options(parser):
            choices = tuple(action.choices or ())
            if not choices or not all(isinstance(c, str) for c in choices):
                continue
            if set(action.option_strings) & AXIS_CHOICES:
                continue
            if choices not in sets:
                missing.append(f"{name} {action.option_strings}")
                continue
            from_enums.add(sets[choices])
            assert sets[choices](action.default) in sets[choices]
            assert type(action.default) is str, f"{name} {action.option_strings}"
    assert missing == [], "string choices that are no StrEnum's values (choices.values)"
    names = {kind.__name__ for kind in from_enums}
    assert {"TrajectoryFormat", "World", "Executor", "RangeRateSource", "ShortFrames"} <= names
