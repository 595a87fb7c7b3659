"""Vectorised RINEX observation reader: versions 2.10/2.11 and 3.02–3.05.

The file body is turned into one fixed-width byte matrix with a row per satellite record; all
fields (F14.3 value, LLI, signal strength; RINEX 3.05 Table A3, RINEX 2.11 Table A1) are then
decoded with numpy at once. Only the epoch headers of RINEX 2 are walked in a Python loop (their
length depends on the satellite count); no Python object is made per satellite or observation.

Epoch flags (RINEX 3.05 sec. 5.5): 0 ok, 1 power failure (data kept), 2–5 events followed by
``n`` special records (header records in flags 3/4 may redefine the observation types; this is
honoured), 6 cycle-slip records (skipped, counted).
"""

from __future__ import annotations

import itertools
import logging
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.io.rinex_common import label, parse_version_line, read_rinex_bytes, split_header
from vo_doppler.model.gpstime import calendar_to_gps_seconds, utc_to_gps_seconds
from vo_doppler.model.observations import Observations, ObsHeader

log = logging.getLogger(__name__)

SYSTEMS = "GRECJSI"
FIELD_WIDTH = 16
VALUE_WIDTH = 14
_DOT_COLUMN = 10  # F14.3: the decimal point is the 11th character of the value field
_EPOCH2 = re.compile(rb"^ [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d\.\d{7}  [0-6][ \d]{2}\d")
_EVENT2 = re.compile(rb"^ {28}[2-5][ \d]{2}\d")
_OBS_TYPE_LABELS = ("SYS / # / OBS TYPES", "# / TYPES OF OBSERV")


@dataclass
class _Records:
    """Fixed-width satellite records before field decoding."""

    rows: list[bytes] = field(default_factory=list)
    epoch: list[int] = field(default_factory=list)
    system: list[str] = field(default_factory=list)
    prn: list[int] = field(default_factory=list)
    line: list[int] = field(default_factory=list)
    typeset: list[int] = field(default_factory=list)


@dataclass
class _Epochs:
    calendar: list[tuple[float, ...]] = field(default_factory=list)
    flag: list[int] = field(default_factory=list)

    def add(self, date_text: bytes, flag: int) -> bool:
        """Append an epoch; False when its date cannot be read."""
        parts = date_text.split()
        try:
            calendar = tuple(float(p) for p in parts)
        except ValueError:
            return False
        if len(calendar) != 6:
            return False
        self.calendar.append(calendar)
        self.flag.append(flag)
        return True


def read_obs(path: str | Path) -> Observations:
    """Read a RINEX 2.10/2.11/3.0x observation file (plain, .gz, .Z or Hatanaka).

    Raises InputError when the file cannot be read at all (no header, wrong version line, not an
    observation file). Bad records inside the body are skipped with a logged warning naming file
    and line; they are listed in ``Observations.problems``.
    """
    path = Path(path)
    text = read_rinex_bytes(path)
    header_lines, body = split_header(path, text)
    header = _parse_header(path, header_lines)
    problems: list[str] = []
    typesets = [dict(header.obs_types)]
    if header.version < 3:
        epochs, records = _walk_rinex2(path, header, body, typesets, problems)
    else:
        epochs, records = _walk_rinex3(path, header, body, typesets, problems)
    return _decode(path, header, epochs, records, typesets, problems)


def _problem(problems: list[str], path: Path, line: int, message: str) -> None:
    text = f"{path}:{line}: {message}"
    log.warning(text)
    problems.append(text)


