"""Shared pieces of the RINEX readers: opening (plain, gzip, Unix compress, Hatanaka) within
size limits, encoding and header splitting, calendar and satellite-number validation.

RINEX header records carry their label in columns 61–80 (RINEX 3.05 sec. 5.1); RINEX files are
ASCII (RINEX 3.05 sec. 4: "the character set is ASCII"), so a byte above 0x7F is refused except
inside free-text header records, where it is replaced by '?'.
"""

from __future__ import annotations

import gzip
import io
import logging
import math
import re
import stat
import subprocess
import tempfile
import zlib
from importlib import resources
from pathlib import Path
from typing import BinaryIO

import hatanaka
import ncompress

from vo_doppler.errors import InputError

log = logging.getLogger(__name__)

LABEL_COLUMN = 60
MAX_TEXT_BYTES = 1 << 30
"""Largest RINEX text read (plain or after decompression), 1 GiB."""
MIN_EXPANDED_LIMIT = 16 << 20
EXPANSION_RATIO = 40
"""A compressed file may expand to max(16 MiB, 40 × its size): gzip reaches 4–10× on RINEX and
Hatanaka + gzip 10–20×, so a larger ratio is a decompression bomb, refused before it fills
memory."""
HATANAKA_RATIO = 8
"""Compact RINEX expands at most about 8× (a 16-character field written as one digit and a
space), so the Hatanaka input may be at most 1/8 of the expanded limit."""
_CHUNK = 1 << 20
FREE_TEXT_LABELS = frozenset(
    {
        "COMMENT",
        "MARKER NAME",
        "MARKER NUMBER",
        "OBSERVER / AGENCY",
        "PGM / RUN BY / DATE",
        "REC # / TYPE / VERS",
        "ANT # / TYPE",
    }
)
PRN_RANGE = {
    "G": (1, 32),
    "R": (1, 27),
    "E": (1, 36),
    "C": (1, 63),
    "J": (1, 10),
    "I": (1, 14),
    "S": (20, 59),
}
"""Satellite numbers per system letter (RINEX 3.05 sec. 3.5: GPS PRN, GLONASS slot with 25–27
for receivers' spare slots, Galileo SVID, BeiDou PRN, QZSS PRN − 192, NavIC PRN, SBAS PRN − 100)."""
FIRST_YEAR, LAST_YEAR = 1980, 2099
_NON_ASCII = re.compile(rb"[\x80-\xff]")


class SizeLimitError(Exception):
    """Raised inside a capped writer when decompressed data exceed the limit."""


def expanded_limit(compressed_size: int) -> int:
    """Largest text accepted from a compressed file of the given size (bytes)."""
    return min(MAX_TEXT_BYTES, max(MIN_EXPANDED_LIMIT, EXPANSION_RATIO * compressed_size))


def read_rinex_bytes(path: str | Path, problems: list[str] | None = None) -> bytes:
    """File contents as plain RINEX text (bytes, ``\\n`` line ends).

    gzip (``.gz``), Unix compress (``.Z``) and Hatanaka-compressed (``.crx``, ``.YYd``) files are
    expanded, streamed with a cap (:func:`expanded_limit`); Hatanaka decoding runs the ``crx2rnx``
    program shipped with the ``hatanaka`` package (RNXCMP format 1.0 and 3.0). Every failure
    (unreadable file, corrupt or oversized compressed data) is an InputError naming the file,
    except a gzip stream damaged or cut short after whole lines of text when ``problems`` is
    given: the complete lines before the damage are returned, as for a truncated plain file,
    and the damage is added to ``problems`` naming the first line lost.
    """
    path = Path(path)
    try:
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):
            raise InputError("not a regular file", path)
        if info.st_size > MAX_TEXT_BYTES:  # refused before a byte is read
            raise InputError(
                f"file is {info.st_size} bytes, larger than the {MAX_TEXT_BYTES >> 20} MiB "
                "this reader accepts",
                path,
            )
        with path.open("rb") as stream:
            raw = _read_until_nul(stream, path, problems)
    except OSError as exc:
        raise InputError(f"cannot read file: {exc.strerror or exc}", path) from exc
    if len(raw) > MAX_TEXT_BYTES:
        raise InputError(f"file grew beyond {MAX_TEXT_BYTES >> 20} MiB while being read", path)
    limit = expanded_limit(len(raw))
    try:
        if raw[:2] == b"\x1f\x8b":
            raw = _gunzip(raw, limit, keep_partial=problems is not None)
        elif raw[:2] == b"\x1f\x9d":
            raw = _uncompress(raw, limit)
        if b"COMPACT RINEX" in raw[:80]:
            raw = _crx2rnx(raw, limit)
    except _DamagedStreamError as damaged:
        raw = damaged.text[: damaged.text.rfind(b"\n") + 1]
        lines = raw.count(b"\n")
        add_problem(
            problems,
            path,
            lines + 1,
            f"gzip data damaged or cut short here ({_one_line(damaged.cause)}): the {lines} "
            "lines before are read, the rest of the file is lost",
        )
    except SizeLimitError as exc:
        raise InputError(f"decompressed data exceed {limit >> 20} MiB: {exc}", path) from exc
    except (OSError, EOFError, ValueError, RuntimeError, zlib.error) as exc:
        raise InputError(f"cannot decompress: {_one_line(exc)}", path) from exc
    if b"\r" in raw:
        raw = raw.replace(b"\r\n", b"\n")
    return raw


