"""A ``vo-doppler run`` report of a short generated drive, shared by the report tests."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture(scope="session")
def run_report(short_drive_run) -> Path:
    """Folder of ``vo-doppler run`` outputs (report.html, …) on a 10 s simulated drive, the
    run the damaged-input tests compare with (group ``short_drive``). Read-only."""
    return short_drive_run
