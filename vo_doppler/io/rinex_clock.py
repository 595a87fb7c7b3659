"""RINEX clock files (versions 2.00 to 3.04, "RINEX Extensions to Handle Clock Information")
→ :class:`SatelliteClocks`.

Only the satellite records ``AS`` are kept (receiver ``AR``, calibration and discontinuity
records are skipped). A record reads ``AS <name> yyyy mm dd hh mi ss.ssssss n bias [σ …]``,
the values continuing on the next line when n > 2; it is split on blanks, which reads both the
4-character names of 3.02 and the 9-character names of 3.04. The time system is the header's
``TIME SYSTEM ID`` (GPS when absent). CRLF line endings are accepted; errors name the line.

The header layout depends on the version (the clock format documents of 2.00, 3.02 and 3.04):
up to 3.02 the first line is ``F9.2,11X,A1,19X,A1`` with the labels in columns 61–80, so the
file type ``C`` is in column 21; 3.04 widened the header to ``F4.2,17X,A1,20X,A1`` with the
labels in columns 66–85, the type in column 22 (and the satellite system in column 43).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.io.rinex_common import parse_calendar
from vo_doppler.io.sp3 import MAX_CLOCK_S, TIME_SYSTEMS, satellite_id, text_lines, to_gps_seconds
from vo_doppler.model.gpstime import calendar_to_gps_seconds
from vo_doppler.model.precise_orbits import SatelliteClocks

VALUES_PER_LINE = 2
MAX_VALUES = 6
VERSIONS = (2.0, 3.0, 3.01, 3.02, 3.04)
"""The versions of the clock format published (there is no 3.03)."""
WIDE_HEADER_VERSION = 3.04
"""From this version on the header is the 3.04 layout (module docstring)."""


def header_layout(path: Path, first: str) -> tuple[float, int, int]:
    """Version, column index of the file type and of the header labels, from the first line
    (module docstring); an :class:`InputError` naming line 1 when it is no RINEX clock header."""
    wide = first[:1].isdigit()  # F4.2 from column 1; the F9.2 of 2.00-3.02 starts blank
    try:
        version = float(first[:4] if wide else first[:9])
    except ValueError:
        version = math.nan
    type_column, label_column = (21, 65) if version >= WIDE_HEADER_VERSION else (20, 60)
    if "RINEX VERSION / TYPE" not in first[label_column:] or first[type_column] != "C":
        found = f"version {first[:9].strip()!r}, type {first[type_column : type_column + 1]!r}"
        raise InputError(
            "not a RINEX clock file (first line: RINEX VERSION / TYPE with type C in column "
            f"{type_column + 1} for version {version:.2f}; found {found})"
            if math.isfinite(version)
            else f"not a RINEX clock file (first line: no version number in {first[:9]!r})",
            path,
            1,
        )
    if not any(abs(version - v) < 1e-6 for v in VERSIONS):
        known = ", ".join(f"{v:.2f}" for v in VERSIONS)
        raise InputError(f"RINEX clock version {version:.2f} is not one of {known}", path, 1)
    return version, type_column, label_column


def read_rinex_clock(path: str | Path) -> SatelliteClocks:
    """Satellite clock offsets (s) of every ``AS`` record, one row per distinct epoch."""
    path = Path(path)
    lines = text_lines(path, "RINEX clock")
    if not lines:
        raise InputError("not a RINEX clock file (empty)", path)
    _, _, label_column = header_layout(path, lines[0].ljust(85))
    time_system = "GPS"
    body = None
    for number, line in enumerate(lines):
        label = line[label_column:].strip()
        if label == "TIME SYSTEM ID":
            time_system = line[3:6].strip() or "GPS"
        elif label == "END OF HEADER":
            body = number + 1
            break
    if body is None:
        raise InputError("no END OF HEADER", path)
    if time_system not in TIME_SYSTEMS:
        raise InputError(f"unknown time system {time_system!r}", path)
    sats: list[str] = []
    calendar: list[tuple[float, ...]] = []
    bias: list[float] = []
    number = body
    while number < len(lines):
        fields = lines[number].split()
        number += 1
        if not fields or fields[0] != "AS":
            continue
        sat, epoch, n_values, value = _record(path, number, fields)
        if n_values > VALUES_PER_LINE:
            number += 1
        sats.append(sat)
        calendar.append(epoch)
        bias.append(value)
    if not sats:
        raise InputError("no satellite clock (AS) records", path)
    t_all = to_gps_seconds(calendar_to_gps_seconds(*np.array(calendar).T), time_system)
    times, row = np.unique(t_all, return_inverse=True)
    ids, col = np.unique(np.array(sats, dtype="U3"), return_inverse=True)
    table = np.full((times.size, ids.size), np.nan)
    table[row, col] = bias
    return SatelliteClocks(times, ids, table, path)


def _record(path: Path, line: int, fields: list[str]) -> tuple[str, tuple[float, ...], int, float]:
    """Satellite, calendar epoch, number of values and clock bias (s) of one AS record."""
    try:
        sat = satellite_id(fields[1].ljust(3))
        epoch = tuple(float(v) for v in parse_calendar(" ".join(fields[2:8]).encode()))
        n_values = int(fields[8])
        value = float(fields[9].replace("D", "E"))
    except (ValueError, IndexError) as exc:
        raise InputError(f"bad clock record {' '.join(fields)!r}: {exc}", path, line) from None
    if not 1 <= n_values <= MAX_VALUES:
        raise InputError(f"bad clock record {' '.join(fields)!r}", path, line)
    if not abs(value) < MAX_CLOCK_S:
        raise InputError(f"clock bias {value} s beyond ±{MAX_CLOCK_S} s", path, line)
    return sat, epoch, n_values, value
