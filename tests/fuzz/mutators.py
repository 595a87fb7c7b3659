"""Mutations of text input files for the fuzz runner: each takes the bytes and a seeded random
generator and returns new bytes. Text mutations work on lines (duplicated, deleted, swapped,
moved blocks, extra header lines) or on fixed-width numeric fields (inf, nan, huge numbers, out of
range dates); byte mutations (flips, Latin-1 bytes, truncation) also apply to compressed files.

``SHRINKING`` names the mutations whose result should be a subset of the unmutated file's content
(lost lines or a cut end can lose records, never change them).
"""

from __future__ import annotations

import random
import re
from collections.abc import Callable

Mutation = Callable[[bytes, random.Random], bytes]

_NUMBER = re.compile(rb"-?\d+\.\d+(?:[DEde][+-]\d+)?")
_REPLACEMENTS = (
    b"inf",
    b"-inf",
    b"nan",
    b"NaN",
    b"1e308",
    b"9" * 25,
    b"-9" + b"9" * 15,
    b"0.0",
    b"-0.0",
    b"1.0E+99",
    b"9.999999999999D+99",
    b"-1",
    b"",
)
_DATE_FIELDS = (b"13", b"00", b"32", b"25", b"60", b"99", b"-1", b"inf", b"nan", b"1e9")


def _lines(data: bytes) -> list[bytes]:
    return data.split(b"\n")


def _join(lines: list[bytes]) -> bytes:
    return b"\n".join(lines)


def _header_end(lines: list[bytes]) -> int:
    """Index of the 'END OF HEADER' line (0 when absent)."""
    return next((i for i, line in enumerate(lines) if b"END OF HEADER" in line), 0)


def byte_flips(data: bytes, rng: random.Random) -> bytes:
    out = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        if out:
            out[rng.randrange(len(out))] = rng.randrange(256)
    return bytes(out)


def latin1_byte(data: bytes, rng: random.Random) -> bytes:
    position = rng.randrange(len(data) + 1)
    return data[:position] + bytes([rng.choice((0xE9, 0xB0, 0xFC, 0xA0, 0xFF))]) + data[position:]


def truncate(data: bytes, rng: random.Random) -> bytes:
    return data[: rng.randrange(len(data) + 1)]


def duplicate_line(data: bytes, rng: random.Random) -> bytes:
    lines = _lines(data)
    k = rng.randrange(len(lines))
    return _join([*lines[: k + 1], lines[k], *lines[k + 1 :]])


def delete_line(data: bytes, rng: random.Random) -> bytes:
    lines = _lines(data)
    del lines[rng.randrange(len(lines))]
    return _join(lines)


def swap_lines(data: bytes, rng: random.Random) -> bytes:
    lines = _lines(data)
    a = rng.randrange(len(lines))
    b = min(len(lines) - 1, a + rng.choice((1, 1, 2, rng.randrange(1, 400))))
    lines[a], lines[b] = lines[b], lines[a]
    return _join(lines)


def duplicate_block(data: bytes, rng: random.Random) -> bytes:
    """A run of body lines repeated right after itself (duplicated epochs or records)."""
    lines = _lines(data)
    start = rng.randrange(_header_end(lines) + 1, len(lines) + 1)
    stop = min(len(lines), start + rng.randint(2, 400))
    return _join(lines[:stop] + lines[start:stop] + lines[stop:])


def move_block(data: bytes, rng: random.Random) -> bytes:
    """A run of body lines moved elsewhere in the body (epochs or records out of order)."""
    lines = _lines(data)
    body = _header_end(lines) + 1
    start = rng.randrange(body, len(lines) + 1)
    stop = min(len(lines), start + rng.randint(2, 400))
    block, rest = lines[start:stop], lines[:start] + lines[stop:]
    at = rng.randrange(body, len(rest) + 1)
    return _join(rest[:at] + block + rest[at:])


def number_field(data: bytes, rng: random.Random) -> bytes:
    """One number replaced by inf, nan, a huge or odd value, right-aligned in the same width."""
    lines = _lines(data)
    for _ in range(20):
        k = rng.randrange(len(lines))
        found = list(_NUMBER.finditer(lines[k]))
        if found:
            match = rng.choice(found)
            width = match.end() - match.start()
            new = rng.choice(_REPLACEMENTS)
            new = new.rjust(width) if len(new) <= width or rng.random() < 0.5 else new
            lines[k] = lines[k][: match.start()] + new + lines[k][match.end() :]
            break
    return _join(lines)


def date_field(data: bytes, rng: random.Random) -> bytes:
    """A month, day, hour, minute or second of an epoch or record date made impossible."""
    lines = _lines(data)
    body = _header_end(lines) + 1
    dated = [
        i
        for i in range(body, len(lines))
        if re.match(rb"^(> |[A-Z][ \d]\d |[ \d]\d | [ \d]\d )\s*\d{2,4} [ \d]\d [ \d]\d", lines[i])
    ]
    if not dated:
        return data
    k = rng.choice(dated)
    fields = list(re.finditer(rb"\d+(?:\.\d+)?", lines[k][:30]))
    fields = [f for f in fields if f.start() >= 1][:7]
    if len(fields) < 2:
        return data
    match = rng.choice(fields[1:] if lines[k][:1].isalpha() or lines[k][:1] == b">" else fields)
    width = match.end() - match.start()
    new = rng.choice(_DATE_FIELDS).rjust(width)
    lines[k] = lines[k][: match.start()] + new + lines[k][match.end() :]
    return _join(lines)


def extra_header_lines(data: bytes, rng: random.Random) -> bytes:
    """Copies of one header line (up to 3,000) inserted before 'END OF HEADER'."""
    lines = _lines(data)
    end = _header_end(lines)
    if end == 0:
        return data
    k = rng.randrange(end)
    count = rng.choice((1, 2, 50, 3000))
    return _join(lines[:end] + [lines[k]] * count + lines[end:])


def long_line(data: bytes, rng: random.Random) -> bytes:
    """One line made very long (up to 1 MB)."""
    lines = _lines(data)
    k = rng.randrange(len(lines))
    lines[k] = lines[k] + rng.choice((b" ", b"9", b"x", b"1.000 ")) * rng.choice(
        (100, 10_000, 1 << 20)
    )
    return _join(lines)


def crlf(data: bytes, rng: random.Random) -> bytes:
    return data.replace(b"\n", b"\r\n")


TEXT_MUTATIONS: dict[str, Mutation] = {
    "byte_flips": byte_flips,
    "latin1_byte": latin1_byte,
    "truncate": truncate,
    "duplicate_line": duplicate_line,
    "delete_line": delete_line,
    "swap_lines": swap_lines,
    "duplicate_block": duplicate_block,
    "move_block": move_block,
    "number_field": number_field,
    "date_field": date_field,
    "extra_header_lines": extra_header_lines,
    "long_line": long_line,
    "crlf": crlf,
}
"""Mutations of the plain text (applied before any compression)."""
BYTE_MUTATIONS: dict[str, Mutation] = {"byte_flips": byte_flips, "truncate": truncate}
"""Mutations of the bytes as stored (applied after compression)."""
SHRINKING = frozenset({"truncate", "delete_line"})
