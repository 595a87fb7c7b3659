"""The size of a PNG or JPEG image read from its header, as OpenCV decodes the image, without
decoding it or loading OpenCV (about 24 MiB resident, needed only by the VO stage).

The size is the PNG's ``IHDR`` chunk (ISO/IEC 15948, sec. 11.2.2) or the JPEG's frame header
``SOFn`` (ITU-T T.81, sec. B.2.2), with width and height exchanged when the image's EXIF
orientation (tag 274, CIPA DC-008 sec. 4.6.4) is one of the four that turn it a quarter (5–8):
OpenCV's ``imread``/``imdecode`` apply that orientation, from a JPEG's ``APP1 Exif`` segment or
a PNG's ``eXIf`` chunk. Anything else in a header that is not as the format states is an
:class:`ImageHeaderError` naming the file, the byte and what was found."""

from __future__ import annotations

import struct
from pathlib import Path
from typing import BinaryIO

from vo_doppler.errors import InputError

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
JPEG_START = b"\xff\xd8"
EXIF_PREFIX = b"Exif\x00\x00"
ORIENTATION_TAG = 0x0112
QUARTER_TURNS = frozenset({5, 6, 7, 8})
"""EXIF orientations whose display exchanges the stored image's axes."""
SOF_MARKERS = frozenset(range(0xC0, 0xD0)) - {0xC4, 0xC8, 0xCC}
"""Frame headers (T.81 Table B.1): every ``SOFn``; C4 (DHT), C8 (JPG) and CC (DAC) are not."""
STANDALONE_MARKERS = frozenset({0x01, *range(0xD0, 0xD8)})
"""Markers without a length (TEM, RST0–7)."""
SCAN_OR_END = frozenset({0xDA, 0xD9})
"""Start of scan and end of image: a frame header must come before either."""
MAX_DIMENSION = 2**31 - 1
"""PNG's bound on a width or height (sec. 11.2.2)."""


class ImageHeaderError(InputError):
    """An image header that does not follow its format (or a format this module does not
    read): the message names the file and, where it applies, the byte."""


def image_size(path: str | Path) -> tuple[int, int]:
    """(width, height) in pixels of the PNG or JPEG image ``path`` as OpenCV decodes it (EXIF
    orientation applied); an :class:`ImageHeaderError` for another format or a damaged header,
    an :class:`InputError` when the file cannot be read."""
    try:
        with open(path, "rb") as file:
            start = file.read(len(PNG_SIGNATURE))
            if start == PNG_SIGNATURE:
                return _png_size(file, path)
            if start[:2] == JPEG_START:
                file.seek(2)
                return _jpeg_size(file, path)
    except OSError as exc:
        raise InputError(f"cannot read image ({exc})", path) from exc
    raise ImageHeaderError(f"neither a PNG nor a JPEG image (starts with {start[:8]!r})", path)


def _exact(file: BinaryIO, count: int, path: str | Path, what: str) -> bytes:
    at = file.tell()
    data = file.read(count)
    if len(data) != count:
        raise ImageHeaderError(
            f"file ends inside the {what} ({len(data)} of {count} bytes)", path, byte=at
        )
    return data


def _png_size(file: BinaryIO, path: str | Path) -> tuple[int, int]:
    """IHDR, then the chunks up to IEND for an ``eXIf`` (read over by their lengths)."""
    length, kind = struct.unpack(">I4s", _exact(file, 8, path, "first chunk header"))
    if kind != b"IHDR" or length != 13:
        raise ImageHeaderError(
            f"the first PNG chunk is {kind!r} of {length} bytes, not IHDR of 13", path, byte=8
        )
    width, height = struct.unpack(">II", _exact(file, 8, path, "IHDR chunk"))
    _check_dimensions(width, height, path, 16)
    file.seek(5 + 4, 1)  # the rest of IHDR's data, its CRC
    orientation = None
    while True:
        at = file.tell()
        length, kind = struct.unpack(">I4s", _exact(file, 8, path, "chunk header"))
        if kind == b"IEND":
            break
        if kind == b"eXIf" and orientation is None:
            orientation = _exif_orientation(_exact(file, length, path, "eXIf chunk"), path, at + 8)
            file.seek(4, 1)
        else:
            file.seek(length + 4, 1)
    return _oriented(width, height, orientation)


