"""Helpers of the batch tests: tiny generated drives shared by a test session, and ``prepare``
steps (importable, so spawned workers can unpickle them) that block, crash or fail on cue."""

from __future__ import annotations

import os
import time
from pathlib import Path

from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

BLOCK_DIR_ENV = "VO_DOPPLER_TEST_BLOCK_DIR"
"""Folder of flag files: while ``<name>`` exists there, recording ``<name>`` waits."""


def tiny_drive(tmp_path_factory, seed: int) -> Path:
    """An 8 s urban-canyon drive with 320×180 images at 10 Hz, generated once per test process (its
    users carry the ``xdist_group`` mark ``tiny_drives``)."""
    folder = tmp_path_factory.getbasetemp() / "tiny_drives" / f"drive{seed}"
    if not (folder / "sequence.yaml").exists():
        config = UrbanCanyonConfig(duration_s=8.0, seed=seed, fps=10.0, image_size_px=(320, 180))
        simulate_urban_canyon(folder, config)
    return folder


def imageless_drive(tmp_path_factory, seed: int) -> Path:
    """A 5 s urban-canyon drive without images, generated once per test process: for the tests
    of the batch machinery (markers, resumption), whose runs need no VO (3.5 s of CPU to
    generate and 0.2 s to run, against 10 s and 2.4 s for :func:`tiny_drive`)."""
    folder = tmp_path_factory.getbasetemp() / "imageless_drives" / f"drive{seed}"
    if not (folder / "sequence.yaml").exists():
        config = UrbanCanyonConfig(duration_s=5.0, seed=seed, render=False)
        simulate_urban_canyon(folder, config)
    return folder


def wait_while_blocked(source: Path, work_dir: Path) -> Path:
    """Prepare step that writes its pid to ``<block dir>/<name>.pid`` and waits while the flag
    file ``<block dir>/<name>`` exists; the recording is then used as it is."""
    block_dir = Path(os.environ[BLOCK_DIR_ENV])
    (block_dir / f"{source.name}.pid").write_text(str(os.getpid()))
    while (block_dir / source.name).exists():
        time.sleep(0.05)
    return source


def die_or_fail(source: Path, work_dir: Path) -> Path:
    """Prepare step: the worker process dies at once for ``crash*``, raises a plain exception
    (a bug) for ``bug*``, and returns the source (a sequence folder, or not) otherwise."""
    if source.name.startswith("crash"):
        os._exit(3)
    if source.name.startswith("bug"):
        raise RuntimeError(f"bug in the importer of {source.name}")
    return source


def opencv_thread_count(_: int) -> int:
    """A pool worker's OpenCV thread count (a module-level function, so spawn can pickle it)."""
    import cv2

    return cv2.getNumThreads()
