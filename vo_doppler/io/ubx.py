"""u-blox UBX binary logs (pyubx2): raw measurements, GPS, QZSS, Galileo, BeiDou and GLONASS
ephemerides, the receiver's own fixes.

Framing (u-blox interface description, "UBX frame structure"): sync 0xB5 0x62, class, id,
little-endian length, payload, 8-bit Fletcher checksum over class…payload. The stream is
scanned here so that every problem names its byte offset; bytes between frames (NMEA, RTCM)
are skipped and counted; a frame with a bad checksum, a payload shorter or longer than its
message needs (an empty one included) or one pyubx2 cannot parse is skipped with a message
``FILE, byte OFFSET: …`` in ``problems`` (and the log); a truncated last frame likewise.
A file larger than ``MAX_UBX_BYTES`` is refused before it is read; the file is scanned a chunk
at a time, and after ``MAX_GAP`` bytes without a frame the rest of it is not read (a problem).
Physical bounds come from :mod:`vo_doppler.bounds`.

- RXM-RAWX → :class:`Observations`, epoch = week·604800 + rcvTow (receiver time, like a RINEX
  epoch). Per signal (gnssId, sigId → RINEX 3 code, ``SIGNAL_CODES``): pseudorange ``C`` when
  prValid, carrier phase ``L`` (cycles) when cpValid, Doppler ``D`` (Hz, positive approaching:
  already the RINEX sign, RINEX 3.05 sec. 5.2.10), C/N0 ``S`` (dB-Hz). LLI on ``L`` rows:
  bit 0 when the lock time dropped since the signal's previous epoch, bit 1 when the half cycle
  is not resolved (halfCyc = 0). Values outside ``VALUE_RANGES`` (or not finite) are dropped
  and counted, and so are signals of a satellite number outside the system's (``PRN_RANGE``).
  Reported σ (prStdev 0.01·2ⁿ m, cpStdev 0.004·n cycles, doStdev 0.002·2ⁿ Hz) are kept as a
  :class:`RowSigma`. GLONASS channel k = freqId − 7; rows
  with an unknown GLONASS slot (svId 255) are skipped.
- RXM-SFRBX → broadcast ephemerides (:mod:`vo_doppler.io.sfrbx`, shared with the ROS bag
  reader): GPS and QZSS LNAV subframes 1–3 (parity-checked; their week from RXM-RAWX or NAV-PVT),
  Galileo I/NAV words 1–5 (E1-B and E5b-I pages, CRC-checked), BeiDou D1 subframes 1–3 of the
  MEO/IGSO satellites (BCH-checked), GLONASS strings 1–4 (their day from the first RXM-RAWX
  epoch or NAV-PVT fix). A refused subframe, page or string, or an ephemeris off its system's
  orbits, is named by byte offset in ``problems`` (GPS and QZSS one by one, the others counted
  with the first named). Not decoded, counted: GPS/QZSS subframes 4–5 (almanac, ionosphere,
  UTC), BeiDou GEO (D2) and almanac subframes, Galileo alert pages, and every other system's or
  signal's navigation data (SBAS, NavIC, CNAV, F/NAV).
- NAV-PVT → :class:`ReceiverSolution`; the time is the GPS time whose second of week is iTOW,
  nearest to the message's UTC date and time plus the leap seconds of that date; a message
  whose two times disagree by more than 2 s, or without a valid date, is skipped, and so is one
  repeating the previous fix's time, or with a velocity or height no road vehicle has
  (``VELOCITY_COMPONENT``, ``GROUND_SPEED``, ``HEIGHT``); a fix earlier than the previous one
  is an error.
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import numpy as np
from pyubx2 import UBXMessageError, UBXParseError, UBXReader, UBXTypeError

from vo_doppler.bounds import (
    CARRIER_PHASE,
    CN0,
    DOPPLER,
    GROUND_SPEED,
    HEIGHT,
    PSEUDORANGE,
    VELOCITY_COMPONENT,
)
from vo_doppler.errors import InputError
from vo_doppler.io.obs_rows import observations_from_rows
from vo_doppler.io.rinex_common import prn_in_range
from vo_doppler.io.sfrbx import SYSTEMS, SfrbxMessage, decode_sfrbx
from vo_doppler.io.textfile import regular_file
from vo_doppler.model.gpstime import SECONDS_PER_WEEK, calendar_to_gps_seconds, utc_to_gps_seconds
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.observations import Observations
from vo_doppler.model.receiver_solution import ReceiverSolution
from vo_doppler.model.row_sigma import RowSigma

log = logging.getLogger(__name__)

SYNC = b"\xb5\x62"
RAWX = (0x02, 0x15)
SFRBX = (0x02, 0x13)
PVT = (0x01, 0x07)
SIGNAL_CODES: dict[tuple[int, int], str] = {
    # (gnssId, sigId) → RINEX 3 band + attribute (u-blox F9 interface description, signal table)
    (0, 0): "1C",
    (0, 3): "2L",
    (0, 4): "2S",
    (0, 6): "5I",
    (0, 7): "5Q",
    (1, 0): "1C",
    (2, 0): "1C",
    (2, 1): "1B",
    (2, 3): "5I",
    (2, 4): "5Q",
    (2, 5): "7I",
    (2, 6): "7Q",
    (2, 8): "6B",
    (2, 9): "6C",
    (2, 10): "6A",
    (3, 0): "2I",
    (3, 1): "2I",
    (3, 2): "7I",
    (3, 3): "7I",
    (3, 4): "6I",
    (3, 10): "6I",
    (3, 5): "1P",
    (3, 6): "1D",
    (3, 7): "5P",
    (3, 8): "5D",
    (5, 0): "1C",
    (5, 1): "1Z",
    (5, 4): "2S",
    (5, 5): "2L",
    (5, 8): "5I",
    (5, 9): "5Q",
    (6, 0): "1C",
    (6, 2): "2C",
    (7, 0): "5A",
}
VALUE_RANGES = {  # plausible RXM-RAWX values; others (and NaN) are dropped and counted
    "C": (PSEUDORANGE.low, PSEUDORANGE.high),  # pseudorange, m
    "L": (CARRIER_PHASE.low, CARRIER_PHASE.high),  # carrier phase, cycles
    "D": (DOPPLER.low, DOPPLER.high),  # Doppler, Hz
    "S": (CN0.low, CN0.high),  # C/N0, dB-Hz
}
MAX_UBX_BYTES = 1 << 30
"""Largest UBX log read, 1 GiB (about 10 h of 10-Hz RXM-RAWX with 30 signals; its rows fill
several GB of memory): a larger file is refused before any byte is read."""
MAX_GAP = 16 << 20
"""Bytes without a UBX frame after which the rest of a file is not read: NMEA or RTCM between
frames take far less; a file whose logger reserved space it never wrote is NUL bytes."""
READ_CHUNK = 1 << 20
PVT_PAYLOAD = 92
"""NAV-PVT payload length (bytes, u-blox 8 / 9 interface descriptions)."""
PVT_TIME_TOLERANCE_S = 2.0  # iTOW vs UTC + leap seconds: a leap second unknown to the table
_PARSE_ERRORS = (UBXParseError, UBXMessageError, UBXTypeError, ValueError, struct.error)


@dataclass(frozen=True)
class UbxRecording:
    """What a UBX log holds: observations (None without RXM-RAWX), broadcast ephemerides, the
    receiver's fixes, the receiver-reported σ per observation row, and skipped-data messages."""

    observations: Observations | None
    navigation: Navigation
    solution: ReceiverSolution
    sigma: RowSigma
    problems: tuple[str, ...]
    path: Path


