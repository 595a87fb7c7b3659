"""GPS fixes from a CSV file (``t,lat_deg,lon_deg[,speed_mps]``) or from NMEA 0183 sentences.

NMEA: GGA, RMC and VTG sentences through pynmeagps. Fix times become GPS time in seconds since
1980-01-06 (UTC + leap seconds) once an RMC sentence has given the date; a file without RMC has
no date, so its times stay UTC seconds of day (logged). Sentences with a bad checksum or no fix
(GGA quality 0, RMC status V, VTG mode N) are skipped and counted. A speed over ground (RMC's,
or VTG's in km/h, else in knots) beyond what a vehicle can report
(:data:`vo_doppler.bounds.GROUND_SPEED`: negative or above 150 m/s) skips its
sentence, warned with its line; more than 1 % of the speeds beyond it is an error naming the
first such line (the receiver's output is wrong, not a sentence). When GGA and RMC report the
same time, one fix is kept (GGA position, RMC speed over ground). Fix times must not go
backwards (the ``"error"`` policy of :mod:`vo_doppler.io.time_order`, naming the sentence's
line).

VTG carries no time. Receivers send it in the burst of sentences of one epoch, after that
epoch's GGA or RMC, so a VTG speed goes with the time of the last GGA or RMC before it; it fills
the speed of that fix unless an RMC gives one (the first VTG after a time counts). A VTG before
any GGA or RMC, or after one that is unreadable or has no fix, has no fix to go with and is
skipped and counted (warned with its first line: a receiver that sends VTG first in each epoch
would have its speeds one epoch late, which the file cannot show).
"""

from __future__ import annotations

import datetime as dt
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from pynmeagps import NMEAMessageError, NMEAParseError, NMEAReader, NMEATypeError

from vo_doppler.bounds import (
    GROUND_SPEED,
    LATITUDE_DEG,
    LONGITUDE_DEG,
    too_many_out_of_range,
)
from vo_doppler.errors import InputError
from vo_doppler.io.sensor_csv import read_numeric_csv
from vo_doppler.io.textfile import read_text, regular_file
from vo_doppler.io.time_order import order_samples
from vo_doppler.model.gpstime import calendar_to_gps_seconds
from vo_doppler.model.gpstime import utc_to_gps_seconds as gpstime_utc_to_gps

log = logging.getLogger(__name__)

KNOT_MPS = 1852.0 / 3600.0