def _read_until_nul(stream: BinaryIO, path: Path, problems: list[str] | None) -> bytes:
    """The bytes of a file (at most :data:`MAX_TEXT_BYTES` + 1), read a chunk at a time; a
    text file (not gzip or compress data) ends at its first NUL byte, which no RINEX line
    holds: a logger's reserved space it never wrote, or a sparse file. With ``problems`` the
    complete lines before it are kept and a problem names the line (as for a truncated file);
    without, it is an :class:`InputError`. Nothing after it is read."""
    chunks: list[bytes] = []
    size = 0
    while size <= MAX_TEXT_BYTES and (chunk := stream.read(_CHUNK)):
        if not chunks and chunk[:2] in (b"\x1f\x8b", b"\x1f\x9d"):  # compressed: NULs are data
            return chunk + stream.read(MAX_TEXT_BYTES + 1 - len(chunk))
        nul = chunk.find(b"\0")
        if nul >= 0:
            chunks.append(chunk[:nul])
            text = b"".join(chunks)
            line = text.count(b"\n") + 1
            message = "NUL bytes where a line should be: the file ends here (not RINEX text)"
            if problems is None:
                raise InputError(message, path, line)
            add_problem(problems, path, line, f"{message}; the {line - 1} lines before are read")
            return text[: text.rfind(b"\n") + 1]
        chunks.append(chunk)
        size += len(chunk)
    return b"".join(chunks)


def _one_line(exc: Exception) -> str:
    text = " ".join(str(exc).split())
    return (text[:200] + "…") if len(text) > 200 else text or type(exc).__name__


class _DamagedStreamError(Exception):
    """A compressed stream that broke after ``text`` was decoded (``cause``: why)."""

    def __init__(self, text: bytes, cause: Exception):
        super().__init__(str(cause))
        self.text, self.cause = text, cause


def _gunzip(raw: bytes, limit: int, keep_partial: bool = False) -> bytes:
    """gzip members decompressed in chunks, stopping as soon as the output exceeds ``limit``;
    with ``keep_partial`` a stream that breaks after a complete line raises
    :class:`_DamagedStreamError` with the text decoded so far."""
    out = bytearray()
    with gzip.GzipFile(fileobj=io.BytesIO(raw)) as stream:
        try:
            while chunk := stream.read1(_CHUNK):  # read1: what was decoded before a break
                out += chunk
                if len(out) > limit:
                    raise SizeLimitError("gzip data expand further")
        except (OSError, EOFError, zlib.error) as exc:
            if keep_partial and b"\n" in out:
                raise _DamagedStreamError(bytes(out), exc) from exc
            raise
    return bytes(out)


class _CappedWriter(io.RawIOBase):
    def __init__(self, limit: int):
        self.data = bytearray()
        self.limit = limit

    def writable(self) -> bool:
        return True

    def write(self, chunk) -> int:
        self.data += chunk
        if len(self.data) > self.limit:
            raise SizeLimitError("compress (.Z) data expand further")
        return len(chunk)


