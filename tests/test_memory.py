"""Releasing memory: ``malloc_trim(0)`` is called when the C library has it (the heap's free
pages go back to the system); a written figure's reference cycles are collected, and when the
caller froze what was alive, what survives the collection is frozen too (later passes skip
it)."""

from __future__ import annotations

import gc
import weakref

from vo_doppler import memory
from vo_doppler.memory import _malloc_trim, release_cycles, release_free_heap
from vo_doppler.report.figure import new_figure


def test_release_free_heap_calls_malloc_trim_with_no_padding(monkeypatch):
    calls = []
    monkeypatch.setattr(memory, "_malloc_trim", lambda: calls.append)
    assert release_free_heap() is None
    assert calls == [0]


def test_release_free_heap_does_nothing_without_malloc_trim(monkeypatch):
    monkeypatch.setattr(memory, "_malloc_trim", lambda: None)
    assert release_free_heap() is None


def test_release_free_heap_runs_with_this_c_library():
    trim = _malloc_trim()
    assert trim is None or callable(trim)
    assert _malloc_trim() is trim  # looked up once
    assert release_free_heap() is None


def _tracked(value: object) -> bool:
    """Whether the collector's passes walk ``value`` (frozen objects are left out)."""
    return any(o is value for o in gc.get_objects())


def _garbage_figure() -> weakref.ref:
    fig = new_figure(figsize=(2, 2))
    fig.subplots().plot([0.0, 1.0])
    return weakref.ref(fig)


def test_under_a_freeze_the_figure_is_freed_and_the_survivors_frozen():
    gc.freeze()
    try:
        survivor = [[]]
        figure = _garbage_figure()
        assert _tracked(survivor) and figure() is not None
        release_cycles()
        assert figure() is None
        assert not _tracked(survivor)
    finally:
        gc.unfreeze()
    assert _tracked(survivor)


def test_without_a_freeze_nothing_is_frozen():
    survivor = [[]]
    figure = _garbage_figure()
    release_cycles()
    assert figure() is None
    assert gc.get_freeze_count() == 0
    assert _tracked(survivor)
