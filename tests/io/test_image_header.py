"""An image's size from its PNG or JPEG header, against the shape OpenCV decodes (the VO's),
and damaged headers named by file and byte."""

from __future__ import annotations

import io
import struct

import cv2
import numpy as np
import pytest
from PIL import Image

from tests.conftest import REPO_ROOT
from vo_doppler.errors import InputError
from vo_doppler.io.image_header import ImageHeaderError, image_size
from vo_doppler.io.images import list_images, probe_size

SAMPLE_IMAGES = REPO_ROOT / "sample_sequences" / "urban_canyon_small" / "image_0"


def decoded_size(path) -> tuple[int, int]:
    """(width, height) of the image as the VO decodes it."""
    image = cv2.imdecode(np.fromfile(path, dtype=np.uint8), cv2.IMREAD_GRAYSCALE)
    return image.shape[1], image.shape[0]


def pil_bytes(image: Image.Image, fmt: str, **options) -> bytes:
    buffer = io.BytesIO()
    image.save(buffer, fmt, **options)
    return buffer.getvalue()


def exif(orientation: int) -> bytes:
    tags = Image.Exif()
    tags[0x0112] = orientation
    return tags.tobytes()


def png_chunks(data: bytes) -> list[bytes]:
    chunks, at = [], 8
    while at < len(data):
        (length,) = struct.unpack(">I", data[at : at + 4])
        chunks.append(data[at : at + 12 + length])
        at += 12 + length
    return chunks


