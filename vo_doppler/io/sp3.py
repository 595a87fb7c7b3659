"""SP3-c / SP3-d precise orbit files (NGS/IGS "The Extended Standard Product 3 Orbit Format",
SP3-c 2007, SP3-d 2016) → :class:`PreciseOrbits`.

Read: the first line (version ``c``/``d``, position-only or position+velocity flag, number of
epochs, coordinate system, agency), the ``+`` satellite list (any number of lines, as SP3-d
allows), the ``%c`` time system, the ``*`` epoch lines and the ``P`` position/clock records
(km, µs; a position of 0.000000 or a clock of 999999.999999 marks a missing value). A file
with fewer epochs than its first line declares (trimmed to a recording's hours, or cut short)
is read with a warning when its epochs start at the header's start time and keep its
interval; more epochs than declared, or epochs that do not fit the header, are an error. Velocity
(``V``) and correlation (``EP``/``EV``) records are skipped: the GNSS stage differentiates the
interpolated positions. CRLF line endings are accepted. Errors name the file and the line.
"""

from __future__ import annotations

import logging
import math
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.io.rinex_common import PRN_RANGE, parse_calendar, prn_in_range
from vo_doppler.io.textfile import regular_file
from vo_doppler.model.gpstime import BDT_MINUS_GPST_S, calendar_to_gps_seconds, utc_to_gps_seconds
from vo_doppler.model.precise_orbits import PreciseOrbits

log = logging.getLogger(__name__)

BAD_CLOCK_US = 999999.0
MAX_CLOCK_S = 0.1
"""Satellite clocks are steered to within a few ms of system time (7 ms seen in an IGS product):
a larger value in a clock field is a damaged file."""
ORBIT_RADIUS_M = (1.0e7, 5.0e7)
"""Geocentric distances of GNSS satellites (MEO about 2.6e7 m, GEO/IGSO 4.2e7 m)."""
TAI_MINUS_GPST_S = 19.0
GLONASS_TIME_MINUS_UTC_S = 3 * 3600.0
TIME_SYSTEMS = ("GPS", "GAL", "QZS", "IRN", "BDT", "TAI", "UTC", "GLO")


def to_gps_seconds(calendar_seconds: np.ndarray, time_system: str) -> np.ndarray:
    """Calendar times of a product's time system (read as if GPS) to GPS seconds (RINEX 3.05
    sec. 6.1: GST, QZSST and IRNSST run on GPS time, BDT = GPST − 14 s, TAI = GPST + 19 s,
    GLONASS time = UTC + 3 h)."""
    t = np.asarray(calendar_seconds, dtype=float)
    if time_system in ("GPS", "GAL", "QZS", "IRN"):
        return t
    if time_system == "BDT":
        return t - BDT_MINUS_GPST_S
    if time_system == "TAI":
        return t - TAI_MINUS_GPST_S
    if time_system == "GLO":
        t = t - GLONASS_TIME_MINUS_UTC_S
    return utc_to_gps_seconds(t)


def satellite_id(text: str) -> str:
    """'G05' from an SP3 satellite field ('G05', 'G 5', ' 5' = GPS in old files); ValueError
    for a system or number that does not exist (``PRN_RANGE``)."""
    if len(text) < 3:
        raise ValueError(f"no satellite {text!r}")
    letter = text[0] if text[0] != " " else "G"
    number = int(text[1:3])
    if letter not in PRN_RANGE or not prn_in_range(letter, number):
        raise ValueError(f"no satellite {text!r}")
    return f"{letter}{number:02d}"


PRODUCT_MAX_BYTES = 256 << 20
"""Largest SP3 or RINEX clock file read (a day of 5-s clocks of every satellite is about
120 MB): a larger one is refused before it is read."""


def text_lines(path: Path, what: str) -> list[str]:
    """The lines of a text product, LF or CRLF (splitlines drops either); a file larger than
    :data:`PRODUCT_MAX_BYTES` or holding a NUL byte (no text does) is an error."""
    regular_file(path, f"{what} file", PRODUCT_MAX_BYTES)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read {what} file: {exc}", path) from exc
    nul = data.find(b"\0")
    if nul >= 0:
        line = data.count(b"\n", 0, nul) + 1
        raise InputError(f"NUL bytes: not a {what} text file", path, line)
    return data.decode("ascii", errors="replace").splitlines()