def _uncompress(raw: bytes, limit: int) -> bytes:
    """Unix compress (LZW) data through ``ncompress``, capped like gzip."""
    writer = _CappedWriter(limit)
    ncompress.decompress(raw, writer)
    return bytes(writer.data)


def _crx2rnx(raw: bytes, limit: int) -> bytes:
    """Compact RINEX expanded by the ``crx2rnx`` program of the ``hatanaka`` package, its output
    read in chunks and the program stopped when the output exceeds ``limit``."""
    if len(raw) > limit // HATANAKA_RATIO:
        raise SizeLimitError(f"Compact RINEX text of {len(raw) >> 20} MiB")
    program = resources.files(hatanaka.bin).joinpath("crx2rnx")
    with tempfile.TemporaryFile() as source, tempfile.TemporaryFile() as errors:
        source.write(raw)
        source.seek(0)
        process = subprocess.Popen(
            [str(program), "-"], stdin=source, stdout=subprocess.PIPE, stderr=errors
        )
        out = bytearray()
        try:
            while chunk := process.stdout.read(_CHUNK):
                out += chunk
                if len(out) > limit:
                    raise SizeLimitError("Compact RINEX data expand further")
        finally:
            process.stdout.close()
            if process.poll() is None:
                process.kill()
            code = process.wait()
        errors.seek(0)
        message = errors.read(4096).decode("ascii", "replace")
    if code not in (0, 2):
        raise hatanaka.HatanakaException(message or f"crx2rnx exited with {code}")
    return bytes(out)


def split_header(path: Path, text: bytes) -> tuple[list[str], list[bytes]]:
    """Header lines (decoded) and body lines (bytes, without line ends).

    Raises InputError naming the line when a byte outside ASCII is found, except in free-text
    header records (comment, names, agency), where such bytes become '?'.
    """
    end = text.find(b"END OF HEADER")
    if end < 0:
        raise InputError("no 'END OF HEADER' record: not a RINEX file or truncated header", path)
    header_end = text.find(b"\n", end)
    header_end = len(text) if header_end < 0 else header_end + 1
    header_bytes, body_bytes = text[:header_end], text[header_end:]
    header = _decode_header(path, header_bytes)
    if not body_bytes.isascii():
        _refuse_non_ascii(path, body_bytes, len(header))
    body = body_bytes.split(b"\n")
    if body and body[-1] == b"":
        body.pop()
    return header, body


def _decode_header(path: Path, header_bytes: bytes) -> list[str]:
    lines = header_bytes.split(b"\n")
    if lines and lines[-1] == b"":
        lines.pop()
    if header_bytes.isascii():
        return [line.decode("ascii") for line in lines]
    decoded = []
    for number, line in enumerate(lines, start=1):
        if not line.isascii():
            text = line.decode("ascii", "replace").replace("\ufffd", "?")
            if label(text) not in FREE_TEXT_LABELS:
                _refuse_non_ascii(path, line, number - 1)
            line = text.encode("ascii")
        decoded.append(line.decode("ascii"))
    return decoded


def _refuse_non_ascii(path: Path, text: bytes, lines_before: int) -> None:
    match = _NON_ASCII.search(text)
    assert match is not None
    line = lines_before + text.count(b"\n", 0, match.start()) + 1
    column = match.start() - (text.rfind(b"\n", 0, match.start()) + 1) + 1
    raise InputError(
        f"byte 0x{match.group()[0]:02X} in column {column} is not ASCII (RINEX is an ASCII format)",
        path,
        line,
    )


MAX_LOGGED_PROBLEMS = 20
"""Problems logged one by one per file; the others are only listed (and counted in the log)."""


def add_problem(problems: list[str], path: Path, line: int, message: str) -> None:
    """Record a skipped record as 'file:line: message', logging the first ones of the file."""
    text = f"{path}:{line}: {message}"
    if len(problems) < MAX_LOGGED_PROBLEMS:
        log.warning(text)
    elif len(problems) == MAX_LOGGED_PROBLEMS:
        log.warning("%s: more problems follow; only their count is logged", path)
    problems.append(text)


