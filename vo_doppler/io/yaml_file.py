"""YAML inputs without alias bombs: aliases (``*name``) are refused, so a few hundred bytes
cannot expand into gigabytes, and the text itself is bounded by :mod:`vo_doppler.io.textfile`.
An integer longer than Python converts from text (4,300 digits) is a YAML error at its line."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from vo_doppler.errors import InputError
from vo_doppler.io.textfile import SMALL_MAX_BYTES, read_text


class NoAliasLoader(yaml.SafeLoader):
    """PyYAML's safe loader that stops at the first alias."""

    def compose_node(self, parent, index):
        if self.check_event(yaml.AliasEvent):
            mark = self.peek_event().start_mark
            raise yaml.composer.ComposerError(
                None, None, "YAML aliases (*name) are not accepted in inputs", mark
            )
        return super().compose_node(parent, index)

    def construct_yaml_int(self, node):
        try:
            return super().construct_yaml_int(node)
        except ValueError:
            digits = len(str(node.value))
            raise yaml.constructor.ConstructorError(
                None,
                None,
                f"an integer of {digits} characters is not a usable number",
                node.start_mark,
            ) from None


NoAliasLoader.add_constructor("tag:yaml.org,2002:int", NoAliasLoader.construct_yaml_int)


def load_yaml(path: str | Path, what: str, max_bytes: int = SMALL_MAX_BYTES) -> Any:
    """The parsed YAML of a bounded UTF-8 file; syntax errors, aliases and nesting too deep for
    the parser are an :class:`InputError` naming the file (and line when YAML gives one)."""
    text = read_text(path, what, max_bytes)
    try:
        return yaml.load(text, Loader=NoAliasLoader)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line = mark.line + 1 if mark is not None else None
        raise InputError(f"{what} is not valid YAML: {exc.problem or exc}", path, line) from exc
    except (yaml.YAMLError, RecursionError) as exc:
        raise InputError(f"{what} is not valid YAML: {type(exc).__name__}", path) from exc