def read_sp3(path: str | Path) -> PreciseOrbits:
    """Positions (ECEF m) and clocks (s) of every listed satellite at every epoch."""
    path = Path(path)
    lines = text_lines(path, "SP3")
    if not lines or lines[0][:1] != "#" or lines[0][1:2] not in ("c", "d"):
        raise InputError("not an SP3-c/d file (first line must start with '#c' or '#d')", path, 1)
    first = lines[0]
    declared_epochs = _int(first[32:39], path, 1, "number of epochs")
    sats, time_system, body = _header(path, lines)
    n_epoch_lines = sum(1 for line in lines[body:] if line[:1] == "*")
    if n_epoch_lines > declared_epochs or n_epoch_lines == 0:
        raise InputError(f"{n_epoch_lines} epochs, header declares {declared_epochs}", path, 1)
    column = {sat: i for i, sat in enumerate(sats)}
    calendar: list[tuple[float, ...]] = []
    positions = np.full((n_epoch_lines, len(sats), 3), np.nan)
    clocks = np.full((n_epoch_lines, len(sats)), np.nan)
    for number in range(body, len(lines)):
        line = lines[number]
        tag = line[:1]
        if line.startswith("EOF"):
            break
        if tag == "*":
            calendar.append(_epoch(path, number + 1, line))
        elif tag == "P":
            if not calendar:
                raise InputError("position record before the first epoch line", path, number + 1)
            sat = _known(path, number + 1, line, column)
            positions[len(calendar) - 1, sat] = _position(path, number + 1, line)
            clocks[len(calendar) - 1, sat] = _clock(path, number + 1, line)
        elif tag not in ("V", "E", "/", ""):
            raise InputError(f"unexpected record {line[:2]!r}", path, number + 1)
    if len(calendar) != n_epoch_lines:  # epoch lines after an 'EOF' line
        raise InputError(f"{n_epoch_lines - len(calendar)} epoch lines after 'EOF'", path)
    times = to_gps_seconds(calendar_to_gps_seconds(*np.array(calendar).T), time_system)
    if np.any(np.diff(times) <= 0):
        raise InputError("epochs not strictly increasing", path)
    if len(calendar) < declared_epochs:
        _check_trimmed(path, lines, calendar, declared_epochs)
    return PreciseOrbits(
        t=times,
        sat_id=np.array(sats, dtype="U3"),
        position=positions,
        clock_s=clocks,
        time_system=time_system,
        coordinate_system=first[46:51].strip(),
        agency=first[56:60].strip(),
        path=path,
    )


def _check_trimmed(
    path: Path, lines: list[str], calendar: list[tuple[float, ...]], declared: int
) -> None:
    """Accept, with a warning naming the file and the epochs, a file holding fewer epochs than
    its first line declares (a product trimmed to the hours of a recording, or cut short)
    when the epochs read are consistent with its header: the first one at the header's start
    time, all of them spaced by the header's interval. Else an :class:`InputError` naming
    line 1, as for a damaged file."""
    read = np.array([calendar_to_gps_seconds(*c) for c in calendar], dtype=float)
    reason = ""
    try:
        start = float(calendar_to_gps_seconds(*parse_calendar(lines[0][3:31].encode())))
        interval = float(lines[1][24:38])
    except (ValueError, IndexError) as exc:
        start, interval, reason = math.nan, math.nan, f"its start or interval unreadable ({exc})"
    if not reason and read[0] != start:
        reason = "its first epoch is not the header's start time"
    elif not reason and not np.allclose(np.diff(read), interval, rtol=0.0, atol=1e-6):
        reason = f"its epochs are not spaced by the header's interval of {interval:g} s"
    if reason:
        raise InputError(
            f"{len(calendar)} epochs, header declares {declared}, and {reason}", path, 1
        )
    log.warning(
        "%s: %d of the %d epochs the header declares (trimmed or cut short): read the "
        "epochs from %s to %s (every %g s); observations outside them get no satellite state",
        path,
        len(calendar),
        declared,
        _stamp(calendar[0]),
        _stamp(calendar[-1]),
        interval,
    )


