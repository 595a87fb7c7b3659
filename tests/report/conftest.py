"""A ``vo-doppler run`` report of a short generated drive, shared by the report tests."""

from __future__ import annotations

from pathlib import Path

import pytest

from vo_doppler.cli import main
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon


@pytest.fixture(scope="session")
def run_report(tmp_path_factory) -> Path:
    """Folder of ``vo-doppler run`` outputs (report.html, …) on a 12 s simulated drive."""
    sequence = tmp_path_factory.mktemp("report_drive") / "seq"
    simulate_urban_canyon(
        sequence, UrbanCanyonConfig(duration_s=12.0, seed=2, image_size_px=(320, 180))
    )
    out = tmp_path_factory.mktemp("report_run")
    assert main(["run", str(sequence), "-o", str(out)]) == 0
    return out
