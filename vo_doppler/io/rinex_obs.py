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
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vo_doppler.bounds import RECEIVER_RADIUS
from vo_doppler.errors import InputError
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
from vo_doppler.model.gpstime import calendar_to_gps_seconds, utc_to_gps_seconds
from vo_doppler.model.observations import Observations, ObsHeader
from vo_doppler.model.signals import SatelliteSystem

log = logging.getLogger(__name__)

SYSTEMS = "".join(SatelliteSystem)
FIELD_WIDTH = 16
VALUE_WIDTH = 14
_DOT_COLUMN = 10  # F14.3: the decimal point is the 11th character of the value field
_EPOCH2 = re.compile(rb"^ [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d\.\d{7}  [0-6][ \d]{2}\d")
_EVENT2 = re.compile(rb"^ {28}[2-5][ \d]{2}\d")
_OBS_TYPE_LABELS = ("SYS / # / OBS TYPES", "# / TYPES OF OBSERV")
MAX_OBS_TYPES = 200
GLONASS_SLOT_LABEL = "GLONASS SLOT / FRQ #"
_GLONASS_COUNT = re.compile(r"\s*\d+(?=\s|$)")
_GLONASS_PAIR = re.compile(r"R ?(\d{1,2})\s+([+-]?\d{1,2})(?!\d)")


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
    calendar: list[tuple[int, int, int, int, int, float]] = field(default_factory=list)
    flag: list[int] = field(default_factory=list)
    line: list[int] = field(default_factory=list)

    def add(self, date_text: bytes, flag: int, line: int) -> str | None:
        """Append an epoch; the reason when its date cannot be read or is not a calendar date."""
        try:
            calendar = parse_calendar(date_text)
        except ValueError as exc:
            return str(exc)
        self.calendar.append(calendar)
        self.flag.append(flag)
        self.line.append(line)
        return None


def read_obs(path: str | Path) -> Observations:
    """Read a RINEX 2.10/2.11/3.0x/4.0x observation file (plain, .gz, .Z or Hatanaka).

    Raises InputError when the file cannot be read at all (no header, wrong version line, not an
    observation file, bytes outside ASCII, inconsistent observation types, data epochs out of
    time order). Bad records inside the body are skipped with a logged warning naming file and
    line; they are listed in ``Observations.problems``. Policies:

    - an epoch whose date is not a calendar date is skipped;
    - an epoch whose satellite count differs from the lines that follow it is skipped (at the
      end of a truncated file the lines present are read);
    - a data epoch at the time of the one before is dropped, the drops counted in one message;
    - a data epoch earlier than the one before is an InputError naming its line;
    - a satellite listed twice in one epoch keeps its first record;
    - a value must be written F14.3 (three decimals): a number cut short is skipped, never read
      as a shorter one;
    - a file from which no observation at all can be read is an InputError.
    """
    path = Path(path)
    problems: list[str] = []
    text = read_rinex_bytes(path, problems)
    header_lines, body = split_header(path, text)
    del text  # the body lines hold what is read: not the file's text too while they are decoded
    header = _parse_header(path, header_lines, problems)
    typesets = [dict(header.obs_types)]
    if header.version < 3:
        epochs, records = _walk_rinex2(path, header, body, typesets, problems)
    else:
        epochs, records = _walk_rinex3(path, header, body, typesets, problems)
    obs = _decode(path, header, epochs, records, typesets, problems)
    log_problem_count(problems, path)
    if len(obs) == 0:
        raise InputError(
            f"no observation could be read ({obs.epoch_time.size} epochs, "
            f"{len(problems)} records skipped)",
            path,
        )
    return obs


