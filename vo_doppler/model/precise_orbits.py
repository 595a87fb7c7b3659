"""Precise satellite orbits and clocks as tabulated by the IGS products (SP3-c/d orbit files,
RINEX clock files): the satellite states of recordings that come without a navigation file.

Times are GPS seconds (the readers convert the file's time system). Positions are ECEF metres
in the product's terrestrial frame (IGS: ITRF, for every constellation), clocks are the
satellite clock offset t_sv − t_GPS in seconds *without* the periodic relativistic term (IGS
convention; the GNSS stage adds it). Missing values are NaN.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class SatelliteClocks:
    """Satellite clock offsets at the epochs ``t`` (M,): ``bias_s`` (M, N) for ``sat_id`` (N,)."""

    t: np.ndarray
    sat_id: np.ndarray
    bias_s: np.ndarray
    path: Path | None = None


@dataclass(frozen=True)
class PreciseOrbits:
    """SP3 tables at the regular epochs ``t`` (E,): ``position`` (E, N, 3) m and ``clock_s``
    (E, N) s of the satellites ``sat_id`` (N,) such as 'G05'. ``clocks`` (a RINEX clock file),
    when given, replaces the SP3 clock column (denser and the reference of the orbits' clocks).
    """

    t: np.ndarray
    sat_id: np.ndarray
    position: np.ndarray
    clock_s: np.ndarray
    time_system: str = "GPS"
    coordinate_system: str = ""
    agency: str = ""
    path: Path | None = None
    clocks: SatelliteClocks | None = None

    @property
    def interval_s(self) -> float:
        """Nominal spacing of the epochs (s); NaN with fewer than two epochs."""
        return float(np.median(np.diff(self.t))) if self.t.size > 1 else float("nan")

    def with_clocks(self, clocks: SatelliteClocks) -> PreciseOrbits:
        return replace(self, clocks=clocks)
