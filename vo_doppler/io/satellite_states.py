"""The satellite-state files of a recording: broadcast navigation (RINEX nav) or precise
orbits (SP3) with an optional RINEX clock file; the GNSS stage accepts either model type."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from vo_doppler.errors import InputError
from vo_doppler.io.rinex_clock import read_rinex_clock
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.sp3 import read_sp3
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.precise_orbits import PreciseOrbits


def read_satellite_states(
    nav: Sequence[Path] | None = None,
    orbits: Path | None = None,
    clocks: Path | None = None,
) -> Navigation | PreciseOrbits:
    """Precise orbits (with ``clocks`` attached) when ``orbits`` is given, else the merged
    navigation files; one of the two is required."""
    if orbits is not None:
        precise = read_sp3(orbits)
        return precise if clocks is None else precise.with_clocks(read_rinex_clock(clocks))
    if clocks is not None:
        raise InputError("a clock file needs precise orbits (SP3) beside it", clocks)
    if not nav:
        raise InputError("no satellite states: give navigation files or precise orbits")
    return read_nav(list(nav))


def state_problems(source: Navigation | PreciseOrbits) -> tuple[str, ...]:
    """Records the reader skipped (precise products are rejected whole instead)."""
    return source.problems if isinstance(source, Navigation) else ()
