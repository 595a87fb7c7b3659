"""Releasing a written figure: its reference cycles are collected, and when the caller froze
what was alive, what survives the collection is frozen too (later passes skip it)."""

from __future__ import annotations

import gc
import weakref

from vo_doppler.report.figure import new_figure
from vo_doppler.report.run_outputs import release_figures


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
        release_figures()
        assert figure() is None
        assert not _tracked(survivor)
    finally:
        gc.unfreeze()
    assert _tracked(survivor)


def test_without_a_freeze_nothing_is_frozen():
    survivor = [[]]
    figure = _garbage_figure()
    release_figures()
    assert figure() is None
    assert gc.get_freeze_count() == 0
    assert _tracked(survivor)
