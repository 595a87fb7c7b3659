"""Help for every ``vo-doppler`` option with its default shown (argparse only: ``--help``
loads none of the library)."""

from __future__ import annotations

import argparse


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
    """An argument parser whose help shows every default (its sub-parsers too)."""

    def __init__(self, *args, formatter_class=DefaultsHelpFormatter, **kwargs) -> None:
        if not issubclass(formatter_class, DefaultsHelpFormatter):
            name = f"{formatter_class.__name__}WithDefaults"
            formatter_class = type(name, (formatter_class, DefaultsHelpFormatter), {})
        super().__init__(*args, formatter_class=formatter_class, **kwargs)