def checksum(body: bytes) -> bytes:
    """8-bit Fletcher checksum (CK_A, CK_B) of class, id, length and payload."""
    a = b = 0
    for byte in body:
        a = (a + byte) & 0xFF
        b = (b + a) & 0xFF
    return bytes((a, b))


class _Window:
    """The part of a binary stream being scanned, read a chunk at a time: a UBX frame is at most
    65,543 bytes, so the scan holds about one chunk whatever the file's size."""

    def __init__(self, stream: BinaryIO, path: Path) -> None:
        self.stream, self.path = stream, path
        self.data = b""
        self.base = 0
        """The file offset of ``data[0]``."""
        self.eof = False

    def need(self, start: int, count: int) -> tuple[int, bool]:
        """Make ``count`` bytes from index ``start`` available, dropping the bytes before
        ``start`` when more must be read; the index of those bytes now, and whether there are
        that many (False at the end of the file)."""
        while len(self.data) - start < count and not self.eof:
            self.data, self.base, start = self.data[start:], self.base + start, 0
            try:
                chunk = self.stream.read(max(READ_CHUNK, count))
            except OSError as exc:
                raise InputError(f"cannot read UBX file: {exc.strerror or exc}", self.path) from exc
            self.eof = not chunk
            self.data += chunk
        return start, len(self.data) - start >= count