def _parse_header(path: Path, lines: list[str]) -> ObsHeader:
    version, _, system = parse_version_line(path, lines, "O")
    values: dict[str, str] = {}
    glonass: dict[int, int] = {}
    types = _parse_obs_types(path, lines, version, system, 1)
    for line in lines:
        key = label(line)
        values.setdefault(key, line[:60])
        if key == "GLONASS SLOT / FRQ #":
            for k in range(8):
                chunk = line[4 + 7 * k : 11 + 7 * k]
                if chunk[:1] == "R" and chunk[1:3].strip():
                    glonass[int(chunk[1:3])] = int(chunk[3:].strip())
    if not types:
        raise InputError("header has no observation types", path)
    position = None
    if "APPROX POSITION XYZ" in values:
        parts = values["APPROX POSITION XYZ"].split()
        position = np.array([float(p) for p in parts[:3]]) if len(parts) >= 3 else None
    interval = _float_or_none(values.get("INTERVAL", "")[:10])
    leap = values.get("LEAP SECONDS", "")[:6].strip()
    time_system = values.get("TIME OF FIRST OBS", " " * 60)[48:51].strip()
    if not time_system:
        time_system = {"R": "GLO", "E": "GAL", "C": "BDT", "J": "QZS"}.get(system, "GPS")
    return ObsHeader(
        path=path,
        version=version,
        system=system,
        marker_name=values.get("MARKER NAME", "").strip(),
        receiver_type=values.get("REC # / TYPE / VERS", " " * 40)[20:40].strip(),
        approx_position=position,
        interval=interval,
        obs_types=types,
        glonass_channels=glonass,
        time_system=time_system,
        leap_seconds=int(leap) if leap.lstrip("-").isdigit() else None,
        signal_strength_unit=values.get("SIGNAL STRENGTH UNIT", "").strip(),
        n_lines=len(lines),
    )