def _jpeg_size(file: BinaryIO, path: str | Path) -> tuple[int, int]:
    """The markers after SOI, read over by their lengths up to the first frame header; the
    first ``APP1 Exif`` segment's orientation."""
    orientation = None
    while True:
        at = file.tell()
        if _exact(file, 1, path, "marker") != b"\xff":
            raise ImageHeaderError("expected a JPEG marker (0xFF)", path, byte=at)
        marker = _exact(file, 1, path, "marker")[0]
        while marker == 0xFF:  # fill bytes before a marker (T.81 B.1.1.2)
            marker = _exact(file, 1, path, "marker")[0]
        if marker in STANDALONE_MARKERS:
            continue
        if marker in SCAN_OR_END or marker == 0xD8:
            raise ImageHeaderError(f"marker 0x{marker:02X} before any frame header", path, byte=at)
        (length,) = struct.unpack(">H", _exact(file, 2, path, "segment length"))
        if length < 2:
            raise ImageHeaderError(f"segment length {length} (at least 2)", path, byte=at + 2)
        body = at + 4
        if marker in SOF_MARKERS:
            if length < 8:
                raise ImageHeaderError(
                    f"frame header of {length} bytes (at least 8)", path, byte=at
                )
            _, height, width = struct.unpack(">BHH", _exact(file, 5, path, "frame header"))
            _check_dimensions(width, height, path, body + 1)
            return _oriented(width, height, orientation)
        if marker == 0xE1 and orientation is None:
            segment = _exact(file, length - 2, path, "APP1 segment")
            if segment.startswith(EXIF_PREFIX):
                orientation = _exif_orientation(segment[len(EXIF_PREFIX) :], path, body + 6)
        else:
            file.seek(length - 2, 1)


def _exif_orientation(tiff: bytes, path: str | Path, offset: int) -> int | None:
    """The orientation tag of an EXIF block's first image directory (a TIFF structure starting
    at file byte ``offset``), None when it has none. A PNG ``eXIf`` may repeat the JPEG's
    ``Exif`` prefix; it is passed over."""
    if tiff.startswith(EXIF_PREFIX):
        tiff, offset = tiff[len(EXIF_PREFIX) :], offset + len(EXIF_PREFIX)
    order = {b"II": "<", b"MM": ">"}.get(tiff[:2])
    if order is None or len(tiff) < 8 or struct.unpack(order + "H", tiff[2:4])[0] != 42:
        raise ImageHeaderError("EXIF block without a TIFF header (II/MM, 42)", path, byte=offset)
    (directory,) = struct.unpack(order + "I", tiff[4:8])
    if directory + 2 > len(tiff):
        raise ImageHeaderError(
            f"EXIF directory at {directory}, beyond the block's {len(tiff)} bytes",
            path,
            byte=offset,
        )
    (count,) = struct.unpack(order + "H", tiff[directory : directory + 2])
    entries = directory + 2
    if entries + 12 * count > len(tiff):
        raise ImageHeaderError(
            f"EXIF directory of {count} entries runs past the block's {len(tiff)} bytes",
            path,
            byte=offset + directory,
        )
    for k in range(count):
        entry = entries + 12 * k
        tag, kind, _, value = struct.unpack(order + "HHIH", tiff[entry : entry + 10])
        if tag == ORIENTATION_TAG:
            return value if kind == 3 else None  # a SHORT, as the standard has it
    return None


def _check_dimensions(width: int, height: int, path: str | Path, at: int) -> None:
    if not (0 < width <= MAX_DIMENSION and 0 < height <= MAX_DIMENSION):
        raise ImageHeaderError(f"image of {width}×{height} px in its header", path, byte=at)


def _oriented(width: int, height: int, orientation: int | None) -> tuple[int, int]:
    return (height, width) if orientation in QUARTER_TURNS else (width, height)