def frames(
    stream: BinaryIO, path: Path, problems: list[str]
) -> Iterator[tuple[int, int, int, bytes]]:
    """(offset, class, id, frame) of every well-formed UBX frame, in stream order, read from
    ``stream`` a chunk at a time; after :data:`MAX_GAP` bytes without a frame the rest of the
    stream is not read (with a problem saying so)."""
    window = _Window(stream, path)
    position = skipped = gap = 0
    while True:
        start = window.data.find(SYNC, position)
        if start < 0:
            tail = max(position, len(window.data) - 1)  # its last byte may begin a sync
            skipped, gap = skipped + tail - position, gap + tail - position
            if gap > MAX_GAP:
                _problem(
                    problems,
                    path,
                    window.base + tail,
                    f"no UBX frame in the {MAX_GAP >> 20} MiB before: the rest of the file is "
                    "not read (not UBX data, or space the logger reserved and never wrote)",
                )
                break
            position, more = window.need(tail, 2)
            if not more:
                skipped += len(window.data) - position
                break
            continue
        skipped, gap = skipped + start - position, gap + start - position
        start, complete = window.need(start, 6)
        if not complete:
            _problem(problems, path, window.base + start, "truncated UBX header at end of file")
            break
        length = int.from_bytes(window.data[start + 4 : start + 6], "little")
        start, complete = window.need(start, 8 + length)
        offset = window.base + start
        if not complete:
            _problem(problems, path, offset, f"truncated UBX frame ({length}-byte payload)")
            break
        frame = window.data[start : start + 8 + length]
        if checksum(frame[2:-2]) != frame[-2:]:
            _problem(problems, path, offset, "UBX checksum mismatch: frame skipped")
            position = start + 2
            continue
        yield offset, frame[2], frame[3], frame
        position, gap = start + 8 + length, 0
    if skipped:
        _problem(problems, path, 0, f"{skipped} bytes outside UBX frames skipped")


def _payload_problem(kind: tuple[int, int], payload: bytes) -> str | None:
    """Why a RXM-RAWX, RXM-SFRBX or NAV-PVT payload cannot hold its message, or None: its length
    must be the fixed part plus what its own count field announces."""
    name, length = {RAWX: "RXM-RAWX", SFRBX: "RXM-SFRBX", PVT: "NAV-PVT"}[kind], len(payload)
    if kind == PVT:
        expected = PVT_PAYLOAD
    elif kind == RAWX:
        expected = 16 + 32 * payload[11] if length >= 16 else 16
    else:
        expected = 8 + 4 * payload[4] if length >= 8 else 8
    if length != expected:
        return f"{name} payload of {length} bytes, expected {expected}"
    return None


def _problem(problems: list[str], path: Path, offset: int, message: str) -> None:
    text = f"{path}, byte {offset}: {message}"
    log.warning(text)
    problems.append(text)