def _float_or_none(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _parse_obs_types(
    path: Path, lines: list[str], version: float, file_system: str, first_line: int
) -> dict[str, tuple[str, ...]]:
    """Observation types per system from 'SYS / # / OBS TYPES' or '# / TYPES OF OBSERV'."""
    types: dict[str, list[str]] = {}
    current = ""
    for number, line in enumerate(lines, start=first_line):
        key = label(line)
        if key == "SYS / # / OBS TYPES" and version >= 3:
            if line[0] != " ":
                current = line[0]
                if current not in SYSTEMS:
                    log.warning("%s:%d: unknown satellite system %r ignored", path, number, current)
                types[current] = []
            types.setdefault(current, []).extend(line[7:60].split())
        elif key == "# / TYPES OF OBSERV" and version < 3:
            types.setdefault("*", []).extend(line[6:60].split())
    if "*" in types:
        shared = tuple(types.pop("*"))
        systems = SYSTEMS if file_system == "M" else file_system
        return {s: shared for s in systems}
    return {s: tuple(v) for s, v in types.items() if s in SYSTEMS}


def _walk_rinex3(path, header, body, typesets, problems) -> tuple[_Epochs, _Records]:
    """Epoch headers start with '>'; the satellite records follow, one line each."""
    epochs, records = _Epochs(), _Records()
    markers = [i for i, line in enumerate(body) if line[:1] == b">"]
    markers.append(len(body))
    offset = header.n_lines + 1
    for i in range(len(body) if not markers[:-1] else markers[0]):
        if body[i].strip():
            _problem(problems, path, offset + i, "line outside any epoch skipped")
    for start, stop in itertools.pairwise(markers):
        line = body[start]
        flag_text, count_text = line[31:32], line[32:35]
        if not (flag_text.isdigit() and count_text.strip().isdigit()):
            _problem(problems, path, offset + start, "unreadable epoch record skipped")
            continue
        flag, count = int(flag_text), int(count_text)
        block = body[start + 1 : stop]
        if 2 <= flag <= 5:
            if len(block) != count:
                _problem(
                    problems,
                    path,
                    offset + start,
                    f"event says {count} records, {len(block)} follow",
                )
            _apply_event_header(path, header, block, typesets, offset + start + 1)
            continue
        if flag == 6:
            continue
        if flag > 6:
            _problem(problems, path, offset + start, f"unknown epoch flag {flag}: epoch skipped")
            continue
        if len(block) != count:
            _problem(
                problems,
                path,
                offset + start,
                f"epoch says {count} satellites but {len(block)} lines follow; reading the lines",
            )
        epoch_index = len(epochs.flag)
        if not epochs.add(line[2:29], flag):
            _problem(problems, path, offset + start, "unreadable epoch date: epoch skipped")
            continue
        for j, obs_line in enumerate(block):
            _add_record(
                path,
                records,
                problems,
                obs_line[:1].decode("ascii", "replace"),
                obs_line[1:3],
                obs_line[3:],
                epoch_index,
                offset + start + 1 + j,
                len(typesets) - 1,
            )
    return epochs, records


def _add_record(path, records, problems, system, prn_text, row, epoch, line, typeset) -> None:
    system = system if system.strip() else "G"
    if system not in SYSTEMS:
        _problem(
            problems, path, line, f"unknown satellite system letter {system!r}: record skipped"
        )
        return
    if not prn_text.strip().isdigit():
        _problem(problems, path, line, f"unreadable satellite number {prn_text!r}: record skipped")
        return
    records.rows.append(row)
    records.epoch.append(epoch)
    records.system.append(system)
    records.prn.append(int(prn_text))
    records.line.append(line)
    records.typeset.append(typeset)


def _apply_event_header(path, header, block, typesets, first_line) -> None:
    """Header records inside the body (flags 3/4) may redefine the observation types."""
    lines = [b.decode("ascii", "replace") for b in block]
    if any(label(line) in _OBS_TYPE_LABELS for line in lines):
        new_types = dict(typesets[-1])
        new_types.update(_parse_obs_types(path, lines, header.version, header.system, first_line))
        typesets.append(new_types)


def _walk_rinex2(path, header, body, typesets, problems) -> tuple[_Epochs, _Records]:
    """RINEX 2 epoch records: header (12 satellites a line) then ⌈n_obs/5⌉ lines per satellite."""
    epochs, records = _Epochs(), _Records()
    offset = header.n_lines + 1
    i, n = 0, len(body)
    while i < n:
        line = body[i]
        if not line.strip():
            i += 1
            continue
        if _EVENT2.match(line) or (_EPOCH2.match(line) and 2 <= int(line[28:29]) <= 5):
            count = int(line[29:32])
            _apply_event_header(path, header, body[i + 1 : i + 1 + count], typesets, offset + i + 1)
            i += 1 + count
            continue
        if not _EPOCH2.match(line):
            nxt = _next_epoch2(body, i + 1)
            _problem(
                problems, path, offset + i, f"expected an epoch record; skipped {nxt - i} lines"
            )
            i = nxt
            continue
        flag, count = int(line[28:29]), int(line[29:32])
        header_lines = max(1, -(-count // 12))
        sats = b"".join(body[i + k][32:68].ljust(36) for k in range(min(header_lines, n - i)))
        n_types = len(typesets[-1][next(iter(typesets[-1]))])
        per_sat = -(-n_types // 5)
        data_start = i + header_lines
        stop = data_start + count * per_sat
        nxt = _next_epoch2(body, data_start)
        if stop != nxt and not (stop > n and nxt == n):
            _problem(
                problems,
                path,
                offset + i,
                f"epoch says {count} satellites but {(nxt - data_start) / per_sat:g} "
                "satellites' lines follow: epoch skipped",
            )
            i = nxt
            continue
        if stop > n:
            _problem(problems, path, offset + i, "file ends inside this epoch: partial epoch kept")
        i = min(stop, n)
        if flag == 6:
            continue
        epoch_index = len(epochs.flag)
        if not epochs.add(line[1:26], flag):
            _problem(problems, path, offset + i, "unreadable epoch date: epoch skipped")
            continue
        for k in range(count):
            first = data_start + k * per_sat
            if first + per_sat > n:
                break
            row = b"".join(body[first + j][:80].ljust(80) for j in range(per_sat))
            sat = sats[3 * k : 3 * k + 3]
            _add_record(
                path,
                records,
                problems,
                sat[:1].decode("ascii", "replace"),
                sat[1:3],
                row,
                epoch_index,
                offset + first,
                len(typesets) - 1,
            )
    return epochs, records


def _next_epoch2(body: list[bytes], start: int) -> int:
    for j in range(start, len(body)):
        if _EPOCH2.match(body[j]) or _EVENT2.match(body[j]):
            return j
    return len(body)


def _epoch_times(header: ObsHeader, calendar: list[tuple[float, ...]]) -> np.ndarray:
    """GPS seconds of epoch dates (year, month, day, hour, minute, second; 2-digit year in v2)."""
    if not calendar:
        return np.zeros(0)
    parts = np.array(calendar)
    year = parts[:, 0].astype(np.int64)
    year = np.where(year < 80, year + 2000, np.where(year < 100, year + 1900, year))
    month, day, hour, minute = (parts[:, k].astype(np.int64) for k in range(1, 5))
    t = calendar_to_gps_seconds(year, month, day, hour, minute, parts[:, 5])
    if header.time_system == "GLO":
        return utc_to_gps_seconds(t, header.leap_seconds)
    if header.time_system == "BDT":
        return t + 14.0
    return t


def _decode(path, header, epochs, records, typesets, problems) -> Observations:
    """Decode all value/LLI/SSI fields of all records at once."""
    codes: list[str] = []
    for types in typesets:
        for sys_types in types.values():
            codes.extend(c for c in sys_types if c not in codes)
    n_fields = max(len(t) for types in typesets for t in types.values())
    width = FIELD_WIDTH * n_fields
    n_rec = len(records.rows)
    buffer = b"".join(row[:width].ljust(width) for row in records.rows)
    matrix = np.frombuffer(buffer, dtype=np.uint8).reshape(n_rec, n_fields, FIELD_WIDTH)
    system_index = np.array([SYSTEMS.index(s) for s in records.system], dtype=np.int64)
    table = np.full((len(typesets), len(SYSTEMS), n_fields), -1, dtype=np.int16)
    for t, types in enumerate(typesets):
        for s, sys_types in types.items():
            table[t, SYSTEMS.index(s), : len(sys_types)] = [codes.index(c) for c in sys_types]
    rec_codes = table[np.asarray(records.typeset, dtype=np.int64), system_index]
    value_chars = matrix[:, :, :VALUE_WIDTH]
    present = (rec_codes >= 0) & (value_chars != 32).any(axis=2)
    missing_types = (rec_codes < 0).all(axis=1)
    for r in np.flatnonzero(missing_types):
        _problem(
            problems, path, records.line[r], f"no observation types for system {records.system[r]}"
        )
    rec, slot = np.nonzero(present)
    chars = np.ascontiguousarray(value_chars[rec, slot])
    well_formed = chars[:, _DOT_COLUMN] == ord(".")
    values = np.full(rec.size, np.nan)
    text = chars.view(f"S{VALUE_WIDTH}").ravel()
    try:
        values[well_formed] = text[well_formed].astype(float)
    except ValueError:
        for k in np.flatnonzero(well_formed):
            try:
                values[k] = float(text[k])
            except ValueError:
                well_formed[k] = False
    for k in np.flatnonzero(~well_formed):
        line = records.line[rec[k]] + (slot[k] * FIELD_WIDTH // 80 if header.version < 3 else 0)
        _problem(
            problems,
            path,
            line,
            f"corrupt number {text[k].decode('ascii', 'replace').strip()!r} "
            f"({codes[rec_codes[rec[k], slot[k]]]}) skipped",
        )
    keep = well_formed
    rec, slot, values = rec[keep], slot[keep], values[keep]
    indicators = matrix[rec, slot, VALUE_WIDTH:].astype(np.int16) - ord("0")
    indicators[(indicators < 0) | (indicators > 9)] = -1
    epoch_time = _epoch_times(header, epochs.calendar)
    epoch_of_record = np.asarray(records.epoch, dtype=np.int64)
    return Observations(
        header=header,
        time=epoch_time[epoch_of_record[rec]] if rec.size else np.zeros(0),
        system=np.asarray(records.system, dtype="U1")[rec],
        prn=np.asarray(records.prn, dtype=np.int16)[rec],
        code=rec_codes[rec, slot],
        codes=tuple(codes),
        value=values,
        lli=indicators[:, 0].astype(np.int8),
        ssi=indicators[:, 1].astype(np.int8),
        epoch_time=epoch_time,
        epoch_flag=np.asarray(epochs.flag, dtype=np.int8),
        problems=tuple(problems),
    )
