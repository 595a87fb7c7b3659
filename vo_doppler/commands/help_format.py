"""The ``vo-doppler`` argument parser: help for every option with its default shown, option
values that start with "-" (``--up -y``), and checks of options against each other as usage
errors (argparse only: ``--help`` loads none of the library)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence

OptionsCheck = Callable[[argparse.Namespace], str | None]
"""A check of parsed options against each other: the problem (naming the options), or None."""


def shown_default(value) -> str:
    """A default as it is typed on the command line: tuples as ``A,B``, nested ones flattened."""
    if isinstance(value, tuple | list):
        return ",".join(shown_default(v) for v in value)
    return str(value)


def has_default(action: argparse.Action) -> bool:
    """An option whose default a person can see and change (not None, not a flag's False)."""
    return (
        bool(action.option_strings)
        and not action.required
        and not any(action.default is v for v in (None, False, argparse.SUPPRESS))
        and not isinstance(
            action, argparse._HelpAction | argparse._VersionAction | argparse._CountAction
        )
    )


class DefaultsHelpFormatter(argparse.HelpFormatter):
    """Appends ``(default: X)`` to the help of every option with a default, unless the help
    already shows it with ``%(default)s``."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if has_default(action) and "%(default)" not in text:
            text += f" (default: {shown_default(action.default).replace('%', '%%')})"
        return text


class OptionsParser(argparse.ArgumentParser):
    """An argument parser whose help shows every default (its sub-parsers too), which takes a
    choice starting with "-" as the value of its option, and which runs its
    :meth:`add_check` checks once the options are parsed."""

    def __init__(self, *args, formatter_class=DefaultsHelpFormatter, **kwargs) -> None:
        if not issubclass(formatter_class, DefaultsHelpFormatter):
            name = f"{formatter_class.__name__}WithDefaults"
            formatter_class = type(name, (formatter_class, DefaultsHelpFormatter), {})
        super().__init__(*args, formatter_class=formatter_class, **kwargs)
        self.checks: list[OptionsCheck] = []

    def add_check(self, check: OptionsCheck) -> None:
        """Run ``check`` on the parsed options: a problem it returns is a usage error (exit 2,
        with the usage), before the command reads or writes anything. For options that are
        right alone but contradict each other, e.g. one that has no effect with another."""
        self.checks.append(check)

    def parse_known_args(self, args: Sequence[str] | None = None, namespace=None):
        words = joined_dash_choices(self, sys.argv[1:] if args is None else list(args))
        parsed, extras = super().parse_known_args(words, namespace)
        for check in self.checks:
            problem = check(parsed)
            if problem:
                self.error(problem)
        return parsed, extras


def joined_dash_choices(parser: argparse.ArgumentParser, words: list[str]) -> list[str]:
    """``words`` with ``--option VALUE`` written ``--option=VALUE`` where VALUE is one of the
    option's choices and starts with "-" (e.g. ``eval --up -y``): argparse would take such a
    VALUE for an option and say the option lacks its argument. Only exact choices are joined,
    and nothing after ``--``."""
    dash_choices = {
        option: action.choices
        for action in parser._actions
        if action.option_strings and action.nargs is None and action.choices is not None
        if any(str(choice).startswith("-") for choice in action.choices)
        for option in action.option_strings
    }
    joined: list[str] = []
    i = 0
    while i < len(words):
        word = words[i]
        if word == "--":
            return joined + words[i:]
        following = words[i + 1] if i + 1 < len(words) else None
        if (
            word in dash_choices
            and following is not None
            and following.startswith("-")
            and following in dash_choices[word]
        ):
            joined.append(f"{word}={following}")
            i += 2
        else:
            joined.append(word)
            i += 1
    return joined