def read_ubx(path: str | Path) -> UbxRecording:
    """Read a UBX log (module docstring). Raises :class:`InputError` when nothing usable is in
    it or when RXM-RAWX epochs go back in time."""
    path = Path(path)
    regular_file(path, "UBX file", MAX_UBX_BYTES)
    try:
        stream = path.open("rb")
    except OSError as exc:
        raise InputError(f"cannot read UBX file: {exc.strerror or exc}", path) from exc
    with stream:
        return _read_stream(stream, path)


def _read_stream(stream: BinaryIO, path: Path) -> UbxRecording:
    """What :func:`read_ubx` returns, from the open file ``stream``."""
    problems: list[str] = []
    raw = _RawxRows()
    pvt: list[dict[str, float]] = []
    navigation_data: list[SfrbxMessage] = []
    for offset, cls, mid, frame in frames(stream, path, problems):
        if (cls, mid) not in (RAWX, SFRBX, PVT):
            continue
        wrong = _payload_problem((cls, mid), frame[6:-2])
        if wrong:
            _problem(problems, path, offset, f"{wrong}: frame skipped")
            continue
        try:
            message = UBXReader.parse(frame)
        except _PARSE_ERRORS as exc:
            _problem(problems, path, offset, f"unparsable UBX message: {exc}")
            continue
        if (cls, mid) == RAWX:
            raw.add(message, offset, path, problems)
        elif (cls, mid) == PVT:
            fix = _pvt_fields(message, offset, path, problems)
            if fix is not None and _in_order(pvt, fix["t"], offset, path, problems):
                pvt.append(fix)
        else:
            words = tuple(getattr(message, f"dwrd_{k:02d}") for k in range(1, message.numWords + 1))
            navigation_data.append(
                SfrbxMessage(
                    offset, message.gnssId, message.svId, message.sigId, message.freqId, words
                )
            )
    if not (raw.time or pvt or navigation_data):
        raise InputError("no UBX RXM-RAWX, RXM-SFRBX or NAV-PVT message", path)
    week = raw.week if raw.week is not None else _week_of(pvt)
    reference = raw.time[0] if raw.time else (pvt[0]["t"] if pvt else None)
    navigation = _navigation(navigation_data, week, reference, path, problems)
    observations = raw.observations(path, problems) if raw.time else None
    return UbxRecording(
        observations, navigation, _solution(pvt), raw.sigma(), tuple(problems), path
    )