def _parse_header(path: Path, lines: list[str], problems: list[str]) -> ObsHeader:
    version, _, system = parse_version_line(path, lines, "O")
    values: dict[str, tuple[int, str]] = {}
    glonass: dict[int, int] = {}
    types = _parse_obs_types(path, lines, version, system, 1)
    for number, line in enumerate(lines, start=1):
        key = label(line)
        if key != GLONASS_SLOT_LABEL and line.rstrip().endswith(GLONASS_SLOT_LABEL):
            key = GLONASS_SLOT_LABEL  # content past column 60 pushed the label right
        values.setdefault(key, (number, line[:60]))
        if key == GLONASS_SLOT_LABEL:
            content = line.rstrip()[: -len(GLONASS_SLOT_LABEL)]
            _glonass_slots(path, number, content, glonass, problems)
    if not types:
        raise InputError("header has no observation types", path)
    interval = _header_number(path, values, "INTERVAL", slice(0, 10), problems)
    if interval is not None and interval < 0:
        add_problem(problems, path, values["INTERVAL"][0], "negative INTERVAL ignored")
        interval = None
    leap = _header_number(path, values, "LEAP SECONDS", slice(0, 6), problems)
    if leap is not None and not (leap == int(leap) and 0 <= leap < 100):
        add_problem(problems, path, values["LEAP SECONDS"][0], f"LEAP SECONDS {leap:g} ignored")
        leap = None
    time_system = _time_system(path, values, version, system, problems)
    return ObsHeader(
        path=path,
        version=version,
        system=system,
        marker_name=values.get("MARKER NAME", (0, ""))[1].strip(),
        receiver_type=values.get("REC # / TYPE / VERS", (0, " " * 40))[1][20:40].strip(),
        approx_position=_approx_position(path, values, problems),
        interval=interval,
        obs_types=types,
        glonass_channels=glonass,
        time_system=time_system,
        leap_seconds=None if leap is None else int(leap),
        signal_strength_unit=values.get("SIGNAL STRENGTH UNIT", (0, ""))[1].strip(),
        n_lines=len(lines),
    )


def time_systems(version: float) -> tuple[str, ...]:
    """The time systems TIME OF FIRST OBS may name in a file of ``version``: RINEX 2.10 GPS and
    GLO, 2.11 also GAL, RINEX 3 and 4 also QZS, BDT and IRN."""
    if version < 2.11:
        return ("GPS", "GLO")
    if version < 3:
        return ("GPS", "GLO", "GAL")
    return ("GPS", "GLO", "GAL", "QZS", "BDT", "IRN")


def _time_system(path: Path, values, version: float, system: str, problems) -> str:
    """The epochs' time system from TIME OF FIRST OBS (blank: the file's satellite system's);
    one the version does not define (``UTC`` in a 2.10 file) is read as GPS, with a problem
    naming the line."""
    number, line = values.get("TIME OF FIRST OBS", (0, " " * 60))
    time_system = line[48:51].strip()
    if not time_system:
        return {"R": "GLO", "E": "GAL", "C": "BDT", "J": "QZS"}.get(system, "GPS")
    allowed = time_systems(version)
    if time_system not in allowed:
        add_problem(
            problems,
            path,
            number,
            f"TIME OF FIRST OBS time system {time_system!r} is not one of RINEX {version:.2f}'s "
            f"({', '.join(allowed)}): the epochs are read as GPS time (UTC epochs would be the "
            "leap seconds behind)",
        )
        return "GPS"
    return time_system


def _glonass_slots(
    path: Path, number: int, content: str, glonass: dict[int, int], problems
) -> None:
    """Slot → frequency channel (−7…+6) pairs of one 'GLONASS SLOT / FRQ #' record.

    RINEX 3.05 Table A2 writes ``I3,1X,8(A1,I2.2,1X,I2,1X)``: the count, then up to eight pairs
    such as ``R01  1``, continued on lines whose count is blank. Writers vary it (a GSDC Pixel5
    file among them): another spacing, more or fewer pairs on a line, no count, content past
    column 60. The pairs are read as tokens (``R``, the slot, blanks, the signed channel)
    wherever they stand; the text that is no valid pair is named once for the line.
    """
    count = _GLONASS_COUNT.match(content)
    text = content[count.end() :] if count else content
    unread: list[str] = []
    end = 0
    for pair in _GLONASS_PAIR.finditer(text):
        unread.append(text[end : pair.start()].strip())
        end = pair.end()
        slot, channel = int(pair[1]), int(pair[2])
        if prn_in_range("R", slot) and -7 <= channel <= 6:
            glonass[slot] = channel
        else:
            unread.append(" ".join(pair[0].split()))
    unread.append(text[end:].strip())
    unread = [u for u in unread if u]
    if unread:
        add_problem(
            problems,
            path,
            number,
            f"unreadable GLONASS slot/channel {', '.join(repr(u) for u in unread)} ignored",
        )


def _header_number(path, values, key, columns, problems) -> float | None:
    """A finite number from a header record, None (with a problem) when unreadable."""
    if key not in values:
        return None
    number, text = values[key]
    try:
        value = float(text[columns])
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        add_problem(problems, path, number, f"unreadable {key} {text[columns].strip()!r} ignored")
        return None
    return value


