"""GNSS observations in columns: one row per (epoch, satellite, observable), on GPS time.

Filled by the RINEX reader (:mod:`vo_doppler.io.rinex_obs`) and by the importers of other
receiver formats; read by the GNSS stage.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np


@dataclass(frozen=True)
class ObsHeader:
    """Header fields of a RINEX observation file (RINEX 3.05 Table A2, RINEX 2.11 Table A1)."""

    path: Path
    version: float
    system: str
    marker_name: str
    receiver_type: str
    approx_position: np.ndarray | None
    interval: float | None
    obs_types: dict[str, tuple[str, ...]]
    glonass_channels: dict[int, int]
    time_system: str
    leap_seconds: int | None
    signal_strength_unit: str
    n_lines: int


@dataclass(frozen=True)
class Observations:
    """Columnar observations: one row per (epoch, satellite, observable) with a value.

    ``time`` GPS seconds; ``system`` one letter; ``prn`` satellite number; ``code`` an index into
    ``codes`` (RINEX 3 three-character codes such as ``D1C``, RINEX 2 two-character codes such as
    ``D1`` kept as written); ``lli`` and ``ssi`` −1 where blank. ``epoch_time``/``epoch_flag``
    list the data epochs. ``problems`` holds one message per problem the reader met: a skipped
    record, or a header value read otherwise than written (e.g. an unknown time system).
    ``row_fields`` holds per-row values a format carries beyond RINEX's, by name, each an array
    aligned with ``value`` (smartLoc's NLOS label and σ, :mod:`vo_doppler.io.smartloc`); empty
    for RINEX. :meth:`subset` keeps them with their rows.
    """

    header: ObsHeader
    time: np.ndarray
    system: np.ndarray
    prn: np.ndarray
    code: np.ndarray
    codes: tuple[str, ...]
    value: np.ndarray
    lli: np.ndarray
    ssi: np.ndarray
    epoch_time: np.ndarray
    epoch_flag: np.ndarray
    problems: tuple[str, ...] = field(default=())
    row_fields: dict[str, np.ndarray] = field(default_factory=dict)

    def __len__(self) -> int:
        return int(self.value.size)

    def satellites(self) -> np.ndarray:
        """Satellite identifiers ('G05', 'R12', …) per row."""
        if self.prn.size == 0:
            return np.zeros(0, dtype="U3")
        return np.char.add(self.system, np.char.zfill(self.prn.astype(str), 2))

    def code_index(self, code: str) -> int:
        """Index of an observable code in ``codes`` (−1 when absent)."""
        return self.codes.index(code) if code in self.codes else -1

    def codes_of(self, system: str) -> list[str]:
        """Observable codes present for one system."""
        used = np.unique(self.code[self.system == system])
        return [self.codes[i] for i in used]

    def mask(self, system: str | None = None, code: str | None = None) -> np.ndarray:
        """Boolean row mask for a system and/or an observable code."""
        keep = np.ones(self.value.size, dtype=bool)
        if system is not None:
            keep &= self.system == system
        if code is not None:
            keep &= self.code == self.code_index(code)
        return keep

    def subset(self, rows: np.ndarray) -> Observations:
        """The observations of the given rows (mask or indices), same header and codes."""
        return Observations(
            header=self.header,
            time=self.time[rows],
            system=self.system[rows],
            prn=self.prn[rows],
            code=self.code[rows],
            codes=self.codes,
            value=self.value[rows],
            lli=self.lli[rows],
            ssi=self.ssi[rows],
            epoch_time=self.epoch_time,
            epoch_flag=self.epoch_flag,
            problems=self.problems,
            row_fields={name: values[rows] for name, values in self.row_fields.items()},
        )

    def epochs_only(self) -> Observations:
        """These observations without a row: their header, codes, epochs and problems, what is
        read of them once the GNSS stage has run (the rows of a 30-min drive at 20 Hz are
        11 MiB)."""
        return self.subset(np.zeros(0, dtype=int))

    def select(self, system: str | None = None, code: str | None = None) -> Observations:
        """Rows of one system and/or observable code."""
        return self.subset(self.mask(system, code))

    def matrix(self, code: str, system: str | None = None) -> tuple[np.ndarray, np.ndarray]:
        """One observable as an (epoch × satellite) array, NaN where absent.

        Returns the satellite identifiers (columns, sorted) and the values; rows follow
        ``epoch_time``.
        """
        rows = self.select(system, code)
        sats = rows.satellites()
        names, column = np.unique(sats, return_inverse=True)
        values = np.full((self.epoch_time.size, names.size), np.nan)
        values[np.searchsorted(self.epoch_time, rows.time), column] = rows.value
        return names, values


def row_keys(epoch_time: np.ndarray, time, system, prn, code=None) -> np.ndarray:
    """Integer key per row from (epoch, system, prn[, code]) for joining rows of one file."""
    epoch = np.searchsorted(epoch_time, np.asarray(time, dtype=float)).astype(np.int64)
    letters = np.array([ord(s) for s in system], dtype=np.int64).reshape(epoch.shape)
    key = (epoch * 128 + letters) * 128 + np.asarray(prn, dtype=np.int64)
    return key if code is None else key * 4096 + np.asarray(code, dtype=np.int64)


def lookup(keys: np.ndarray, values: np.ndarray, wanted: np.ndarray) -> np.ndarray:
    """values[i] where keys[i] == wanted, NaN where no key matches."""
    out = np.full(wanted.shape, np.nan)
    if keys.size == 0 or wanted.size == 0:
        return out
    order = np.argsort(keys)
    pos = np.clip(np.searchsorted(keys[order], wanted), 0, keys.size - 1)
    hit = keys[order][pos] == wanted
    out[hit] = values[order][pos[hit]]
    return out