class _RawxRows:
    """Row lists of RXM-RAWX messages and the lock-time state behind the LLI."""

    def __init__(self) -> None:
        self.time: list[float] = []
        self.system: list[str] = []
        self.prn: list[int] = []
        self.code: list[str] = []
        self.value: list[float] = []
        self.lli: list[int] = []
        self.sigma_value: list[float] = []
        self.channels: dict[int, int] = {}
        self.lock: dict[tuple[int, int, int], int] = {}
        self.week: int | None = None
        self.n_unknown = 0
        self.n_out_of_range = 0

    def add(self, message, offset: int, path: Path, problems: list[str]) -> None:
        tow, week = float(message.rcvTow), int(message.week)
        if not (np.isfinite(tow) and 0.0 <= tow < SECONDS_PER_WEEK and 0 < week < 8192):
            _problem(problems, path, offset, f"RXM-RAWX time out of range (week {week}, {tow})")
            return
        t = week * SECONDS_PER_WEEK + tow
        if self.time and t < self.time[-1]:
            raise InputError(
                f"RXM-RAWX epoch {t:.3f} before the previous one {self.time[-1]:.3f}",
                path,
                byte=offset,
            )
        self.week = week if self.week is None else self.week
        for k in range(1, int(message.numMeas) + 1):
            self._signal(message, f"_{k:02d}", t)

    def _signal(self, m, s: str, t: float) -> None:
        gnss, sv, sig = getattr(m, "gnssId" + s), getattr(m, "svId" + s), getattr(m, "sigId" + s)
        band = SIGNAL_CODES.get((gnss, sig))
        if band is None or (gnss == 6 and sv == 255):
            self.n_unknown += 1
            return
        system = SYSTEMS[gnss]
        prn = sv - 100 if system == "S" else sv
        if not prn_in_range(system, prn):
            self.n_unknown += 1
            return
        if system == "R":
            self.channels[prn] = int(getattr(m, "freqId" + s)) - 7
        lock = int(getattr(m, "locktime" + s))
        previous = self.lock.get((gnss, sv, sig))
        self.lock[(gnss, sv, sig)] = lock
        slip = previous is not None and lock < previous
        lli = int(slip) | (0 if getattr(m, "halfCyc" + s) else 2)
        rows = [("D", getattr(m, "doMes" + s), 0.002 * 2 ** getattr(m, "doStd" + s), -1)]
        rows.append(("S", float(getattr(m, "cno" + s)), np.nan, -1))
        if getattr(m, "prValid" + s):
            rows.append(("C", getattr(m, "prMes" + s), 0.01 * 2 ** getattr(m, "prStd" + s), -1))
        if getattr(m, "cpValid" + s):
            rows.append(("L", getattr(m, "cpMes" + s), 0.004 * getattr(m, "cpStd" + s), lli))
        for kind, value, sigma, flag in rows:
            low, high = VALUE_RANGES[kind]
            if not low <= value <= high:  # False for NaN too
                self.n_out_of_range += 1
                continue
            self.time.append(t)
            self.system.append(system)
            self.prn.append(prn)
            self.code.append(kind + band)
            self.value.append(float(value))
            self.sigma_value.append(sigma)
            self.lli.append(flag)

    def observations(self, path: Path, problems: list[str]) -> Observations:
        if self.n_unknown:
            _problem(
                problems,
                path,
                0,
                f"{self.n_unknown} RXM-RAWX signals of unknown kind or satellite number",
            )
        if self.n_out_of_range:
            _problem(problems, path, 0, f"{self.n_out_of_range} RXM-RAWX values out of range")
        return observations_from_rows(
            path,
            "u-blox (UBX RXM-RAWX)",
            np.array(self.time),
            np.array(self.system, dtype="U1"),
            np.array(self.prn),
            np.array(self.code, dtype="U3"),
            np.array(self.value),
            np.array(self.lli),
            self.channels,
            tuple(problems),
        )

    def sigma(self) -> RowSigma:
        return RowSigma(
            np.array(self.time, dtype=float),
            np.array(self.system, dtype="U1"),
            np.array(self.prn, dtype=np.int16),
            np.array(self.code, dtype="U3"),
            np.array(self.sigma_value, dtype=float),
        )


