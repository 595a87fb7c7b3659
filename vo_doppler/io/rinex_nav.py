"""RINEX navigation reader: RINEX 2 GPS ('N') and GLONASS ('G'), RINEX 3 mixed.

Broadcast records (RINEX 3.05 Tables A6–A14, RINEX 2.11 Tables A4/A11): Keplerian elements for
GPS, Galileo, BeiDou, QZSS (and NavIC) — 8 lines; GLONASS state vectors — 4 lines. SBAS records
are skipped. Every time is converted to GPS seconds: BDT + 14 s, GLONASS UTC + leap seconds.
Records that cannot be read are skipped with a message naming file and line.
"""

from __future__ import annotations

import logging
import re
from pathlib import Path

import numpy as np

from vo_doppler.io.rinex_common import label, parse_version_line, read_rinex_bytes, split_header
from vo_doppler.model.gpstime import (
    BDT_MINUS_GPST_S,
    SECONDS_PER_WEEK,
    calendar_to_gps_seconds,
    utc_to_gps_seconds,
)
from vo_doppler.model.navigation import Navigation, NavRecords

log = logging.getLogger(__name__)

KEPLER_SYSTEMS = "GECJI"
KEPLER_FIELDS = (
    # broadcast orbit 0 … 7 in record order (IS-GPS-200 Table 20-III names)
    ("af0", "af1", "af2"),
    ("iode", "crs", "delta_n", "m0"),
    ("cuc", "e", "cus", "sqrt_a"),
    ("toe_sow", "cic", "omega0", "cis"),
    ("i0", "crc", "omega", "omega_dot"),
    ("idot", "codes", "week", "l2p_flag"),
    ("accuracy", "health", "tgd", "iodc"),
    ("transmission_sow", "fit_interval"),
)
GLONASS_FIELDS = (
    ("minus_tau_n", "gamma_n", "frame_time"),
    ("x", "vx", "ax", "health"),
    ("y", "vy", "ay", "channel"),
    ("z", "vz", "az", "age"),
)
_LINES = {"G": 8, "E": 8, "C": 8, "J": 8, "I": 8, "R": 4, "S": 4}
_START3 = re.compile(rb"^[A-Z][ \d]\d ")
_NUMBER_WIDTH = 19


def read_nav(paths: str | Path | list[str | Path] | tuple[str | Path, ...]) -> Navigation:
    """Read and merge RINEX 2/3 navigation files (plain, .gz, .Z, Hatanaka not applicable)."""
    if isinstance(paths, str | Path):
        paths = [paths]
    result = None
    for path in paths:
        nav = _read_one(Path(path))
        result = nav if result is None else result.merged(nav)
    if result is None:
        raise ValueError("no navigation file given")
    return result


def _problem(problems: list[str], path: Path, line: int, message: str) -> None:
    text = f"{path}:{line}: {message}"
    log.warning(text)
    problems.append(text)


def _read_one(path: Path) -> Navigation:
    header, body = split_header(path, read_rinex_bytes(path))
    version, file_type, system = parse_version_line(path, header, "NGH")
    if version < 3:
        system = {"N": "G", "G": "R", "H": "S"}[file_type]
    leap = None
    for line in header:
        if label(line) == "LEAP SECONDS" and line[:6].strip().lstrip("-").isdigit():
            leap = int(line[:6])
    problems: list[str] = []
    records = _split_records(path, version, system, body, len(header) + 1, problems)
    kepler = _decode(path, records, KEPLER_SYSTEMS, KEPLER_FIELDS, version, leap, problems)
    glonass = _decode(path, records, "R", GLONASS_FIELDS, version, leap, problems)
    return Navigation(
        _kepler_times(kepler),
        _glonass_si(glonass),
        leap,
        tuple(problems),
        _klobuchar(header),
    )


def _klobuchar(header: list[str]) -> np.ndarray | None:
    """GPS Klobuchar α0–α3, β0–β3 ('IONOSPHERIC CORR' GPSA/GPSB, RINEX 2 'ION ALPHA/BETA')."""
    parts: dict[str, str] = {}
    for line in header:
        key = label(line)
        if key == "IONOSPHERIC CORR" and line[:4] in ("GPSA", "GPSB"):
            parts[line[3]] = line[5:53]
        elif key in ("ION ALPHA", "ION BETA"):
            parts[key[4]] = line[2:50]
    if set(parts) != {"A", "B"}:
        return None
    try:
        text = parts["A"] + parts["B"]
        values = [float(text[i : i + 12].replace("D", "E")) for i in range(0, 96, 12)]
    except ValueError:
        return None
    return np.array(values)


def _split_records(path, version, file_system, body, first_line, problems):
    """(system, first line number, [lines]) per record."""
    records = []
    i, n = 0, len(body)
    while i < n:
        line = body[i]
        if not line.strip():
            i += 1
            continue
        if version >= 3:
            if not _START3.match(line):
                _problem(problems, path, first_line + i, "expected a record start; line skipped")
                i += 1
                continue
            system = line[:1].decode("ascii")
        else:
            system = file_system
        if system not in _LINES:
            _problem(problems, path, first_line + i, f"unknown satellite system {system!r}")
            i += 1
            while i < n and (body[i][:1] == b" " if version >= 3 else False):
                i += 1
            continue
        count = _LINES[system]
        block = body[i : i + count]
        if len(block) < count or (version >= 3 and any(_START3.match(b) for b in block[1:])):
            _problem(problems, path, first_line + i, "incomplete record skipped")
            i += 1
            continue
        records.append((system, first_line + i, block))
        i += count
    return records


