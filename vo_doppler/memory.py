"""Giving freed memory back to the system between the main job's steps: the C heap's free pages
(glibc's ``malloc_trim``) and what only the cycle collector frees."""

from __future__ import annotations

import ctypes
import functools
import gc
from collections.abc import Callable


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
