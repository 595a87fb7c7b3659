"""Docstrings and comments state the method and point to the record; measured benchmark figures
live in docs/benchmarks.md (issue 32). A scan of every module's docstrings (module, class,
function and attribute docstrings: every string statement) and comments fails, naming the file
and the line, on

* a commit hash: a word of 7 to 40 hexadecimal digits with at least one digit 0–9 and one
  letter a–f (figures "at <commit>" belong to the record; digit-only words such as a preamble's
  bits and letter-only words such as "defaced" are not hashes);
* a reported measurement: the word "measured" (or "re-measured") used as the verb of a report
  — followed by a colon or by one of the prepositions of ``REPORT_PREPOSITIONS`` ("measured on
  comma2k19: …", "measured with 1/2/3: …") — and later in the same sentence a number with a
  unit of ``FIGURE_UNIT``.

Not figures, by rule: "measured" as an adjective ("the measured speed: above 0.5 m/s", "measured
and keyframe flags"); rates in Hz and signal strengths in dB-Hz (they describe the recording a
figure was taken on, "measured on the drive at 1 Hz"); text inside double quotes (a section
title of docs/benchmarks.md such as "Error per 100 m", in a pointer to the record, even when
it runs over a line break). A sentence
ends at a full stop followed by white space or the end of the text, or at a blank line.
"""

from __future__ import annotations

import ast
import io
import re
import tokenize
from collections.abc import Iterator
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "vo_doppler"
REPORT_PREPOSITIONS = ("on", "with", "without", "at", "in", "over", "from", "against", "for", "by")
COMMIT_HASH = re.compile(r"\b(?=[0-9a-f]*[0-9])(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}\b")
MEASURED = re.compile(
    r"\b(?:re-)?measured(?=\s*:|\s+(?:" + "|".join(REPORT_PREPOSITIONS) + r")\b)", re.IGNORECASE
)
FIGURE_UNIT = re.compile(
    r"(?<![\w.])\d+(?:[.,]\d+)?\s?(?:%|°|×|(?:m/s²|m/s|°/s|ms|px|km|[kMG]i?B|m|s)(?![\w/-]))"
)
SENTENCE_END = re.compile(r"\.(?=\s|$)|\n\s*\n")
QUOTED = re.compile(r'"[^"]*"')


def prose(source: str) -> Iterator[tuple[int, str]]:
    """(first line, text) of every comment and every string statement of ``source``."""
    for token in tokenize.generate_tokens(io.StringIO(source).readline):
        if token.type == tokenize.COMMENT:
            yield token.start[0], token.string
    for node in ast.walk(ast.parse(source)):
        if (
            isinstance(node, ast.Expr)
            and isinstance(node.value, ast.Constant)
            and isinstance(node.value.value, str)
        ):
            yield node.lineno, node.value.value


def figures(text: str) -> Iterator[tuple[int, str]]:
    """(line offset within ``text``, what) of each benchmark figure ``text`` states."""
    for match in COMMIT_HASH.finditer(text):
        yield text.count("\n", 0, match.start()), f"commit hash {match.group()}"
    for match in MEASURED.finditer(text):
        end = SENTENCE_END.search(text, match.end())
        sentence = QUOTED.sub('""', text[match.end() : end.start() if end else len(text)])
        figure = FIGURE_UNIT.search(sentence)
        if figure:
            offset = text.count("\n", 0, match.start())
            yield offset, f"measured figure {figure.group()!r}"


def violations(package: Path = PACKAGE) -> list[str]:
    """``file:line: what`` of every benchmark figure in the docstrings and comments of
    ``package``, by file and line."""
    found = []
    for path in sorted(package.rglob("*.py")):
        name = path.relative_to(package.parent).as_posix()
        in_file = sorted(
            (line + offset, what)
            for line, text in prose(path.read_text())
            for offset, what in figures(text)
        )
        found += [f"{name}:{line}: {what}" for line, what in in_file]
    return found


def test_no_docstring_or_comment_states_a_measured_figure():
    assert violations() == []


def test_the_scan_names_figures_and_passes_methods(tmp_path):
    package = tmp_path / "vo_doppler"
    (package / "vo").mkdir(parents=True)
    (package / "vo" / "bad.py").write_text(
        '"""Window of 20 frames.\n\n'
        'Measured on comma2k19: 0.45° heading error."""\n'
        "WINDOW = 20\n"
        "# error per 100 m 0.61 -> 0.55 at 3b8ff1c\n"
        "SPLIT = 0.5\n"
        '"""Re-measured with 3\n    on the sample: 0.82 m per 100 m."""\n'
    )
    (package / "vo" / "good.py").write_text(
        '"""Speed of light (m/s) and a lateral acceleration bound of 10 m/s²."""\n'
        "C = 299792458.0\n"
        "# The measured speed: a median speed above 0.5 m/s.\n"
        '"""Measured on the Hong Kong drive at 1 Hz (docs/benchmarks.md, "Error per\n'
        '    100 m on the simulator\'s drives")."""\n'
        '"""Preamble 11100010010, a facade deadbeef; measured. Then 3 m."""\n'
        "TIME = 'abc1234' + 'measured on: 5 m'\n"
    )
    assert violations(package) == [
        "vo_doppler/vo/bad.py:3: measured figure '0.45°'",
        "vo_doppler/vo/bad.py:5: commit hash 3b8ff1c",
        "vo_doppler/vo/bad.py:7: measured figure '0.82 m'",
    ]