def _decode(path, records, systems, names, version, leap, problems) -> NavRecords:
    """Parse the 19-character D/E-format numbers of all records of the given systems at once."""
    chosen = [r for r in records if r[0] in systems]
    start = 4 if version >= 3 else 3
    n_lines = len(names)
    rows, ids, dates, lines = [], [], [], []
    for system, line_number, block in chosen:
        first = block[0]
        date_end = 23 if version >= 3 else 22
        numbers = first[date_end:].ljust(3 * _NUMBER_WIDTH)[: 3 * _NUMBER_WIDTH]
        rest = b"".join(b[start:].ljust(4 * _NUMBER_WIDTH)[: 4 * _NUMBER_WIDTH] for b in block[1:])
        rows.append(numbers + b" " * _NUMBER_WIDTH + rest)
        ids.append((system, first[1:3] if version >= 3 else first[:2]))
        dates.append(first[4:23] if version >= 3 else first[2:22])
        lines.append(line_number)
    n_fields = 4 * n_lines
    buffer = b"".join(rows).replace(b"D", b"E").replace(b"d", b"e")
    chars = np.frombuffer(buffer, dtype=np.uint8).reshape(len(rows), n_fields, _NUMBER_WIDTH)
    text = np.ascontiguousarray(chars).view(f"S{_NUMBER_WIDTH}")[..., 0]
    values = np.full(text.shape, np.nan)
    blank = (chars == ord(" ")).all(axis=2)
    good = np.ones(len(rows), dtype=bool)
    bad_line = np.zeros(len(rows), dtype=np.int64)
    try:
        values[~blank] = text[~blank].astype(float)
    except ValueError:
        for r, c in zip(*np.nonzero(~blank), strict=True):
            try:
                values[r, c] = float(text[r, c])
            except ValueError:
                good[r] = False
                bad_line[r] = c // 4
    columns = [4 * k + j for k, group in enumerate(names) for j in range(len(group))]
    flat_names = [name for group in names for name in group]
    values = values[:, columns]
    essential = [i for i, name in enumerate(flat_names) if name in _ESSENTIAL]
    good &= ~np.isnan(values[:, essential]).any(axis=1)
    toc = np.full(len(rows), np.nan)
    prn = np.zeros(len(rows), dtype=np.int16)
    for r, ((system, prn_text), date) in enumerate(zip(ids, dates, strict=True)):
        try:
            prn[r] = int(prn_text)
            toc[r] = _record_time(date, system, leap)
        except ValueError:
            good[r] = False
    for r in np.flatnonzero(~good):
        _problem(
            problems, path, lines[r] + bad_line[r], "unreadable number or date: record skipped"
        )
    params = {name: values[good, i] for i, name in enumerate(flat_names)}
    return NavRecords(
        np.array([s for s, _ in ids], dtype="U1")[good] if ids else np.zeros(0, dtype="U1"),
        prn[good],
        toc[good],
        params,
        np.asarray(lines, dtype=np.int64)[good],
    )


_ESSENTIAL = {
    "af0",
    "af1",
    "af2",
    "crs",
    "delta_n",
    "m0",
    "cuc",
    "e",
    "cus",
    "sqrt_a",
    "toe_sow",
    "cic",
    "omega0",
    "cis",
    "i0",
    "crc",
    "omega",
    "omega_dot",
    "idot",
    "health",
    "minus_tau_n",
    "gamma_n",
    "x",
    "vx",
    "ax",
    "y",
    "vy",
    "ay",
    "z",
    "vz",
    "az",
}


def _record_time(date: bytes, system: str, leap: int | None) -> float:
    """Record epoch (toc / tb) in GPS seconds from its calendar fields in the system's time."""
    y, mo, d, h, mi, s = (float(p) for p in date.split())
    if y < 100:
        y += 2000 if y < 80 else 1900
    t = float(calendar_to_gps_seconds(int(y), int(mo), int(d), int(h), int(mi), s))
    if system == "C":
        return t - BDT_MINUS_GPST_S
    if system == "R":
        return float(utc_to_gps_seconds(t, leap))
    return t


def _glonass_si(glonass: NavRecords) -> NavRecords:
    """GLONASS positions, velocities and accelerations from km, km/s, km/s² to SI."""
    params = dict(glonass.params)
    for name in ("x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"):
        params[name] = params[name] * 1000.0
    return NavRecords(glonass.system, glonass.prn, glonass.toc, params, glonass.line)


def _kepler_times(kepler: NavRecords) -> NavRecords:
    """Full toe in GPS seconds: the toe second of week nearest to toc (BDT shifted by 14 s)."""
    shift = np.where(kepler.system == "C", -BDT_MINUS_GPST_S, 0.0)
    toc_system = kepler.toc - shift
    toc_sow = np.mod(toc_system, SECONDS_PER_WEEK)
    delta = kepler["toe_sow"] - toc_sow
    delta -= SECONDS_PER_WEEK * np.round(delta / SECONDS_PER_WEEK)
    params = dict(kepler.params)
    params["toe"] = toc_system + delta + shift
    return NavRecords(kepler.system, kepler.prn, kepler.toc, params, kepler.line)
