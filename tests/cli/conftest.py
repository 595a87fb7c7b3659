"""Fixtures shared by the command tests: a short simulated drive with its vehicle signals as
CSV files, whole and cut to a span as text (``--start`` / ``--end``, ``run --heading``)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.helpers.cut_recording import csv_sequence, cut_copy
from vo_doppler.cli import main
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

SPAN_START_S = 4.025
"""``--start`` of the span tests: seconds from the first epoch (between samples of every
sensor, so that no sample lies on a bound)."""
SPAN_END_S = 12.025
"""The span's end, from the first epoch (given as a GPS time)."""


@dataclass(frozen=True)
class SpanDrive:
    """The whole drive, the drive cut to [first + start, first + end] (GPS), and the first GNSS
    epoch."""

    full: Path
    cut: Path
    first: float

    @property
    def begin(self) -> float:
        return self.first + SPAN_START_S

    @property
    def end(self) -> float:
        return self.first + SPAN_END_S


@pytest.fixture(scope="session")
def span_drive(tmp_path_factory) -> SpanDrive:
    """A 16-s simulated canyon drive (320×180 images at 10 Hz) and its 8-s cut."""
    root = tmp_path_factory.mktemp("span")
    config = UrbanCanyonConfig(duration_s=16.0, seed=2, fps=10.0, image_size_px=(320, 180))
    simulate_urban_canyon(root / "simulated", config)
    full = csv_sequence(root / "simulated", root / "full")
    first = float(read_obs(full / "gnss" / "rover.obs").epoch_time[0])
    cut = cut_copy(full, root / "cut", first + SPAN_START_S, first + SPAN_END_S)
    return SpanDrive(full, cut, first)


@pytest.fixture(scope="session")
def span_cut_run(span_drive, tmp_path_factory) -> Path:
    """The folder ``vo-doppler -q run`` writes for the cut drive (heading.csv, summary.json,
    the trajectories), once per test process (group ``span_drive``). Read-only."""
    out = tmp_path_factory.mktemp("span_cut_run") / "out"
    assert main(["-q", "run", str(span_drive.cut), "-o", str(out)]) == 0
    return out