def test_the_samples_images_read_as_opencv_decodes_them():
    images = list_images(SAMPLE_IMAGES)
    for path in images[:: len(images) // 10]:
        assert image_size(path) == decoded_size(path) == (640, 360)


@pytest.mark.parametrize("orientation", range(1, 9))
@pytest.mark.parametrize("fmt", ["png", "jpeg"])
def test_every_exif_orientation_as_opencv_applies_it(tmp_path, fmt, orientation):
    path = tmp_path / f"o{orientation}.{fmt}"
    pixels = np.random.default_rng(orientation).integers(0, 256, (30, 50), np.uint8)
    path.write_bytes(pil_bytes(Image.fromarray(pixels), fmt, exif=exif(orientation)))
    expected = (30, 50) if orientation in (5, 6, 7, 8) else (50, 30)
    assert image_size(path) == decoded_size(path) == expected


@pytest.mark.parametrize(
    ("mode", "fmt", "options"),
    [
        ("L", "png", {}),
        ("RGB", "png", {}),
        ("RGBA", "png", {}),
        ("P", "png", {}),
        ("I;16", "png", {}),
        ("L", "jpeg", {}),
        ("RGB", "jpeg", {"progressive": True}),
        ("RGB", "jpeg", {"subsampling": 0, "quality": 95}),
        ("CMYK", "jpeg", {}),
    ],
)
def test_kinds_of_png_and_jpeg(tmp_path, mode, fmt, options):
    path = tmp_path / f"image.{fmt}"
    path.write_bytes(pil_bytes(Image.new(mode, (77, 23)), fmt, **options))
    assert image_size(path) == decoded_size(path) == (77, 23)


def test_an_exif_chunk_after_the_image_data_still_turns_a_png(tmp_path):
    """OpenCV reads a PNG's ``eXIf`` wherever it lies, so the reader reads on to IEND."""
    data = pil_bytes(Image.new("L", (50, 30)), "png", exif=exif(8))
    chunks = png_chunks(data)
    kinds = [chunk[4:8] for chunk in chunks]
    assert kinds == [b"IHDR", b"eXIf", b"IDAT", b"IEND"]
    moved = data[:8] + chunks[0] + chunks[2] + chunks[1] + chunks[3]
    path = tmp_path / "late.png"
    path.write_bytes(moved)
    assert image_size(path) == decoded_size(path) == (30, 50)


def test_fill_bytes_and_long_segments_before_the_frame_header(tmp_path):
    data = pil_bytes(Image.new("L", (64, 48)), "jpeg")
    comment = b"\xff\xfe" + struct.pack(">H", 60002) + bytes(60000)  # a COM segment
    path = tmp_path / "padded.jpg"
    path.write_bytes(data[:2] + comment + b"\xff\xff\xff" + data[3:])  # fill bytes, T.81 B.1.1.2
    assert image_size(path) == decoded_size(path) == (64, 48)


def damaged(tmp_path, name: str, data: bytes):
    path = tmp_path / name
    path.write_bytes(data)
    with pytest.raises(ImageHeaderError) as found:
        image_size(path)
    return str(found.value)


def test_damaged_png_headers_are_named_with_file_and_byte(tmp_path):
    data = pil_bytes(Image.new("L", (50, 30)), "png")
    assert damaged(tmp_path, "a.png", data[:20]) == (
        f"{tmp_path / 'a.png'}, byte 16: file ends inside the IHDR chunk (4 of 8 bytes)"
    )
    other = data[:12] + b"IDAT" + data[16:]
    assert "byte 8: the first PNG chunk is b'IDAT' of 13 bytes, not IHDR" in damaged(
        tmp_path, "b.png", other
    )
    zero = data[:16] + struct.pack(">I", 0) + data[20:]
    assert "byte 16: image of 0×30 px in its header" in damaged(tmp_path, "c.png", zero)
    assert "file ends inside the chunk header" in damaged(tmp_path, "d.png", data[:-12])


def test_damaged_jpeg_headers_are_named_with_file_and_byte(tmp_path):
    data = pil_bytes(Image.new("L", (50, 30)), "jpeg", exif=exif(6))
    assert "d.jpg, byte " in damaged(tmp_path, "d.jpg", data[:40])
    scan = data.index(b"\xff\xda")
    frame = data.index(b"\xff\xc0")
    no_frame = data[:frame] + data[scan:]
    assert f"byte {frame}: marker 0xDA before any frame header" in damaged(
        tmp_path, "e.jpg", no_frame
    )
    tiff = data.index(b"Exif\x00\x00") + 6
    bad_exif = data[:tiff] + b"XX" + data[tiff + 2 :]
    assert f"byte {tiff}: EXIF block without a TIFF header" in damaged(tmp_path, "f.jpg", bad_exif)
    far = data[: tiff + 4] + struct.pack(">I", 4000) + data[tiff + 8 :]
    assert "EXIF directory at 4000, beyond the block's" in damaged(tmp_path, "g.jpg", far)
    garbage = data[:2] + b"\x00" + data[3:]
    assert "byte 2: expected a JPEG marker (0xFF)" in damaged(tmp_path, "h.jpg", garbage)


def test_another_format_or_a_missing_file(tmp_path):
    assert "neither a PNG nor a JPEG image (starts with b'BM" in damaged(
        tmp_path, "x.bmp", pil_bytes(Image.new("L", (5, 3)), "bmp")
    )
    with pytest.raises(InputError, match="cannot read image"):
        image_size(tmp_path / "missing.png")


def test_probe_size_decodes_what_no_header_gives(tmp_path):
    """A BMP (no header read here) is measured by decoding it; a PNG cut before its end, whose
    IHDR alone is whole, is not measured (OpenCV does not decode it either: the VO flags it),
    nor is a PNG without IHDR."""
    (tmp_path / "a.bmp").write_bytes(pil_bytes(Image.new("L", (5, 3)), "bmp"))
    assert probe_size(tmp_path / "a.bmp") == (5, 3)
    whole = pil_bytes(Image.new("L", (50, 30)), "png")
    (tmp_path / "b.png").write_bytes(whole[:-12])
    assert probe_size(tmp_path / "b.png") is None
    (tmp_path / "c.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(30))
    assert probe_size(tmp_path / "c.png") is None
    (tmp_path / "d.png").write_bytes(whole)
    assert probe_size(tmp_path / "d.png") == (50, 30)
