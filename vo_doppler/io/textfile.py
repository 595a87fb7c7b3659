"""Reading a text input safely: a regular file of bounded size, not binary, UTF-8, with bounded
lines. Every failure is an :class:`InputError` naming the file (and the line for encoding and
line-length problems), so no reader meets ``UnicodeDecodeError``, ``_csv.Error`` on a huge field,
or a device such as ``/dev/zero`` that never ends.
"""

from __future__ import annotations

import stat
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError

MIB = 1 << 20
DATA_MAX_BYTES = 2048 * MIB
"""Default bound on a sensor data file (a CAN log of hours stays far below it)."""
SMALL_MAX_BYTES = 16 * MIB
"""Bound on small configuration-like files (calibration, DBC, times, heading tables)."""
MAX_LINE_CHARS = 64 * 1024
"""Longest line (bytes) a text reader accepts (below the csv module's 128 KiB field limit)."""

# Leading bytes of binary formats a user may hand over by mistake, with their names.
MAGIC = (
    (b"\x89PNG\r\n\x1a\n", "PNG image"),
    (b"\xff\xd8\xff", "JPEG image"),
    (b"GIF8", "GIF image"),
    (b"BM", "BMP image"),
    (b"%PDF", "PDF document"),
    (b"\x1f\x8b", "gzip archive"),
    (b"PK\x03\x04", "zip archive"),
    (b"\x7fELF", "executable"),
    (b"LOGG", "BLF log"),
    (b"\x93NUMPY", "numpy array"),
)


def regular_file(path: str | Path, what: str, max_bytes: int = DATA_MAX_BYTES) -> int:
    """Size of ``path`` after checking it is a readable regular file of at most ``max_bytes``
    (devices, FIFOs and folders are refused: ``/dev/zero`` would never end)."""
    path = Path(path)
    try:
        info = path.stat()
    except OSError as exc:
        raise InputError(f"cannot read {what}: {exc.strerror or exc}", path) from exc
    if not stat.S_ISREG(info.st_mode):
        kind = "a folder" if stat.S_ISDIR(info.st_mode) else "not a regular file"
        raise InputError(f"{what} is {kind}", path)
    if info.st_size > max_bytes:
        raise InputError(
            f"{what} is {info.st_size} bytes, more than the {max_bytes // MIB} MiB this reader "
            "accepts",
            path,
        )
    return info.st_size


def binary_kind(head: bytes) -> str | None:
    """Name of the binary format ``head`` (a file's first bytes) starts, None for text."""
    for magic, name in MAGIC:
        if head.startswith(magic):
            return name
    if b"\0" in head[:8192]:
        return "binary file (NUL bytes)"
    return None


def read_bytes(path: str | Path, what: str, max_bytes: int = DATA_MAX_BYTES) -> bytes:
    """The bytes of a regular file of at most ``max_bytes`` (re-checked while reading: a file
    growing past the bound is refused). Reads the size ``stat`` gave in one call, so no buffer
    of ``max_bytes`` is ever allocated."""
    size = regular_file(path, what, max_bytes)
    try:
        with Path(path).open("rb") as handle:
            data = handle.read(size + 1)
            while len(data) > size and len(data) <= max_bytes:
                more = handle.read(MIB)
                if not more:
                    break
                data += more
    except OSError as exc:
        raise InputError(f"cannot read {what}: {exc.strerror or exc}", path) from exc
    if len(data) > max_bytes:
        raise InputError(f"{what} grew beyond {max_bytes // MIB} MiB while being read", path)
    return data


def decode_text(data: bytes, path: str | Path, what: str, max_line: int = MAX_LINE_CHARS) -> str:
    """UTF-8 text of ``data`` (a BOM is dropped); binary content, a byte that is not UTF-8 or a
    line longer than ``max_line`` bytes is an :class:`InputError` naming the line."""
    kind = binary_kind(data[:8192])
    if kind is not None:
        raise InputError(f"{what} is a {kind}, not a text file", path)
    check_line_lengths(data, path, what, max_line)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        raise InputError(
            f"{what} is not UTF-8 text (byte 0x{data[exc.start]:02X}); save it as UTF-8",
            path,
            line,
        ) from exc
    return text


def check_line_lengths(data: bytes, path: str | Path, what: str, max_line: int) -> None:
    """Raise naming the first line longer than ``max_line`` bytes (one linear pass over the
    newline positions; a character is at least a byte, so no longer line passes)."""
    if len(data) <= max_line:
        return
    ends = np.flatnonzero(np.frombuffer(data, dtype=np.uint8) == 10)
    starts = np.concatenate([[0], ends + 1])
    lengths = np.concatenate([ends, [len(data)]]) - starts
    long = np.flatnonzero(lengths > max_line)
    if long.size:
        raise InputError(
            f"{what} line has {lengths[long[0]]} bytes, more than {max_line}",
            path,
            int(long[0]) + 1,
        )


def read_text(
    path: str | Path, what: str, max_bytes: int = DATA_MAX_BYTES, max_line: int = MAX_LINE_CHARS
) -> str:
    """The UTF-8 text of a regular text file, bounded in size and line length."""
    return decode_text(read_bytes(path, what, max_bytes), path, what, max_line)


LINES_PIECE_CHARS = 1 << 20
"""Characters of a text split into lines at once by :func:`text_lines`."""


def text_lines(text: str, piece_chars: int = LINES_PIECE_CHARS) -> Iterator[str]:
    """The lines of ``text`` as ``text.splitlines()`` gives them, split a piece of about
    ``piece_chars`` at a time (each piece ends after a line feed, which ends a line
    whatever precedes it): a reader going through them once never holds every line at once
    (the 180,000 lines of a 30-min ground truth at 100 Hz are 28 MiB as strings)."""
    start = 0
    while start < len(text):
        cut = text.find("\n", start + piece_chars)
        end = len(text) if cut < 0 else cut + 1
        yield from text[start:end].splitlines()
        start = end
