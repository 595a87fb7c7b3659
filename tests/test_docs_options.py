"""README.md, docs/outputs.md and docs/formats.md name only options that exist, on the command
they are written with (issue 30: the documents true to the code).

Where the documents write a command line (a backtick span, a line of a code block), every
``--option`` in it must be one of that command's options in ``--help`` (or a global one); any
other ``--option`` in the prose must be some command's. Benchmark lines
(``python benchmarks/NAME.py ...``) are checked against that script's own ``--help``. The shell
blocks' ``vo-doppler`` lines parse as written. The full lists stay in ``--help``, which the
README names as such."""

from __future__ import annotations

import argparse
import re
import shlex
import subprocess
import sys
from dataclasses import dataclass

import pytest

from tests.cli.test_help import PARSERS, _options
from tests.conftest import REPO_ROOT
from vo_doppler.cli import build_parser
from vo_doppler.commands.eval_command import gnss_parser

DOCS = ("README.md", "docs/outputs.md", "docs/formats.md")
OPTION = re.compile(r"(?<![\w-])--[a-z][a-z0-9-]*")
COMMAND = re.compile(r"vo-doppler((?:\s+[a-z][a-z0-9-]*)+)")
BENCHMARK = re.compile(r"python\s+(benchmarks/\w+\.py)")
FOREIGN = ("ray start", "pip install")
"""Command lines of other programs the README shows (their options are not ours)."""

ALL_PARSERS = {**PARSERS, "vo-doppler eval gnss": gnss_parser("vo-doppler eval gnss")}
"""``eval gnss`` parses its own arguments after ``eval``'s (a parser of its own)."""


def _option_strings(parser: argparse.ArgumentParser) -> set[str]:
    return {o for action in _options(parser) for o in action.option_strings}


GLOBAL = _option_strings(ALL_PARSERS["vo-doppler"]) | {"--help"}
OPTIONS = {name: _option_strings(parser) | GLOBAL for name, parser in ALL_PARSERS.items()}


@dataclass(frozen=True)
class Mention:
    """A piece of a document that names options: where it is and its text."""

    where: str
    text: str


def _fenced_lines(doc: str, text: str) -> list[Mention]:
    """The lines of the fenced code blocks, a line continued by a backslash joined to the next."""
    found = []
    for block in re.finditer(r"```\w*\n(.*?)```", text, re.S):
        line = text.count("\n", 0, block.start(1)) + 1
        for number, command in enumerate(block.group(1).replace("\\\n", " ").splitlines()):
            found.append(Mention(f"{doc}: code block at line {line} (+{number})", command))
    return found


def mentions() -> list[Mention]:
    """Every backtick span (the command table's too) and code-block line of the documents."""
    found = []
    for doc in DOCS:
        text = (REPO_ROOT / doc).read_text()
        found += _fenced_lines(doc, text)
        prose = re.sub(r"```.*?```", lambda m: "\n" * m.group().count("\n"), text, flags=re.S)
        for span in re.finditer(r"`([^`]+)`", prose):
            number = prose.count("\n", 0, span.start()) + 1
            found.append(Mention(f"{doc}:{number}", span.group(1)))
    return found


MENTIONS = mentions()


def command_of(text: str) -> str | None:
    """The longest known command a text starts its command line with, if it has one."""
    match = COMMAND.search(text)
    if match is None:
        return None
    words = match.group(1).split()
    for count in range(len(words), -1, -1):
        name = " ".join(["vo-doppler", *words[:count]])
        if name in ALL_PARSERS:
            return name
    return None


def test_the_documents_name_commands_and_options():
    """The scan finds what it checks: every command of the CLI is written with options."""
    commands = {command_of(m.text) for m in MENTIONS if OPTION.search(m.text)}
    assert {name for name, parser in ALL_PARSERS.items() if _options(parser)} - {
        "vo-doppler"
    } <= commands | {None}
    assert len([m for m in MENTIONS if OPTION.search(m.text)]) > 80


def test_every_option_written_with_a_command_is_one_of_its_options():
    wrong = []
    for mention in MENTIONS:
        name = command_of(mention.text)
        if name is None:
            continue
        after = mention.text[COMMAND.search(mention.text).start() :]
        wrong += [
            f"{mention.where}: {option} is not an option of {name}"
            for option in OPTION.findall(after)
            if option not in OPTIONS[name]
        ]
    assert not wrong, "\n".join(wrong)


def test_every_other_option_in_the_prose_is_some_commands():
    known = set().union(*OPTIONS.values())
    wrong = [
        f"{mention.where}: {option} is no command's option"
        for mention in MENTIONS
        if command_of(mention.text) is None
        and not BENCHMARK.search(mention.text)
        and not mention.text.startswith(FOREIGN)
        for option in OPTION.findall(mention.text)
        if option not in known
    ]
    assert not wrong, "\n".join(wrong)


def _benchmark_lines() -> dict[str, list[Mention]]:
    """The mentions of each benchmark script run with ``python``, by script."""
    lines: dict[str, list[Mention]] = {}
    for mention in MENTIONS:
        for script in BENCHMARK.findall(mention.text):
            lines.setdefault(script, []).append(mention)
    return lines


BENCHMARK_LINES = _benchmark_lines()


@pytest.mark.slow
@pytest.mark.parametrize(
    "script",
    sorted(s for s, lines in BENCHMARK_LINES.items() if any(OPTION.search(m.text) for m in lines)),
)
def test_every_option_of_a_benchmark_line_is_in_its_help(script):
    """``python benchmarks/NAME.py --help`` lists every option the documents give it."""
    written = {o for m in BENCHMARK_LINES[script] for o in OPTION.findall(m.text)}
    shown = subprocess.run(
        [sys.executable, script, "--help"],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    ).stdout
    assert written <= set(OPTION.findall(shown)), written - set(OPTION.findall(shown))


SHELL_COMMANDS = [
    m
    for m in MENTIONS
    if "code block" in m.where
    and m.text.lstrip().startswith("vo-doppler ")
    and not re.search(r"[\[(|…]", m.text.split("#")[0])
]
"""Runnable lines: a synopsis (``[--vel vel.csv]``, ``(A | B)``, ``…``) is only checked for
its option names."""


def test_the_shell_blocks_have_commands():
    assert len(SHELL_COMMANDS) >= 3


@pytest.mark.parametrize("mention", SHELL_COMMANDS, ids=lambda m: m.text.split()[1])
def test_a_shell_block_command_parses_as_written(mention):
    """Parsing only (argument types, choices, required options): the files need not exist."""
    words = shlex.split(mention.text, comments=True)[1:]
    args = build_parser(words[0]).parse_args(words)
    assert args.command == words[0]