def _pvt_fields(message, offset: int, path: Path, problems: list[str]) -> dict[str, float] | None:
    """NAV-PVT in SI units and radians, or None (with a problem) when it cannot be placed."""
    m = message
    if not (m.validDate and m.validTime):
        _problem(problems, path, offset, "NAV-PVT without a valid UTC date/time: skipped")
        return None
    if abs(m.lat) > 90 or abs(m.lon) > 180 or not 0 <= m.iTOW < SECONDS_PER_WEEK * 1000:
        _problem(problems, path, offset, "NAV-PVT latitude, longitude or iTOW out of range")
        return None
    velocity = np.array([m.velN, m.velE, m.velD]) / 1000.0
    if (
        VELOCITY_COMPONENT.outside(velocity).any()
        or GROUND_SPEED.outside(np.array([m.gSpeed / 1000.0]))[0]
        or HEIGHT.outside(np.array([m.height / 1000.0]))[0]
    ):
        _problem(
            problems,
            path,
            offset,
            f"NAV-PVT velocity (N {velocity[0]:g}, E {velocity[1]:g}, D {velocity[2]:g} m/s), "
            f"speed {m.gSpeed / 1000.0:g} m/s or height {m.height / 1000.0:g} m beyond a road "
            f"vehicle's ({VELOCITY_COMPONENT}, {GROUND_SPEED}, {HEIGHT}): skipped",
        )
        return None
    try:
        utc = calendar_to_gps_seconds(m.year, m.month, m.day, m.hour, m.min, m.second)
    except (ValueError, OverflowError):
        _problem(problems, path, offset, "NAV-PVT date out of range: skipped")
        return None
    approx = float(utc_to_gps_seconds(utc)) + m.nano * 1e-9
    sow = m.iTOW / 1000.0
    delta = sow - np.mod(approx, SECONDS_PER_WEEK)
    delta -= SECONDS_PER_WEEK * np.round(delta / SECONDS_PER_WEEK)
    if abs(delta) > PVT_TIME_TOLERANCE_S:
        _problem(problems, path, offset, f"NAV-PVT iTOW and UTC time disagree by {delta:.3f} s")
        return None
    return {
        "t": approx + delta,
        "lat": np.radians(m.lat),
        "lon": np.radians(m.lon),
        "height": m.height / 1000.0,
        "vn": m.velN / 1000.0,
        "ve": m.velE / 1000.0,
        "vd": m.velD / 1000.0,
        "speed": m.gSpeed / 1000.0,
        "course": np.radians(m.headMot),
        "speed_accuracy": m.sAcc / 1000.0,
        "course_accuracy": np.radians(m.headAcc),
        "horizontal_accuracy": m.hAcc / 1000.0,
        "vertical_accuracy": m.vAcc / 1000.0,
        "fix_ok": float(m.gnssFixOk),
        "n_sat": float(m.numSV),
    }


def _in_order(pvt: list[dict[str, float]], t: float, offset: int, path: Path, problems) -> bool:
    """Whether a NAV-PVT fix comes after the previous one: a repeated time is skipped with a
    problem, an earlier one is an :class:`InputError` naming the offset (as for RXM-RAWX)."""
    if not pvt or t > pvt[-1]["t"]:
        return True
    if t == pvt[-1]["t"]:
        _problem(problems, path, offset, "NAV-PVT repeats the previous fix's time: skipped")
        return False
    raise InputError(
        f"NAV-PVT time {t:.3f} before the previous one {pvt[-1]['t']:.3f}", path, byte=offset
    )


def _week_of(pvt: list[dict[str, float]]) -> int | None:
    return int(pvt[0]["t"] // SECONDS_PER_WEEK) if pvt else None


def _solution(pvt: list[dict[str, float]]) -> ReceiverSolution:
    def column(name: str) -> np.ndarray:
        return np.array([p[name] for p in pvt], dtype=float)

    return ReceiverSolution(
        t=column("t"),
        lat=column("lat"),
        lon=column("lon"),
        height=column("height"),
        velocity_ned=np.stack([column("vn"), column("ve"), column("vd")], axis=1),
        speed=column("speed"),
        course=column("course"),
        speed_accuracy=column("speed_accuracy"),
        course_accuracy=column("course_accuracy"),
        horizontal_accuracy=column("horizontal_accuracy"),
        vertical_accuracy=column("vertical_accuracy"),
        fix_ok=column("fix_ok").astype(bool),
        n_sat=column("n_sat").astype(np.int64),
    )


def _navigation(
    messages: list[SfrbxMessage], week: int | None, reference: float | None, path: Path, problems
) -> Navigation:
    """The ephemerides of the RXM-SFRBX messages (:mod:`vo_doppler.io.sfrbx`: GPS and QZSS need
    a full week, GLONASS a GPS time, from RXM-RAWX or NAV-PVT), their problems named by byte
    offset."""
    decoded = decode_sfrbx(messages, week, reference)
    for offset, text in decoded.problems:
        _problem(problems, path, 0 if offset is None else offset, text)
    return Navigation(decoded.kepler, decoded.glonass, problems=tuple(problems))
