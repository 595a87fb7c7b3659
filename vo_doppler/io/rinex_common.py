"""Shared pieces of the RINEX readers: opening (plain, gzip, Hatanaka), header splitting.

RINEX header records carry their label in columns 61–80 (RINEX 3.05 sec. 5.1).
"""

from __future__ import annotations

import gzip
import logging
from pathlib import Path

import hatanaka

from vo_doppler.errors import InputError

log = logging.getLogger(__name__)

LABEL_COLUMN = 60


def read_rinex_bytes(path: str | Path) -> bytes:
    """File contents as plain RINEX text (bytes, ``\\n`` line ends).

    gzip (``.gz``), Unix compress (``.Z``) and Hatanaka-compressed (``.crx``, ``.YYd``) files are
    expanded; Hatanaka decoding uses the ``hatanaka`` package (RNXCMP format 1.0 and 3.0).
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read file: {exc.strerror}", path) from exc
    try:
        if raw[:2] == b"\x1f\x8b":
            raw = gzip.decompress(raw)
        if raw[:2] == b"\x1f\x9d" or b"COMPACT RINEX" in raw[:80]:
            raw = hatanaka.decompress(raw)
    except (OSError, EOFError, ValueError) as exc:
        raise InputError(f"cannot decompress: {exc}", path) from exc
    if b"\r" in raw[:4096]:
        raw = raw.replace(b"\r\n", b"\n")
    return raw


def split_header(path: Path, text: bytes) -> tuple[list[str], list[bytes]]:
    """Header lines (decoded) and body lines (bytes, without line ends)."""
    end = text.find(b"END OF HEADER")
    if end < 0:
        raise InputError("no 'END OF HEADER' record: not a RINEX file or truncated header", path)
    header_end = text.find(b"\n", end)
    header_end = len(text) if header_end < 0 else header_end + 1
    header = text[:header_end].decode("ascii", errors="replace").splitlines()
    body = text[header_end:].split(b"\n")
    if body and body[-1] == b"":
        body.pop()
    return header, body


def label(line: str) -> str:
    """Header record label (columns 61–80)."""
    return line[LABEL_COLUMN:].strip()


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
        raise InputError(f"file type {file_type!r} is not one of {expected_type!r}", path, 1)
    system = first[40:41].upper() or "G"
    return version, file_type, system if system.strip() else "G"
