"""Image-sequence input: a folder of PNG/JPG images sorted by name, and their timestamps
from ``times.txt`` (one time per line, KITTI style), a CSV, or a fixed frame rate."""

from __future__ import annotations

import csv
import itertools
import logging
import os
from collections import deque
from collections.abc import Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.io.image_header import image_size
from vo_doppler.io.textfile import read_text
from vo_doppler.model.camera import Camera
from vo_doppler.model.image_files import ImageFiles

log = logging.getLogger(__name__)

IMAGE_MAX_BYTES = 256 << 20
"""Largest image file read (an uncompressed 8K frame is 100 MB); a larger one is a damaged
frame, not read."""
IMAGE_SUFFIXES = {".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".pgm"}


def list_images(folder: str | Path) -> ImageFiles:
    """Image files of a folder (or its ``image_0`` subfolder), sorted by name."""
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError("image folder does not exist", folder)
    names = sorted(n for n in os.listdir(folder) if Path(n).suffix.lower() in IMAGE_SUFFIXES)
    if not names and (folder / "image_0").is_dir():
        return list_images(folder / "image_0")
    if not names:
        raise InputError("no PNG/JPG images in folder", folder)
    return ImageFiles.in_folder(folder, names)


def read_image(path: Path) -> np.ndarray | None:
    """Grey uint8 image, or ``None`` (with a warning) when the file cannot be read or decoded
    (:func:`decode_image`)."""
    image, problem = decode_image(path)
    if image is None:
        log.warning("%s: %s; the frame is flagged and bridged", path, problem)
    return image


def decode_image(path: Path) -> tuple[np.ndarray | None, str]:
    """The grey uint8 image of ``path``, or None and why not (a file larger than
    ``IMAGE_MAX_BYTES``, unreadable, or not an image OpenCV decodes).

    The file is read by Python and decoded from memory: ``cv2.imread`` encodes the path as
    UTF-8, and a name that is not (bytes ``\\xff``, held as a lone surrogate) crashes OpenCV
    with a segmentation fault."""
    import cv2  # OpenCV (16 MiB resident) is loaded by the first image read, not with the package

    try:
        size = Path(path).stat().st_size
        if size > IMAGE_MAX_BYTES:
            return None, f"image of {size} bytes, more than {IMAGE_MAX_BYTES >> 20} MiB: not read"
        data = np.fromfile(path, dtype=np.uint8)
    except OSError as exc:
        return None, f"cannot read image ({exc})"
    image = cv2.imdecode(data, cv2.IMREAD_GRAYSCALE) if data.size else None
    return image, "" if image is not None else "cannot decode image"


def check_image_size(camera: Camera, images: list[Path], calibration: str | Path) -> None:
    """Raise an :class:`InputError` naming the ``calibration`` file, the first image and both
    sizes when the images are not of the size the calibration states
    (:meth:`~vo_doppler.model.camera.Camera.size_mismatch`): checked on the first image whose
    size is known (of the first :data:`MAX_SIZE_PROBES`), before any work; the VO checks every
    frame again."""
    if not (camera.width and camera.height):
        return
    for path in images[:MAX_SIZE_PROBES]:
        size = probe_size(path)
        if size is None:  # an unreadable one is the VO's to flag
            continue
        mismatch = camera.size_mismatch(*size)
        if mismatch:
            raise InputError(f"{mismatch} (first image {path})", calibration)
        return


def probe_size(path: Path) -> tuple[int, int] | None:
    """(width, height) of the image ``path`` as the VO will decode it: from a PNG or JPEG
    header (:func:`~vo_doppler.io.image_header.image_size`, so that OpenCV loads with the VO,
    not with the reader), otherwise, or when that header is damaged, from decoding the image
    (:func:`decode_image`); None when it does not decode."""
    try:
        return image_size(path)
    except InputError:
        image, _ = decode_image(path)
        return None if image is None else (image.shape[1], image.shape[0])


MAX_SIZE_PROBES = 5
"""Images tried, from the first, for one that decodes to check its size (an unreadable one is
flagged later by the VO)."""


def prefetch_images(paths: Iterable[Path], depth: int = 4) -> Iterator[np.ndarray | None]:
    """:func:`read_image` of every path, in order, decoded by a background thread that keeps up
    to ``depth`` images ready (OpenCV releases the GIL while decoding, so decoding overlaps the
    caller's work on another core)."""
    if depth < 1:
        raise ValueError(f"prefetch depth must be at least 1, got {depth}")
    remaining = iter(paths)
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="image-prefetch") as pool:
        pending = deque(pool.submit(read_image, p) for p in itertools.islice(remaining, depth))
        try:
            while pending:
                image = pending.popleft().result()
                pending.extend(pool.submit(read_image, p) for p in itertools.islice(remaining, 1))
                yield image
        finally:
            for future in pending:
                future.cancel()


def read_times(path: str | Path, n_images: int) -> np.ndarray:
    """Timestamps for ``n_images`` frames from ``times.txt`` or a CSV with a ``t`` column.

    A CSV may have a header naming ``t`` (or ``timestamp``); a plain file has one number a line.
    Times must increase strictly; the count must equal the number of images.
    """
    path = Path(path)
    text = read_text(path, "timestamps file")
    rows = [
        (number, line.strip())
        for number, line in enumerate(text.splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    column = 0
    if rows and not _is_number(next(csv.reader([rows[0][1]]))[0]):
        header = [h.strip().lower() for h in next(csv.reader([rows[0][1]]))]
        for name in ("t", "timestamp", "time", "t_s"):
            if name in header:
                column = header.index(name)
                break
        else:
            raise InputError(f"CSV header {header} has no 't' or 'timestamp' column", path, 1)
        rows = rows[1:]
    times = np.empty(len(rows))
    for k, (number, line) in enumerate(rows):
        fields = next(csv.reader([line])) if "," in line else line.split()
        try:
            times[k] = float(fields[column])
        except (ValueError, IndexError) as exc:
            raise InputError(
                f"timestamp is not a number (field {column + 1})", path, number
            ) from exc
    if len(times) != n_images:
        raise InputError(f"{len(times)} timestamps for {n_images} images", path)
    steps = np.diff(times)
    if np.any(~np.isfinite(times)) or np.any(steps <= 0):
        bad = int(np.flatnonzero(~(steps > 0))[0]) + 1 if np.any(~(steps > 0)) else 0
        raise InputError(
            f"timestamps must increase strictly (row {bad + 1} of the data is not after the one "
            "before)",
            path,
            rows[bad][0] if rows else None,
        )
    return times


def times_from_fps(fps: float, n_images: int) -> np.ndarray:
    if not fps > 0:
        raise InputError(f"frame rate must be positive, got {fps}")
    return np.arange(n_images) / fps


def find_times_file(images_folder: Path) -> Path | None:
    """``times.txt`` inside the image folder or beside it (KITTI layout), if present."""
    for candidate in (images_folder / "times.txt", images_folder.parent / "times.txt"):
        if candidate.is_file():
            return candidate
    return None


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True
