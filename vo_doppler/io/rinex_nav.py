"""RINEX navigation reader: RINEX 2 GPS ('N') and GLONASS ('G'), RINEX 3 mixed, RINEX 4.

Broadcast records (RINEX 3.05 Tables A6–A14, RINEX 2.11 Tables A4/A11): Keplerian elements for
GPS, Galileo, BeiDou, QZSS (and NavIC) — 8 lines; GLONASS state vectors — 4 lines, 5 from RINEX
3.05 on (status flags, L1/L2 group delay difference, URAI, health flags). SBAS records are
skipped. RINEX 4 files are read by record type (RINEX 4.01 sec. 5.4 and Tables A32–A50): the
'> EPH' records of the legacy messages (GPS/QZSS/NavIC LNAV, Galileo INAV/FNAV, BeiDou D1/D2,
GLONASS FDMA) have the RINEX 3 layout and are read; CNAV/CNV1-3 ephemerides, SBAS, STO, EOP and
ION records are skipped and counted in ``Navigation.skipped``. Every time is converted to GPS
seconds: BDT + 14 s, GLONASS UTC + leap seconds. Records that cannot be read, whose lines are
misaligned or whose values are impossible are skipped with a message naming file and line.
"""

from __future__ import annotations

import logging
import math
import re
from pathlib import Path

import numpy as np

from vo_doppler.bounds import SATELLITE_SPEED
from vo_doppler.io.rinex_common import (
    add_problem,
    label,
    log_problem_count,
    parse_calendar,
    parse_version_line,
    prn_in_range,
    read_rinex_bytes,
    split_header,
)
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
    ("status_flags", "delta_tau_n", "urai", "health_flags"),
)
_KNOWN_SYSTEMS = "GECJIRS"
READ_V4 = {
    ("G", "LNAV"),
    ("J", "LNAV"),
    ("I", "LNAV"),
    ("E", "INAV"),
    ("E", "FNAV"),
    ("C", "D1"),
    ("C", "D2"),
    ("R", "FDMA"),
}
"""RINEX 4 ephemeris messages read (system letter, message type); they keep the RINEX 3 layout."""
_START3 = re.compile(rb"^[A-Z][ \d]\d \d{4} [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d")
_START2 = re.compile(rb"^[ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d\.\d")
_NUMBER_WIDTH = 19


def read_nav(paths: str | Path | list[str | Path] | tuple[str | Path, ...]) -> Navigation:
    """Read and merge RINEX 2/3/4 navigation files (plain, .gz or .Z).

    Raises InputError naming the file when it cannot be read at all; records skipped are listed
    in ``Navigation.problems`` (a file with none left gives empty record tables: the stages that
    need ephemerides say so for each satellite).
    """
    if isinstance(paths, str | Path):
        paths = [paths]
    result = None
    for path in paths:
        nav = _read_one(Path(path))
        result = nav if result is None else result.merged(nav)
    if result is None:
        raise ValueError("no navigation file given")
    return result


