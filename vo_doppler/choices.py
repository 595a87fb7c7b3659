"""Named choices of the configuration: each set of allowed strings is a ``StrEnum`` beside the
stage that uses it, checked here when a configuration is built (docs/design.md, "Choices and
units"). A member compares equal to its string, so code and files that hold the string keep
working."""

from __future__ import annotations

import re
from enum import StrEnum
from typing import TypeVar

from vo_doppler.errors import InputError

Choice = TypeVar("Choice", bound=StrEnum)


class ChoiceError(InputError, ValueError):
    """A value outside its choice set: an :class:`InputError` (exit code 1 at the command line)
    and a ``ValueError`` (what a library caller expects of a bad argument)."""


def kind_of(choices: type[StrEnum]) -> str:
    """The choice set in words, from its class name: ``CorrectionMethod`` → "correction
    method"."""
    return re.sub(r"(?<!^)(?=[A-Z])", " ", choices.__name__).lower()


def values(choices: type[StrEnum]) -> tuple[str, ...]:
    """The values of a choice set in their order of definition: an argparse ``choices=`` (whose
    error message shows each choice's ``repr``, a plain string's being the readable one)."""
    return tuple(member.value for member in choices)


def allowed(choices: type[StrEnum]) -> str:
    """The values of a choice set, comma-separated in their order of definition."""
    return ", ".join(values(choices))


def checked(choices: type[Choice], value: object, field: str) -> Choice:
    """``value`` as a member of ``choices``; else a :class:`ChoiceError` naming the ``field``
    (e.g. "CorrectionConfig.method"), the value and the allowed values."""
    try:
        return choices(value)
    except ValueError:
        raise ChoiceError(
            f"{field}: unknown {kind_of(choices)} {value!r}; choose from {allowed(choices)}"
        ) from None


def checked_letters(choices: type[StrEnum], text: str, field: str) -> str:
    """``text`` if it is one or more one-letter values of ``choices`` (e.g. GNSS systems
    "GE"); else a :class:`ChoiceError` naming the ``field``, the first unknown letter and the
    allowed ones."""
    if not isinstance(text, str) or not text:
        raise ChoiceError(f"{field}: expected letters among {allowed(choices)}, got {text!r}")
    for letter in text:
        checked(choices, letter, f"{field} = {text!r}")
    return text


def check_fields(config: object, **choices: type[StrEnum]) -> None:
    """Replace each named field of the dataclass ``config`` by its member of the given choice
    set (:func:`checked`; frozen dataclasses too), so that a configuration holds only members.
    For ``__post_init__``: ``check_fields(self, method=CorrectionMethod)``."""
    for name, kind in choices.items():
        member = checked(kind, getattr(config, name), f"{type(config).__name__}.{name}")
        object.__setattr__(config, name, member)