def log_problem_count(problems: list[str], path: Path) -> None:
    """Say how many problems were not logged one by one."""
    if len(problems) > MAX_LOGGED_PROBLEMS:
        log.warning("%s: %d problems in all", path, len(problems))


def label(line: str) -> str:
    """Header record label (columns 61–80)."""
    return line[LABEL_COLUMN:].strip()


RINEX_FILE_KINDS = {
    "O": "an observation file",
    "N": "a navigation file",
    "G": "a GLONASS navigation file",
    "L": "a Galileo navigation file (RINEX 2)",
    "M": "a meteorological file",
    "C": "a clock file",
}
"""RINEX 'RINEX VERSION / TYPE' file type letters in words (RINEX 3.05 Table A1)."""


def parse_version_line(path: Path, header: list[str], expected_type: str) -> tuple[float, str, str]:
    """Format version, file type letter and system letter from 'RINEX VERSION / TYPE'."""
    first = header[0] if header else ""
    if label(first) != "RINEX VERSION / TYPE":
        raise InputError("first line is not a 'RINEX VERSION / TYPE' record", path, 1)
    try:
        version = float(first[:9])
    except ValueError as exc:
        raise InputError(f"unreadable RINEX version {first[:9].strip()!r}", path, 1) from exc
    if not (2.0 <= version < 5.0):
        raise InputError(f"unsupported RINEX version {version}", path, 1)
    file_type = first[20:21].upper()
    if file_type not in expected_type:
        raise InputError(
            f"RINEX file type {file_type!r} where {' or '.join(expected_type)!r} is expected: "
            f"this looks like {RINEX_FILE_KINDS.get(file_type, 'another kind of file')}"
            f"{' (observation and navigation files swapped?)' if file_type in 'ONGL' else ''}",
            path,
            1,
        )
    system = first[40:41].upper() or "G"
    return version, file_type, system if system.strip() else "G"


def parse_calendar(text: bytes) -> tuple[int, int, int, int, int, float]:
    """Year, month, day, hour, minute (integers) and seconds of a RINEX epoch field.

    Two-digit years are 1980–2079 (RINEX 2.11 sec. 6.5). Raises ValueError saying what is wrong
    when a field is missing, not a number, not finite, not an integer where one is needed, or out
    of the calendar (month 1–12, day within the month, hour 0–23, minute 0–59, second 0–60.999…,
    year 1980–2099).
    """
    parts = text.split()
    if len(parts) != 6:
        raise ValueError(f"{len(parts)} date fields instead of 6")
    try:
        numbers = [float(p) for p in parts]
    except ValueError as exc:
        raise ValueError("date field is not a number") from exc
    if not all(math.isfinite(x) for x in numbers):
        raise ValueError("date field is not finite")
    if any(x != int(x) for x in numbers[:5]):
        raise ValueError("year, month, day, hour or minute is not an integer")
    year, month, day, hour, minute = (int(x) for x in numbers[:5])
    second = numbers[5]
    if year < 100 and len(parts[0]) <= 2:
        year += 2000 if year < 80 else 1900
    if not FIRST_YEAR <= year <= LAST_YEAR:
        raise ValueError(f"year {year} outside {FIRST_YEAR}–{LAST_YEAR}")
    if not 1 <= month <= 12:
        raise ValueError(f"month {month}")
    if not 1 <= day <= _days_in_month(year, month):
        raise ValueError(f"day {day} of month {month}")
    if not (0 <= hour <= 23 and 0 <= minute <= 59 and 0.0 <= second < 61.0):
        raise ValueError(f"time {hour}:{minute}:{second:g}")
    return year, month, day, hour, minute, second


def _days_in_month(year: int, month: int) -> int:
    if month == 2:
        leap = year % 4 == 0 and (year % 100 != 0 or year % 400 == 0)
        return 29 if leap else 28
    return 30 if month in (4, 6, 9, 11) else 31


def prn_in_range(system: str, prn: int) -> bool:
    """Whether a satellite number is valid for its system (:data:`PRN_RANGE`)."""
    low, high = PRN_RANGE.get(system, (1, 99))
    return low <= prn <= high
