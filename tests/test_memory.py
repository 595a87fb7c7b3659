"""Releasing memory: ``malloc_trim(0)`` is called when the C library has it (the heap's free
pages go back to the system); a written figure's reference cycles are collected, and when the
caller froze what was alive, what survives the collection is frozen too (later passes skip
it); a parked value waits in a temporary file on disk, and stays in memory where that would
save nothing or cannot be written."""

from __future__ import annotations

import errno
import gc
import pickle
import tempfile
import weakref
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler import memory
from vo_doppler.memory import Parked, _malloc_trim, release_cycles, release_free_heap
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


@pytest.fixture
def disk_temp(tmp_path, monkeypatch):
    """The temporary folder on this test's (disk) folder; skipped where that is a RAM file
    system, on which nothing is parked."""
    if memory._file_system_of(str(tmp_path)) in memory.RAM_FILE_SYSTEMS:
        pytest.skip(f"{tmp_path} is on a RAM file system: nothing is parked there")
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    return tmp_path


def _value() -> dict:
    return {
        "t": np.linspace(0.0, 1.0, 100_001),
        "rotation": Rotation.from_euler("z", np.linspace(-3.0, 3.0, 7)[:, None]),
        "name": "s1",
    }


def test_a_parked_value_leaves_memory_and_comes_back_equal(disk_temp):
    value = _value()
    expected_t, expected_quat = value["t"].copy(), value["rotation"].as_quat()
    parked = Parked(value)
    released = weakref.ref(value["t"].base if value["t"].base is not None else value["t"])
    del value
    gc.collect()
    assert parked.on_disk and released() is None  # nothing of it is held here any more
    back = parked.take()
    np.testing.assert_array_equal(back["t"], expected_t)
    np.testing.assert_array_equal(back["rotation"].as_quat(), expected_quat)
    assert back["name"] == "s1" and back["t"].flags.writeable
    assert not parked.on_disk and list(disk_temp.iterdir()) == []


def test_no_long_step_ahead_or_a_ram_file_system_keeps_the_value_in_memory(disk_temp, monkeypatch):
    value = _value()
    kept = Parked(value, to_disk=False)
    assert not kept.on_disk and kept.take() is value
    monkeypatch.setattr(memory, "_file_system_of", lambda path: "tmpfs")
    in_ram = Parked(value)
    assert not in_ram.on_disk and in_ram.take() is value


def test_a_temporary_folder_that_cannot_take_the_file_keeps_the_value_in_memory(
    disk_temp, monkeypatch
):
    value = _value()
    monkeypatch.setattr(tempfile, "tempdir", str(disk_temp / "missing"))
    assert Parked(value).take() is value

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(tempfile, "tempdir", str(disk_temp))
    monkeypatch.setattr(pickle, "dump", full)
    parked = Parked(value)
    assert not parked.on_disk and parked.take() is value


@pytest.mark.skipif(not Path("/proc/self/mountinfo").exists(), reason="Linux's mount table")
def test_the_file_system_is_the_longest_mount_point_holding_the_path():
    assert memory._file_system_of("/proc/self") == "proc"
    assert memory._file_system_of("/") not in ("", "proc")
