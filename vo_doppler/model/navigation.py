"""Broadcast navigation records (ephemerides) in columns, one array per parameter."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class NavRecords:
    """Columnar broadcast records of one kind: ``params[name]`` is an array with a row per record.

    ``toc`` (clock reference) is in GPS seconds. For Keplerian records ``toe`` is the full GPS
    time of the ephemeris reference epoch (from its second of week, within half a week of toc).
    """

    system: np.ndarray
    prn: np.ndarray
    toc: np.ndarray
    params: dict[str, np.ndarray]
    line: np.ndarray

    def __len__(self) -> int:
        return int(self.prn.size)

    def __getitem__(self, name: str) -> np.ndarray:
        return self.params[name]

    def subset(self, rows) -> NavRecords:
        return NavRecords(
            self.system[rows],
            self.prn[rows],
            self.toc[rows],
            {k: v[rows] for k, v in self.params.items()},
            self.line[rows],
        )


@dataclass(frozen=True)
class Navigation:
    """Broadcast ephemerides of one or more navigation files."""

    kepler: NavRecords
    glonass: NavRecords
    leap_seconds: int | None = None
    problems: tuple[str, ...] = field(default=())
    klobuchar: np.ndarray | None = None
    skipped: dict[str, int] = field(default_factory=dict)
    """Records not read, counted by RINEX 4 type ('EPH CNAV', 'STO LNAV', …)."""

    def merged(self, other: Navigation) -> Navigation:
        skipped = dict(self.skipped)
        for kind, count in other.skipped.items():
            skipped[kind] = skipped.get(kind, 0) + count
        return Navigation(
            concat_records(self.kepler, other.kepler),
            concat_records(self.glonass, other.glonass),
            self.leap_seconds if self.leap_seconds is not None else other.leap_seconds,
            self.problems + other.problems,
            self.klobuchar if self.klobuchar is not None else other.klobuchar,
            skipped,
        )

    def glonass_channels(self) -> dict[int, int]:
        """GLONASS frequency channel per slot, from the records."""
        channel = self.glonass["channel"]
        return {int(p): int(k) for p, k in zip(self.glonass.prn, channel, strict=True)}


def concat_records(a: NavRecords, b: NavRecords) -> NavRecords:
    return NavRecords(
        np.concatenate([a.system, b.system]),
        np.concatenate([a.prn, b.prn]),
        np.concatenate([a.toc, b.toc]),
        {k: np.concatenate([a.params[k], b.params[k]]) for k in a.params},
        np.concatenate([a.line, b.line]),
    )