def _approx_position(path, values, problems) -> np.ndarray | None:
    """'APPROX POSITION XYZ' (m, ECEF), None when absent or not a position near the Earth."""
    if "APPROX POSITION XYZ" not in values:
        return None
    number, text = values["APPROX POSITION XYZ"]
    try:
        position = np.array([float(p) for p in text.split()[:3]])
    except ValueError:
        position = np.full(3, np.nan)
    if position.size != 3:
        position = np.full(3, np.nan)
    radius = float(np.linalg.norm(position))
    if radius == 0.0:
        return None
    if not (np.isfinite(position).all() and not RECEIVER_RADIUS.outside(radius)):
        add_problem(problems, path, number, f"APPROX POSITION XYZ {text.strip()!r} ignored")
        return None
    return position


def _parse_obs_types(
    path: Path, lines: list[str], version: float, file_system: str, first_line: int
) -> dict[str, tuple[str, ...]]:
    """Observation types per system from 'SYS / # / OBS TYPES' or '# / TYPES OF OBSERV'.

    Each list must have exactly the declared number of distinct codes, at most
    :data:`MAX_OBS_TYPES` (the header drives the record width, so it is bounded).
    """
    types: dict[str, list[str]] = {}
    declared: dict[str, tuple[int, int]] = {}
    current = ""
    for number, line in enumerate(lines, start=first_line):
        key = label(line)
        if key == "SYS / # / OBS TYPES" and version >= 3:
            if line[0] != " ":
                current = line[0]
                if current not in SYSTEMS:
                    log.warning("%s:%d: unknown satellite system %r ignored", path, number, current)
                declared[current] = (number, _declared_count(path, number, line[3:6]))
                types[current] = []
            elif current not in types:
                raise InputError("observation types continue a list never started", path, number)
            types[current].extend(line[7:60].split())
            _check_type_count(path, number, current, types[current], declared[current][1])
        elif key == "# / TYPES OF OBSERV" and version < 3:
            if "*" not in declared:
                declared["*"] = (number, _declared_count(path, number, line[:6]))
            types.setdefault("*", []).extend(line[6:60].split())
            _check_type_count(path, number, "*", types["*"], declared["*"][1])
    for system, codes in types.items():
        number, count = declared[system]
        if len(codes) != count:
            raise InputError(
                f"{count} observation types declared but {len(codes)} listed", path, number
            )
        if len(set(codes)) != len(codes):
            raise InputError("an observation type is listed twice", path, number)
    if "*" in types:
        shared = tuple(types.pop("*"))
        systems = SYSTEMS if file_system == "M" else file_system
        return {s: shared for s in systems}
    return {s: tuple(v) for s, v in types.items() if s in SYSTEMS}


def _declared_count(path: Path, number: int, text: str) -> int:
    count = text.strip()
    if not count.isdigit() or not 0 < int(count) <= MAX_OBS_TYPES:
        raise InputError(
            f"number of observation types {count!r} is not 1–{MAX_OBS_TYPES}", path, number
        )
    return int(count)


def _check_type_count(path: Path, number: int, system: str, codes: list[str], count: int) -> None:
    if len(codes) > count:
        raise InputError(
            f"more observation types than the {count} declared for {system!r}", path, number
        )