@dataclass(frozen=True)
class GpsFixes:
    """Fixes: time (s), latitude and longitude (rad), speed over ground (m/s, NaN if unknown)."""

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    speed: np.ndarray
    path: Path
    n_skipped: int = 0
    time_system: str = "gps"

    def as_tuple(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return self.t, self.lat, self.lon


def utc_to_gps_seconds(moment: dt.datetime) -> float:
    """UTC date-time (naive means UTC) to GPS seconds since 1980-01-06 (leap seconds added)."""
    if moment.tzinfo is not None:
        moment = moment.astimezone(dt.UTC).replace(tzinfo=None)
    second = moment.second + moment.microsecond * 1e-6
    as_gps = calendar_to_gps_seconds(
        moment.year, moment.month, moment.day, moment.hour, moment.minute, second
    )
    return float(gpstime_utc_to_gps(as_gps))


def read_gps_csv(path: str | Path) -> GpsFixes:
    """Read a ``t,lat_deg,lon_deg`` CSV, optionally with a ``speed_mps`` column (a speed over
    ground: a negative one is read as unknown, with a warning)."""
    columns, report = read_numeric_csv(path, ("t", "lat_deg", "lon_deg"), ("speed_mps",))
    speed = columns.get("speed_mps", np.full(len(columns["t"]), np.nan))
    negative = speed < GROUND_SPEED.low
    if np.any(negative):
        log.warning(
            "%s: %d speeds over ground below %g m/s (first %g): read as unknown",
            path,
            int(negative.sum()),
            GROUND_SPEED.low,
            speed[negative][0],
        )
        speed = np.where(negative, np.nan, speed)
    bad = (np.abs(columns["lat_deg"]) > 90) | (np.abs(columns["lon_deg"]) > 180)
    if np.all(bad) and bad.size:
        raise InputError(
            f"all {bad.size} fixes lie outside lat ±90°, lon ±180°: are the lat_deg and lon_deg "
            "columns swapped?",
            path,
        )
    if np.any(bad):
        log.warning("%s: skipped %d fixes outside lat ±90°, lon ±180°", path, int(np.sum(bad)))
    good = ~bad
    return GpsFixes(
        columns["t"][good],
        np.radians(columns["lat_deg"][good]),
        np.radians(columns["lon_deg"][good]),
        speed[good],
        Path(path),
        report.n_skipped + int(np.sum(bad)),
    )


def write_gps_csv(path, t, lat_rad, lon_rad, speed_mps=None) -> None:
    """Write fixes as ``t,lat_deg,lon_deg[,speed_mps]`` with full precision."""
    columns = [np.asarray(t, float), np.degrees(lat_rad), np.degrees(lon_rad)]
    header = "t,lat_deg,lon_deg"
    if speed_mps is not None:
        columns.append(np.asarray(speed_mps, float))
        header += ",speed_mps"
    np.savetxt(
        path, np.column_stack(columns), delimiter=",", fmt="%.17g", header=header, comments=""
    )


def _seconds_of_day(value: dt.time) -> float:
    return value.hour * 3600.0 + value.minute * 60.0 + value.second + value.microsecond * 1e-6


@dataclass
class _Sentences:
    """The readable GGA/RMC messages with a fix and the VTG messages with a speed (line,
    message, time of day: a VTG's is that of the GGA or RMC before it), and what was skipped."""

    messages: list = field(default_factory=list)
    n_bad: int = 0
    n_nofix: int = 0
    n_speeds: int = 0
    """RMC and VTG sentences with a fix and a speed over ground."""
    out_of_range: list[tuple[int, float, str, str]] = field(default_factory=list)
    """(line, speed in m/s, the sentence's value and unit, sentence type) of the speeds beyond
    ``GROUND_SPEED`` (sentences skipped)."""
    speed_kinds: set[str] = field(default_factory=set)
    """The types of the sentences that gave a speed over ground (RMC, VTG)."""
    unpaired: list[int] = field(default_factory=list)
    """Lines of the VTG sentences with no GGA or RMC fix before them to go with."""


TIMED = (b"GGA", b"RMC")
"""Sentence types whose time a VTG after them goes with."""


def _sentence_type(raw: bytes) -> bytes:
    """``GGA`` of ``$GPGGA,...``: the type after the two-letter talker."""
    return raw[3:6]


def _vtg_speed(message) -> tuple[float, str] | None:
    """A VTG's speed over ground (m/s) from its km/h field, else its knots field, with the
    value as the sentence gives it; None without either."""
    if message.sogk != "":
        return float(message.sogk) / 3.6, f"{float(message.sogk):g} km/h"
    if message.sogn != "":
        return float(message.sogn) * KNOT_MPS, f"{float(message.sogn):g} knots"
    return None


def _parse_sentences(path: Path, lines: list[bytes]) -> _Sentences:
    """Readable GGA/RMC messages with a fix, VTG messages paired with the time before them,
    each with a speed a vehicle can have, and the counts of the skipped ones."""
    found = _Sentences()
    anchor: dt.time | None = None
    for number, raw in enumerate(lines, start=1):
        raw = raw.strip()
        if not raw.startswith(b"$"):
            continue
        try:
            message = NMEAReader.parse(raw)
        except (NMEAParseError, NMEAMessageError, NMEATypeError, ValueError) as exc:
            found.n_bad += 1
            anchor = None if _sentence_type(raw) in TIMED else anchor
            log.debug("%s:%d: %s", path, number, exc)
            continue
        if message is None or message.msgID not in ("GGA", "RMC", "VTG"):
            continue
        if message.msgID == "VTG":
            _add_vtg(found, number, message, anchor)
            continue
        gga = message.msgID == "GGA"
        no_fix = message.quality in (0, "") if gga else message.status != "A"
        anchor = message.time or None
        if no_fix or "" in (message.lat, message.lon, message.time):
            found.n_nofix += 1
            continue
        if LATITUDE_DEG.outside([message.lat])[0] or LONGITUDE_DEG.outside([message.lon])[0]:
            found.n_bad += 1
            log.warning(
                "%s:%d: latitude %s, longitude %s outside %s, %s: sentence skipped",
                path,
                number,
                message.lat,
                message.lon,
                LATITUDE_DEG,
                LONGITUDE_DEG,
            )
            continue
        if not gga and message.spd != "":
            speed = float(message.spd) * KNOT_MPS
            if _out_of_range(found, number, (speed, f"{float(message.spd):g} knots"), "RMC"):
                continue
        found.messages.append((number, message, message.time))
    return found


def _add_vtg(found: _Sentences, number: int, message, anchor: dt.time | None) -> None:
    """Keep a VTG with a speed a vehicle can have, paired with ``anchor`` (the time of the
    last GGA or RMC before it; None: none, or an unreadable one)."""
    if getattr(message, "posMode", "") == "N":
        found.n_nofix += 1
        return
    speed = _vtg_speed(message)
    if speed is None:
        return
    if anchor is None:
        found.unpaired.append(number)
        return
    if not _out_of_range(found, number, speed, "VTG"):
        found.messages.append((number, message, anchor))


def _out_of_range(found: _Sentences, number: int, speed: tuple[float, str], kind: str) -> bool:
    """Count a ``kind`` sentence's speed (m/s, as given); True, and noted, when it lies beyond
    ``GROUND_SPEED``."""
    found.n_speeds += 1
    found.speed_kinds.add(kind)
    if GROUND_SPEED.outside(speed[0]):
        found.out_of_range.append((number, *speed, kind))
        return True
    return False


def _check_speeds(path: Path, found: _Sentences) -> None:
    """Raise when the speeds beyond ``GROUND_SPEED`` are more than isolated bad sentences;
    warn with their lines when they are."""
    if not found.out_of_range:
        return
    line, speed, given, kind = found.out_of_range[0]
    n_out = len(found.out_of_range)
    if too_many_out_of_range(n_out, found.n_speeds):
        raise InputError(
            f"{kind} speed over ground {speed:g} m/s ({given}) is outside what a vehicle can "
            f"report, {GROUND_SPEED}, and so are {n_out} of the {found.n_speeds} "
            f"{' and '.join(sorted(found.speed_kinds))} speeds: not isolated bad sentences; "
            "check the receiver's output",
            path,
            line,
        )
    kinds = " and ".join(sorted({entry[3] for entry in found.out_of_range}))
    lines = ", ".join(str(entry[0]) for entry in found.out_of_range[:10])
    more = f" and {n_out - 10} more" if n_out > 10 else ""
    log.warning(
        "%s: skipped %d %s sentences with a speed over ground outside %s (first %g m/s; "
        "lines %s%s)",
        path,
        n_out,
        kinds,
        GROUND_SPEED,
        speed,
        lines,
        more,
    )


def read_nmea(path: str | Path) -> GpsFixes:
    """Read GGA/RMC fixes, with RMC or VTG speeds, from an NMEA 0183 log (midnight roll-overs
    follow the time of day; VTG pairing in the module docstring)."""
    path = Path(path)
    lines = [line.encode("ascii", "replace") for line in read_text(path, "NMEA file").split("\n")]
    found = _parse_sentences(path, lines)
    messages, n_bad, n_nofix = found.messages, found.n_bad, found.n_nofix
    if n_bad or n_nofix:
        log.warning(
            "%s: skipped %d unreadable sentences and %d without a fix", path, n_bad, n_nofix
        )
    _check_speeds(path, found)
    if all(m.msgID == "VTG" for _, m, _ in messages):
        raise InputError("no GGA or RMC fix found in the NMEA file", path)
    date = next((m.date for _, m, _ in messages if m.msgID == "RMC" and m.date != ""), None)
    if date is None:
        log.warning("%s: no RMC date, fix times are UTC seconds of day", path)
    fixes: dict[float, list[float]] = {}
    first_line: dict[float, int] = {}
    previous = None
    for number, message, when in messages:
        if message.msgID == "RMC" and message.date != "":
            date = message.date
        elif (
            previous is not None
            and date is not None
            and _seconds_of_day(when) < _seconds_of_day(previous) - 43200.0
        ):
            date += dt.timedelta(days=1)
        previous = when
        if date is None:
            t = _seconds_of_day(when)
        else:
            t = utc_to_gps_seconds(dt.datetime.combine(date, when))
        if message.msgID == "VTG":
            _pair_vtg(fixes.get(t), number, message, found)
            continue
        entry = fixes.setdefault(t, [np.nan, np.nan, np.nan])
        first_line.setdefault(t, number)
        if message.msgID == "GGA" or np.isnan(entry[0]):
            entry[0], entry[1] = float(message.lat), float(message.lon)
        if message.msgID == "RMC" and message.spd != "":
            entry[2] = float(message.spd) * KNOT_MPS
    _warn_unpaired(path, found.unpaired)
    times, rows, _ = order_samples(
        np.array(list(fixes), dtype=float),
        np.array(list(fixes.values()), dtype=float),
        path,
        "NMEA fixes",
        np.array(list(first_line.values())),
    )
    return GpsFixes(
        times,
        np.radians(rows[:, 0]),
        np.radians(rows[:, 1]),
        rows[:, 2],
        path,
        n_bad + n_nofix + len(found.out_of_range) + len(found.unpaired),
        "gps" if date is not None else "utc-seconds-of-day",
    )


def _pair_vtg(entry: list[float] | None, number: int, message, found: _Sentences) -> None:
    """Give a VTG's speed to the fix at its time (``entry``: latitude, longitude, speed) when
    no RMC or earlier VTG gave one; without a fix there, the VTG is unpaired."""
    if entry is None:
        found.unpaired.append(number)
    elif np.isnan(entry[2]):
        entry[2] = _vtg_speed(message)[0]


def _warn_unpaired(path: Path, unpaired: list[int]) -> None:
    if unpaired:
        log.warning(
            "%s: skipped %d VTG sentences with no GGA or RMC fix before them to take the time "
            "of (VTG has none; first line %d)",
            path,
            len(unpaired),
            min(unpaired),
        )


def read_gps_fixes(path: str | Path) -> GpsFixes:
    """Read fixes from a CSV or an NMEA file: NMEA when one of the first lines starts with $."""
    path = Path(path)
    regular_file(path, "GPS file")
    try:
        with path.open("rb") as handle:
            head = handle.read(8192).splitlines()[:20]
    except OSError as exc:
        raise InputError(f"cannot read GPS file: {exc.strerror or exc}", path) from exc
    is_nmea = any(line.lstrip().startswith(b"$") for line in head)
    return read_nmea(path) if is_nmea else read_gps_csv(path)