def _read_one(path: Path) -> Navigation:
    problems: list[str] = []
    header, body = split_header(path, read_rinex_bytes(path, problems))
    version, file_type, system = parse_version_line(path, header, "NGH")
    if version < 3:
        system = {"N": "G", "G": "R", "H": "S"}[file_type]
    leap = None
    for number, line in enumerate(header, start=1):
        if label(line) == "LEAP SECONDS":
            text = line[:6].strip()
            if text.isdigit() and int(text) < 100:
                leap = int(text)
            else:
                add_problem(problems, path, number, f"LEAP SECONDS {text!r} ignored")
    skipped: dict[str, int] = {}
    records = _split_records(path, version, system, body, len(header) + 1, problems, skipped)
    for kind, count in skipped.items():
        log.info("%s: %d '%s' records skipped (type not read)", path, count, kind)
    kepler = _decode(path, records, KEPLER_SYSTEMS, KEPLER_FIELDS, version, leap, problems)
    glonass = _decode(path, records, "R", GLONASS_FIELDS, version, leap, problems)
    log_problem_count(problems, path)
    return Navigation(
        _kepler_times(kepler),
        _glonass_si(glonass),
        leap,
        tuple(problems),
        _klobuchar(header),
        skipped,
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
        values = np.array([float(text[i : i + 12].replace("D", "E")) for i in range(0, 96, 12)])
    except ValueError:
        return None
    return values if np.isfinite(values).all() else None


def _record_lines(version: float, system: str) -> tuple[int, int]:
    """Fewest and most lines of one record (RINEX 3.05 Tables A6–A14; the GLONASS fourth
    broadcast-orbit line appeared in 3.05)."""
    if system == "R":
        return (4, 5) if version >= 3.05 else (4, 4)
    if system == "S":
        return 4, 4
    return 8, 8


def _is_continuation(line: bytes, indent: int) -> bool:
    return line[:indent] == b" " * indent and bool(line[indent:].strip())


class _Splitter:
    """Cuts the body into records: a start line ('G05 2024 …' / ' 5 10 …') and its continuation
    lines (indented 4 / 3 spaces). A record whose line count is wrong — a line lost, duplicated
    or out of place — is skipped with a message naming its line; the next record start is
    looked for from there, so one bad line costs one record. In RINEX 4 each record follows a
    '> EPH' line naming its message type (RINEX 4.01 sec. 5.4): only the types in :data:`READ_V4`
    are read, the others skipped and counted by type.
    """

    def __init__(self, path, version, file_system, body, first_line, problems, skipped):
        self.path, self.version, self.file_system = path, version, file_system
        self.body, self.first_line = body, first_line
        self.problems, self.skipped = problems, skipped
        self.start = _START3 if version >= 3 else _START2
        self.indent = 4 if version >= 3 else 3
        self.records: list[tuple[str, int, list[bytes]]] = []

    def problem(self, index: int, message: str) -> None:
        add_problem(self.problems, self.path, self.first_line + index, message)

    def is_marker(self, line: bytes) -> bool:
        return self.version >= 4 and line[:1] == b">"

    def next_start(self, index: int) -> int:
        n = len(self.body)
        while index < n and not (
            self.start.match(self.body[index]) or self.is_marker(self.body[index])
        ):
            index += 1
        return index

    def run(self) -> list[tuple[str, int, list[bytes]]]:
        i, n = 0, len(self.body)
        marker: str | None = None
        while i < n:
            line = self.body[i]
            if not line.strip():
                i += 1
            elif self.is_marker(line):
                i, marker = self.read_marker(i)
            elif not self.start.match(line):
                j = self.next_start(i + 1)
                self.problem(i, f"expected a record start; {j - i} lines skipped")
                i = j
            elif self.version >= 4 and marker != line[:1].decode("ascii"):
                j = self.next_start(i + 1)
                self.problem(i, "record without its '> EPH' line: skipped")
                i, marker = j, None
            else:
                i, marker = self.read_record(i), None
        return self.records

    def read_marker(self, i: int) -> tuple[int, str | None]:
        """Index after a RINEX 4 record-type line and the system letter of a record to read."""
        parts = self.body[i][1:].decode("ascii").split()
        kind = " ".join(parts[:1] + parts[2:3])
        if len(parts) >= 3 and parts[0] == "EPH" and (parts[1][:1], parts[2]) in READ_V4:
            return i + 1, parts[1][:1]
        if len(parts) < 3 or parts[0] not in ("EPH", "STO", "EOP", "ION"):
            self.problem(i, f"unreadable record-type line {self.body[i][:40]!r}: record skipped")
        else:
            self.skipped[kind] = self.skipped.get(kind, 0) + 1
        j = i + 1
        while j < len(self.body) and not self.is_marker(self.body[j]):
            j += 1
        return j, None

    def read_record(self, i: int) -> int:
        body, n = self.body, len(self.body)
        system = body[i][:1].decode("ascii") if self.version >= 3 else self.file_system
        low, high = _record_lines(self.version, system)
        j = i + 1
        while j < n and j - i < high and _is_continuation(body[j], self.indent):
            j += 1
        k = j
        while k < n and _is_continuation(body[k], self.indent):
            k += 1
        if system not in _KNOWN_SYSTEMS:
            self.problem(i, f"unknown satellite system {system!r}: record skipped")
        elif k > j:
            self.problem(
                i, f"record has {k - i} lines where {high} are expected (misaligned): skipped"
            )
        elif j - i < low:
            where = "the file ends" if j == n else "a line that does not continue it follows"
            self.problem(i, f"record has {j - i} of its {low} lines ({where}): skipped")
        else:
            self.records.append((system, self.first_line + i, body[i:j]))
        return k


def _split_records(path, version, file_system, body, first_line, problems, skipped):
    """(system, first line number, [lines]) per record (see :class:`_Splitter`)."""
    return _Splitter(path, version, file_system, body, first_line, problems, skipped).run()


def _decode(path, records, systems, names, version, leap, problems) -> NavRecords:
    """Parse the 19-character D/E-format numbers of all records of the given systems at once.

    A number must end in a two-digit exponent ('D+01', 'E-05'): a field cut short is refused,
    not read as a shorter number. Records with a missing or implausible essential parameter
    (:func:`_implausible`), a satellite number outside its system's range or a date that is not
    a calendar date are skipped with a message naming the line.
    """
    chosen = [r for r in records if r[0] in systems]
    start = 4 if version >= 3 else 3
    n_lines = len(names)
    rows, ids, dates, lines = [], [], [], []
    for system, line_number, block in chosen:
        first = block[0]
        date_end = 23 if version >= 3 else 22
        numbers = first[date_end:].ljust(3 * _NUMBER_WIDTH)[: 3 * _NUMBER_WIDTH]
        rest = b"".join(b[start:].ljust(4 * _NUMBER_WIDTH)[: 4 * _NUMBER_WIDTH] for b in block[1:])
        rows.append(numbers + b" " * _NUMBER_WIDTH + rest.ljust((n_lines - 1) * 4 * _NUMBER_WIDTH))
        ids.append((system, first[1:3] if version >= 3 else first[:2]))
        dates.append(first[4:23] if version >= 3 else first[2:22])
        lines.append(line_number)
    n_fields = 4 * n_lines
    buffer = b"".join(rows).replace(b"D", b"E").replace(b"d", b"e")
    chars = np.frombuffer(buffer, dtype=np.uint8).reshape(len(rows), n_fields, _NUMBER_WIDTH)
    text = np.ascontiguousarray(chars).view(f"S{_NUMBER_WIDTH}")[..., 0]
    values = np.full(text.shape, np.nan)
    blank = (chars == ord(" ")).all(axis=2)
    exponent = chars[:, :, -4:]
    digits = (exponent[:, :, 2:] >= ord("0")) & (exponent[:, :, 2:] <= ord("9"))
    formed = (
        np.isin(exponent[:, :, 0], (ord("E"), ord("e")))
        & np.isin(exponent[:, :, 1], (ord("+"), ord("-")))
        & digits.all(axis=2)
    )
    reason = np.full(len(rows), "", dtype=object)
    bad_line = np.zeros(len(rows), dtype=np.int64)
    for r, c in zip(*np.nonzero(~blank & ~formed), strict=True):
        if not reason[r]:
            reason[r] = f"number {text[r, c].decode('ascii').strip()!r} not in D19.12 form"
            bad_line[r] = c // 4
    readable = ~blank & formed
    try:
        values[readable] = text[readable].astype(float)
    except ValueError:
        for r, c in zip(*np.nonzero(readable), strict=True):
            try:
                values[r, c] = float(text[r, c])
            except ValueError:
                if not reason[r]:
                    reason[r] = f"unreadable number {text[r, c].decode('ascii').strip()!r}"
                    bad_line[r] = c // 4
    columns = [4 * k + j for k, group in enumerate(names) for j in range(len(group))]
    flat_names = [name for group in names for name in group]
    values = values[:, columns]
    toc = np.full(len(rows), np.nan)
    prn = np.zeros(len(rows), dtype=np.int16)
    for r, ((system, prn_text), date) in enumerate(zip(ids, dates, strict=True)):
        params = dict(zip(flat_names, values[r], strict=True))
        why = reason[r] or _implausible(params)
        if not prn_text.strip().isdigit() or not prn_in_range(system, int(prn_text)):
            why = why or f"satellite number {prn_text.decode('ascii').strip()!r} of {system}"
        else:
            prn[r] = int(prn_text)
        try:
            toc[r] = _record_time(date, system, leap)
        except ValueError as exc:
            why = why or f"date unusable ({exc})"
        reason[r] = why
    good = reason == ""
    for r in np.flatnonzero(~good):
        add_problem(problems, path, lines[r] + bad_line[r], f"{reason[r]}: record skipped")
    params = {name: values[good, i] for i, name in enumerate(flat_names)}
    return NavRecords(
        np.array([s for s, _ in ids], dtype="U1")[good] if ids else np.zeros(0, dtype="U1"),
        prn[good],
        toc[good],
        params,
        np.asarray(lines, dtype=np.int64)[good],
    )


ESSENTIAL = {
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
PLAUSIBLE = {
    "e": (0.0, 0.5),
    "sqrt_a": (2500.0, 8200.0),
    "toe_sow": (0.0, SECONDS_PER_WEEK),
    "i0": (-math.pi, math.pi),
}
"""Ranges of broadcast Keplerian parameters (IS-GPS-200 Table 20-I bit ranges: e < 0.5,
√a 2530–8192 √m; Galileo, BeiDou and QZSS fall inside), seconds of week, inclination (rad)."""
GLONASS_RADIUS_KM = (19_000.0, 32_000.0)
GLONASS_MAX_SPEED_KM_S = SATELLITE_SPEED.high / 1000.0


def _implausible(params: dict[str, float]) -> str:
    """Why a record's parameters cannot be a broadcast ephemeris ('' when they can)."""
    for name, value in params.items():
        if name in ESSENTIAL and not math.isfinite(value):
            return f"{name} missing"
        if name in PLAUSIBLE and not PLAUSIBLE[name][0] <= value <= PLAUSIBLE[name][1]:
            return f"{name} = {value:g} outside {PLAUSIBLE[name]}"
    if "x" in params:
        radius = math.hypot(params["x"], params["y"], params["z"])
        speed = math.hypot(params["vx"], params["vy"], params["vz"])
        if not GLONASS_RADIUS_KM[0] <= radius <= GLONASS_RADIUS_KM[1]:
            return f"orbit radius {radius:g} km"
        if speed > GLONASS_MAX_SPEED_KM_S:
            return f"speed {speed:g} km/s"
    return ""


def _record_time(date: bytes, system: str, leap: int | None) -> float:
    """Record epoch (toc / tb) in GPS seconds from its calendar fields in the system's time."""
    t = float(calendar_to_gps_seconds(*parse_calendar(date)))
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