def _walk_rinex3(path, header, body, typesets, problems) -> tuple[_Epochs, _Records]:
    """Epoch headers start with '>'; the satellite records follow, one line each."""
    epochs, records = _Epochs(), _Records()
    markers = [i for i, line in enumerate(body) if line[:1] == b">"]
    markers.append(len(body))
    offset = header.n_lines + 1
    for i in range(len(body) if not markers[:-1] else markers[0]):
        if body[i].strip():
            add_problem(problems, path, offset + i, "line outside any epoch skipped")
    for start, stop in itertools.pairwise(markers):
        line = body[start]
        flag_text, count_text = line[31:32], line[32:35]
        if not (flag_text.isdigit() and count_text.strip().isdigit()):
            add_problem(problems, path, offset + start, "unreadable epoch record skipped")
            continue
        flag, count = int(flag_text), int(count_text)
        block = body[start + 1 : stop]
        if 2 <= flag <= 5:
            if len(block) != count:
                add_problem(
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
            add_problem(problems, path, offset + start, f"unknown epoch flag {flag}: epoch skipped")
            continue
        if len(block) < count and stop == len(body):
            add_problem(
                problems,
                path,
                offset + start,
                f"epoch says {count} satellites but {len(block)} lines follow before the end of "
                "the file; reading the lines",
            )
        elif len(block) != count:
            add_problem(
                problems,
                path,
                offset + start,
                f"epoch says {count} satellites but {len(block)} lines follow: epoch skipped",
            )
            continue
        epoch_index = len(epochs.flag)
        reason = epochs.add(line[2:29], flag, offset + start)
        if reason is not None:
            add_problem(problems, path, offset + start, f"epoch date unusable ({reason}): skipped")
            continue
        for j, obs_line in enumerate(block):
            _add_record(
                path,
                records,
                problems,
                obs_line[:1].decode("ascii"),
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
        add_problem(
            problems, path, line, f"unknown satellite system letter {system!r}: record skipped"
        )
        return
    prn_text = prn_text.decode("ascii").strip()
    if not (prn_text.isdigit() and prn_in_range(system, int(prn_text))):
        add_problem(
            problems, path, line, f"satellite number {prn_text!r} of {system}: record skipped"
        )
        return
    records.rows.append(row)
    records.epoch.append(epoch)
    records.system.append(system)
    records.prn.append(int(prn_text))
    records.line.append(line)
    records.typeset.append(typeset)


def _apply_event_header(path, header, block, typesets, first_line) -> None:
    """Header records inside the body (flags 3/4) may redefine the observation types."""
    lines = [b.decode("ascii") for b in block]
    if any(label(line) in _OBS_TYPE_LABELS for line in lines):
        new_types = dict(typesets[-1])
        new_types.update(_parse_obs_types(path, lines, header.version, header.system, first_line))
        typesets.append(new_types)


def _walk_rinex2(path, header, body, typesets, problems) -> tuple[_Epochs, _Records]:
    """RINEX 2 epoch records: header (12 satellites a line) then ⌈n_obs/5⌉ lines per satellite.

    When the file ends inside an epoch, the satellite records present are kept, the last one as
    far as its lines go (as georinex does).
    """
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
            add_problem(
                problems, path, offset + i, f"expected an epoch record; skipped {nxt - i} lines"
            )
            i = nxt
            continue
        flag, count = int(line[28:29]), int(line[29:32])
        epoch_line = offset + i
        header_lines = max(1, -(-count // 12))
        sats = b"".join(body[i + k][32:68].ljust(36) for k in range(min(header_lines, n - i)))
        n_types = len(typesets[-1][next(iter(typesets[-1]))])
        per_sat = -(-n_types // 5)
        data_start = i + header_lines
        stop = data_start + count * per_sat
        nxt = _next_epoch2(body, data_start)
        if stop != nxt and not (stop > n and nxt == n):
            add_problem(
                problems,
                path,
                epoch_line,
                f"epoch says {count} satellites but {(nxt - data_start) / per_sat:g} "
                "satellites' lines follow: epoch skipped",
            )
            i = nxt
            continue
        if stop > n:
            add_problem(
                problems, path, epoch_line, "file ends inside this epoch: partial epoch kept"
            )
        i = min(stop, n)
        if flag == 6:
            continue
        epoch_index = len(epochs.flag)
        reason = epochs.add(line[1:26], flag, epoch_line)
        if reason is not None:
            add_problem(problems, path, epoch_line, f"epoch date unusable ({reason}): skipped")
            continue
        for k in range(count):
            first = data_start + k * per_sat
            if first >= n:
                break
            lines = body[first : first + per_sat]
            row = b"".join(part[:80].ljust(80) for part in lines)
            sat = sats[3 * k : 3 * k + 3]
            _add_record(
                path,
                records,
                problems,
                sat[:1].decode("ascii"),
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


def _epoch_times(header: ObsHeader, calendar: list[tuple[int, int, int, int, int, float]]):
    """GPS seconds of validated epoch dates in the file's time system."""
    if not calendar:
        return np.zeros(0)
    year, month, day, hour, minute = (
        np.array([c[k] for c in calendar], dtype=np.int64) for k in range(5)
    )
    second = np.array([c[5] for c in calendar])
    t = calendar_to_gps_seconds(year, month, day, hour, minute, second)
    if header.time_system == "GLO":
        return utc_to_gps_seconds(t, header.leap_seconds)
    if header.time_system == "BDT":
        return t + 14.0
    return t


def _ordered_epochs(path, header, epochs, problems) -> tuple[np.ndarray, np.ndarray]:
    """Epoch times and a keep-mask: a data epoch at the time of the one before is dropped (and
    counted); one earlier than the one before is refused, naming its line."""
    times = _epoch_times(header, epochs.calendar)
    keep = np.ones(times.size, dtype=bool)
    if times.size > 1:
        step = np.diff(times)
        backwards = np.flatnonzero(step < 0)
        if backwards.size:
            k = int(backwards[0]) + 1
            raise InputError(
                f"epoch {times[k]:.7f} s (GPS) is {-step[k - 1]:g} s before the epoch above it: "
                "epochs out of time order",
                path,
                epochs.line[k],
            )
        keep[1:] = step > 0
    dropped = np.flatnonzero(~keep)
    if dropped.size:
        lines = ", ".join(str(epochs.line[k]) for k in dropped[:5])
        more = "…" if dropped.size > 5 else ""
        add_problem(
            problems,
            path,
            epochs.line[dropped[0]],
            f"{dropped.size} epochs repeat the time of the epoch above and are dropped "
            f"(lines {lines}{more})",
        )
    return times, keep


def _decode(path, header, epochs, records, typesets, problems) -> Observations:
    """Decode all value/LLI/SSI fields of all records at once."""
    codes: list[str] = []
    for types in typesets:
        for sys_types in types.values():
            codes.extend(c for c in sys_types if c not in codes)
    epoch_time, epoch_keep = _ordered_epochs(path, header, epochs, problems)
    _drop_records(path, records, epoch_keep, problems)
    longest = max((len(row) for row in records.rows), default=0)
    n_fields = max(len(t) for types in typesets for t in types.values())
    n_fields = max(1, min(n_fields, -(-longest // FIELD_WIDTH)))
    width = FIELD_WIDTH * n_fields
    n_rec = len(records.rows)
    buffer = b"".join(row[:width].ljust(width) for row in records.rows)
    matrix = np.frombuffer(buffer, dtype=np.uint8).reshape(n_rec, n_fields, FIELD_WIDTH)
    system_index = np.array([SYSTEMS.index(s) for s in records.system], dtype=np.int64)
    table = np.full((len(typesets), len(SYSTEMS), n_fields), -1, dtype=np.int16)
    for t, types in enumerate(typesets):
        for s, sys_types in types.items():
            used = sys_types[:n_fields]
            table[t, SYSTEMS.index(s), : len(used)] = [codes.index(c) for c in used]
    rec_codes = table[np.asarray(records.typeset, dtype=np.int64), system_index]
    value_chars = matrix[:, :, :VALUE_WIDTH]
    present = (rec_codes >= 0) & (value_chars != 32).any(axis=2)
    missing_types = (rec_codes < 0).all(axis=1)
    for r in np.flatnonzero(missing_types):
        add_problem(
            problems, path, records.line[r], f"no observation types for system {records.system[r]}"
        )
    rec, slot = np.nonzero(present)
    chars = np.ascontiguousarray(value_chars[rec, slot])
    decimals = chars[:, _DOT_COLUMN + 1 :]
    well_formed = (chars[:, _DOT_COLUMN] == ord(".")) & (
        (decimals >= ord("0")) & (decimals <= ord("9"))
    ).all(axis=1)
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
        add_problem(
            problems,
            path,
            line,
            f"corrupt number {text[k].decode('ascii').strip()!r} "
            f"({codes[rec_codes[rec[k], slot[k]]]}) skipped",
        )
    keep = well_formed
    rec, slot, values = rec[keep], slot[keep], values[keep]
    indicators = matrix[rec, slot, VALUE_WIDTH:].astype(np.int16) - ord("0")
    indicators[(indicators < 0) | (indicators > 9)] = -1
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
        epoch_time=epoch_time[epoch_keep],
        epoch_flag=np.asarray(epochs.flag, dtype=np.int8)[epoch_keep],
        problems=tuple(problems),
    )


def _drop_records(path, records: _Records, epoch_keep: np.ndarray, problems) -> None:
    """Remove records of dropped epochs and second records of a satellite within one epoch."""
    if not records.rows:
        return
    epoch = np.asarray(records.epoch, dtype=np.int64)
    letters = np.array([ord(s) for s in records.system], dtype=np.int64)
    key = (epoch * 128 + letters) * 128 + np.asarray(records.prn, dtype=np.int64)
    _, first = np.unique(key, return_index=True)
    unique = np.zeros(key.size, dtype=bool)
    unique[first] = True
    for r in np.flatnonzero(~unique & epoch_keep[epoch]):
        add_problem(
            problems,
            path,
            records.line[r],
            f"{records.system[r]}{records.prn[r]:02d} listed twice in one epoch: second skipped",
        )
    keep = unique & epoch_keep[epoch]
    if keep.all():
        return
    for name in ("rows", "epoch", "system", "prn", "line", "typeset"):
        values = getattr(records, name)
        setattr(records, name, [v for v, k in zip(values, keep, strict=True) if k])
