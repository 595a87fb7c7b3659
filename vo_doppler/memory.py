"""Giving memory back to the system between the main job's steps: the C heap's free pages
(glibc's ``malloc_trim``), what only the cycle collector frees, and results parked on disk while
a long step that does not need them runs (:class:`Parked`)."""

from __future__ import annotations

import ctypes
import functools
import gc
import os
import pickle
import tempfile
from collections.abc import Callable
from typing import BinaryIO, Generic, TypeVar, cast

T = TypeVar("T")


@functools.cache
def _malloc_trim() -> Callable[[int], int] | None:
    return getattr(ctypes.CDLL(None), "malloc_trim", None)


def release_free_heap() -> None:
    """Give the C heap's free memory back to the system (glibc's ``malloc_trim``; nothing
    elsewhere). After a stage frees its large NumPy temporaries glibc keeps much of them
    resident: its mmap threshold rises to the largest block freed, so later large arrays come
    from the heap, whose free pages are returned only from its top."""
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


def release_cycles() -> None:
    """Free what only the cycle collector frees (a matplotlib figure already written is a web
    of reference cycles), then give the freed buffers back (:func:`release_free_heap`).

    When the caller froze what was alive (``vo-doppler run`` does, until it ends), what is
    alive after the collection is frozen too: mostly matplotlib's modules, imported by the
    first figure, which each later pass would otherwise walk again."""
    gc.collect()
    if gc.get_freeze_count():
        gc.freeze()
    release_free_heap()


RAM_FILE_SYSTEMS = frozenset({"tmpfs", "ramfs"})
"""File systems whose files are held in memory: a value parked there saves none."""


class Parked(Generic[T]):
    """``value`` kept in an unnamed temporary file on disk while a long step that does not
    need it runs, and read back by :meth:`take` (once): the main job parks the GNSS stage's
    result and the heading table through the VO, 19 MiB on a 30-minute drive (docs/benchmarks.md,
    "Memory"). Where the temporary folder is held in memory (:data:`RAM_FILE_SYSTEMS`, e.g. a
    tmpfs ``/tmp``), or cannot take the file (full, read-only), the value stays in memory,
    as it would without parking: nothing is lost and nothing is only moved out of sight."""

    def __init__(self, value: T, to_disk: bool = True) -> None:
        """``to_disk`` False keeps the value in memory (no long step to park it through)."""
        self._value: T | None = value
        self._file: BinaryIO | None = None
        if not to_disk or _file_system_of(tempfile.gettempdir()) in RAM_FILE_SYSTEMS:
            return
        try:
            file = tempfile.TemporaryFile(prefix="vo-doppler-parked-")  # noqa: SIM115 (open until take)
        except OSError:
            return
        try:
            pickle.dump(value, file, protocol=pickle.HIGHEST_PROTOCOL)
            file.flush()
        except OSError:
            file.close()
            return
        self._file, self._value = file, None

    @property
    def on_disk(self) -> bool:
        return self._file is not None

    def take(self) -> T:
        """The value, read back from its file (which is then deleted) if it was parked."""
        if self._file is None:
            return cast(T, self._value)
        with self._file as file:
            file.seek(0)
            self._file = None
            return pickle.load(file)


def _file_system_of(path: str) -> str:
    """The type of the file system ``path`` lies on (Linux's ``/proc/self/mountinfo``: its
    longest mount point that contains the path); empty where that cannot be read."""
    target = os.path.realpath(path)
    found, found_type = "", ""
    try:
        with open("/proc/self/mountinfo", encoding="utf-8", errors="replace") as mounts:
            for line in mounts:
                fields, _, rest = line.partition(" - ")
                parts = fields.split()
                if len(parts) < 5 or not rest:
                    continue
                mount_point = parts[4].replace("\\040", " ")
                inside = target == mount_point or target.startswith(mount_point.rstrip("/") + "/")
                if inside and len(mount_point) >= len(found):
                    found, found_type = mount_point, rest.split()[0]
    except OSError:
        return ""
    return found_type