def _stamp(calendar: tuple[float, ...]) -> str:
    """'2018-08-02 14:00:00' of a calendar epoch."""
    y, mo, d, h, mi, s = calendar
    return f"{int(y):04d}-{int(mo):02d}-{int(d):02d} {int(h):02d}:{int(mi):02d}:{s:02.0f}"


def _header(path: Path, lines: list[str]) -> tuple[list[str], str, int]:
    """Satellite list, time system, index of the first body line."""
    if len(lines) < 2 or not lines[1].startswith("##"):
        raise InputError("second line must start with '##'", path, 2)
    sats: list[str] = []
    n_sats = None
    time_system = None
    number = 2
    while number < len(lines) and not lines[number].startswith("*"):
        line = lines[number]
        if line.startswith("+ ") and n_sats is None:
            n_sats = _int(line[3:6], path, number + 1, "number of satellites")
        if line.startswith("+ "):
            sats.extend(line[9 + 3 * k : 12 + 3 * k] for k in range(17))
        elif line.startswith("%c") and time_system is None:
            time_system = line[9:12].strip()
        number += 1
    if n_sats is None:
        raise InputError("no '+' satellite list in the header", path)
    listed = [s for s in sats if s.strip() and s.strip() != "0"]
    if len(listed) < n_sats:
        raise InputError(f"{len(listed)} satellites listed, header declares {n_sats}", path)
    try:
        ids = [satellite_id(s) for s in listed[:n_sats]]
    except ValueError as exc:
        raise InputError(f"bad satellite identifier in the '+' lines: {exc}", path) from exc
    if time_system not in TIME_SYSTEMS:
        raise InputError(f"unknown time system {time_system!r} in the '%c' line", path)
    return ids, time_system, number


def _int(text: str, path: Path, line: int, what: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise InputError(f"bad {what} {text.strip()!r}", path, line) from None


def _epoch(path: Path, line_number: int, line: str) -> tuple[float, ...]:
    try:
        return tuple(float(v) for v in parse_calendar(line[1:].encode()))
    except ValueError as exc:
        raise InputError(f"bad epoch line {line.strip()!r}: {exc}", path, line_number) from None


def _position(path: Path, line_number: int, line: str) -> np.ndarray:
    """ECEF metres, NaN for the missing-value mark 0.000000; a satellite off any GNSS orbit
    (``ORBIT_RADIUS_M``) names the line."""
    try:
        xyz = np.array([float(line[4:18]), float(line[18:32]), float(line[32:46])])
    except ValueError:
        raise InputError(f"bad position in {line.strip()!r}", path, line_number) from None
    if np.all(xyz == 0.0):
        return np.full(3, np.nan)
    radius = float(np.linalg.norm(xyz)) * 1000.0 if np.all(np.abs(xyz) < 1e9) else np.nan
    if not ORBIT_RADIUS_M[0] < radius < ORBIT_RADIUS_M[1]:
        raise InputError(f"position off any GNSS orbit in {line.strip()!r}", path, line_number)
    return 1000.0 * xyz


def _clock(path: Path, line_number: int, line: str) -> float:
    """Seconds, NaN for a blank field or the missing-value mark 999999.999999."""
    text = line[46:60].strip()
    try:
        microseconds = float(text) if text else np.nan
    except ValueError:
        raise InputError(f"bad clock {text!r}", path, line_number) from None
    if np.isnan(microseconds) or microseconds >= BAD_CLOCK_US:
        return np.nan
    if not abs(microseconds) < 1e6 * MAX_CLOCK_S:
        raise InputError(f"clock {text} µs beyond ±{MAX_CLOCK_S} s", path, line_number)
    return 1e-6 * microseconds


def _known(path: Path, line_number: int, line: str, column: dict[str, int]) -> int:
    try:
        sat = satellite_id(line[1:4])
    except ValueError:
        raise InputError(f"bad satellite identifier {line[1:4]!r}", path, line_number) from None
    if sat not in column:
        raise InputError(f"satellite {sat} not in the header list", path, line_number)
    return column[sat]
