"""CAN bus logs → vehicle yaw rate and speed, decoded with a DBC.

Log formats are read by python-can (candump ``-l`` ``.log``, Vector ``.asc`` and ``.blf``,
python-can ``.csv``); signals are decoded by cantools. A signal is named ``MESSAGE.SIGNAL``;
several wheel-speed signals are averaged. Values are converted from the DBC unit to SI
(km/h → m/s, deg/s → rad/s). The yaw rate leaves this module counter-clockwise positive
(docs/design.md): ``yaw_rate_sign=-1`` flips a bus that reports clockwise-positive yaw rate.

Frames shorter than their DBC length are skipped, counted and named in a warning (their
missing bytes would decode as made-up values); ``short_frames="pad"`` zero-pads them instead,
for sources known to drop trailing zero bytes (comma2k19's ``raw_can`` arrays). Frames that
cannot be decoded, and log lines that cannot be read (including non-finite times and ids
beyond 29 bits), are counted, logged and skipped — the result keeps every frame that could be
decoded. After a bad line the line formats resume at the next line (linear time); ASC and BLF
keep what came before a corrupt record; a log in which no frame at all could be read, or without
a single frame of a requested message, is an error saying what was found. Decoded values beyond
what a car can report (:mod:`vo_doppler.bounds`) are skipped and counted when
isolated (1 % of the signal's samples at most); more is an error naming the signal and the time
of the first one (a wrong DBC factor or unit). ASC times are on UTC whatever the reading machine's
timezone. Decoding is streamed: frames are decoded as they are read into compact arrays, so
memory grows with the decoded samples only. Time order follows the ``"sort"`` policy of
:mod:`vo_doppler.io.time_order` per message (a frame more than 0.5 s late is an error).
"""

from __future__ import annotations

import calendar
import datetime
import logging
import math
import re
import warnings
from array import array
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import can
import cantools
import numpy as np

from vo_doppler.bounds import (
    FORWARD_ACCELERATION,
    SPEED,
    YAW_RATE,
    SignalBounds,
    too_many_out_of_range,
)
from vo_doppler.choices import checked
from vo_doppler.errors import InputError
from vo_doppler.io.can_report import CanDecodeReport, ShortFrames
from vo_doppler.io.textfile import (
    MAX_LINE_CHARS,
    SMALL_MAX_BYTES,
    binary_kind,
    read_text,
    regular_file,
)
from vo_doppler.io.time_order import order_samples
from vo_doppler.model.series import SensorSeries

log = logging.getLogger(__name__)

# Factor from a DBC unit string (lower case, spaces removed) to the SI unit.
UNIT_TO_SI: dict[str, tuple[float, str]] = {
    "km/h": (1.0 / 3.6, "m/s"),
    "kph": (1.0 / 3.6, "m/s"),
    "kmh": (1.0 / 3.6, "m/s"),
    "m/s": (1.0, "m/s"),
    "mps": (1.0, "m/s"),
    "mph": (0.44704, "m/s"),
    "deg/s": (np.pi / 180.0, "rad/s"),
    "°/s": (np.pi / 180.0, "rad/s"),
    "dps": (np.pi / 180.0, "rad/s"),
    "degree/s": (np.pi / 180.0, "rad/s"),
    "rad/s": (1.0, "rad/s"),
    "m/s^2": (1.0, "m/s^2"),
    "m/s2": (1.0, "m/s^2"),
    "m/s²": (1.0, "m/s^2"),
    "g": (9.80665, "m/s^2"),
}

_LINE_FORMATS = {".log": can.CanutilsLogReader, ".csv": can.CSVReader}


@dataclass
class CanFrames:
    """Raw frames as columns: time (s), arbitration id, payload bytes, bus channel name."""

    t: np.ndarray
    arbitration_id: np.ndarray
    data: list[bytes]
    channel: np.ndarray
    n_unreadable: int = 0
    source: str = "CAN frames"

    def __len__(self) -> int:
        return len(self.t)


@dataclass
class CanMotion:
    """Yaw rate (rad/s, counter-clockwise positive) and speed (m/s) decoded from a CAN log,
    and the longitudinal acceleration (m/s², forward positive) where one was asked for."""

    yaw_rate: SensorSeries | None
    speed: SensorSeries | None
    report: CanDecodeReport
    forward_acceleration: SensorSeries | None = None


class SignalError(InputError):
    """A signal reference that is malformed, not in the DBC or of the wrong kind of unit."""


@dataclass(frozen=True)
class SignalRef:
    """A DBC signal named ``MESSAGE.SIGNAL``."""

    message: str
    signal: str

    @classmethod
    def parse(cls, text: str) -> SignalRef:
        message, dot, signal = text.strip().partition(".")
        if not dot or not message or not signal:
            raise SignalError(f"signal {text!r} is not of the form MESSAGE.SIGNAL")
        return cls(message, signal)

    def __str__(self) -> str:
        return f"{self.message}.{self.signal}"


def parse_signal_list(text: str) -> list[SignalRef]:
    """``"MSG.A,MSG.B"`` → two references."""
    return [SignalRef.parse(part) for part in text.split(",") if part.strip()]


UNIT_NAMES = {"rad/s": "an angular rate", "m/s^2": "m/s²"}
"""How an error names the SI unit a signal should have had."""
MAX_UNREADABLE_LOGGED = 10
"""Unreadable lines logged one by one; the rest are only counted."""
MAX_ARBITRATION_ID = 0x1FFFFFFF


class _TextLines:
    """UTF-8 lines of a binary file handle with their 1-based numbers; over-long lines are
    skipped and counted, a byte that is not UTF-8 is an :class:`InputError` naming the line."""

    def __init__(self, handle, path: Path, report: CanDecodeReport):
        self.handle = handle
        self.path = path
        self.report = report
        self.number = 0
        self.replay: list[str] = []
        """Lines handed out again first (a CSV header for each new reader)."""

    def __iter__(self):
        return self

    def close(self) -> None:
        """python-can closes its file after each pass; the handle stays open for the next."""

    def __next__(self) -> str:
        if self.replay:
            return self.replay.pop()
        while True:
            raw = self.handle.readline(MAX_LINE_CHARS + 2)
            if not raw:
                raise StopIteration
            self.number += 1
            if len(raw) > MAX_LINE_CHARS:
                while raw and not raw.endswith(b"\n"):
                    raw = self.handle.readline(MAX_LINE_CHARS)
                _unreadable(self.report, self.path, self.number, "line too long")
                continue
            try:
                return raw.decode("utf-8")
            except UnicodeDecodeError as exc:
                raise InputError(
                    f"CAN log is not UTF-8 text (byte 0x{raw[exc.start]:02X})",
                    self.path,
                    self.number,
                ) from exc


def _unreadable(report: CanDecodeReport, path: Path, line: int | None, why: object) -> None:
    report.n_unreadable_lines += 1
    if report.n_unreadable_lines <= MAX_UNREADABLE_LOGGED:
        where = f"{path}:{line}" if line is not None else str(path)
        log.warning("%s: unreadable CAN log line skipped (%s)", where, why)


def _line_messages(path: Path, reader_cls, report: CanDecodeReport):
    """Messages of a line-oriented log and their line numbers; after a line the reader rejects,
    a new reader resumes on the following line (each line is read once)."""
    with path.open("rb") as handle:
        kind = binary_kind(handle.read(8192))
        if kind is not None:
            raise InputError(f"CAN log is a {kind}, not a text log", path)
        handle.seek(0)
        lines = _TextLines(handle, path, report)
        header = next(lines, "") if reader_cls is can.CSVReader else None
        while True:
            lines.replay = [] if header is None else [header]
            try:
                for message in reader_cls(lines):
                    yield message, lines.number
                return
            except (ValueError, IndexError, KeyError, TypeError, OverflowError) as exc:
                _unreadable(report, path, lines.number, exc)


class _UtcAscReader(can.ASCReader):
    """python-can's ASC reader with the ``date`` header read as UTC (python-can reads it in the
    reading machine's local timezone, so absolute times moved with ``TZ``)."""

    @staticmethod
    def _datetime_to_timestamp(datetime_string: str) -> float:
        local = can.ASCReader._datetime_to_timestamp(datetime_string)
        wall_clock = datetime.datetime.fromtimestamp(local)
        return calendar.timegm(wall_clock.timetuple()) + wall_clock.microsecond * 1e-6


def _record_messages(path: Path, report: CanDecodeReport):
    """ASC and BLF: python-can cannot resume after a corrupt record, so keep what came first.

    ASC times are made absolute from the ``Begin Triggerblock`` date (as UTC), like BLF times.
    A file python-can cannot open at all is an :class:`InputError`. The file is opened here and
    handed to python-can, so it is closed however the reading ends (python-can's readers leave
    a file they opened open when their header is corrupt or the reading stops early).
    """
    n = 0
    asc = path.suffix.lower() == ".asc"
    if asc:
        with path.open("rb") as handle:
            kind = binary_kind(handle.read(8192))
        if kind is not None:
            raise InputError(f"ASC log is a {kind}, not a text log", path)
    with path.open("r", encoding="utf-8") if asc else path.open("rb") as handle:
        try:
            if asc:
                reader = _UtcAscReader(handle, relative_timestamp=False)
            else:
                reader = can.BLFReader(handle)
            for message in reader:
                n += 1
                yield message, None
        except Exception as exc:  # python-can raises many types on corrupt files
            if n == 0:
                raise InputError(
                    f"cannot read the CAN log: {type(exc).__name__}: {exc}", path
                ) from exc
            log.warning("%s: reading stopped after %d frames: %s", path, n, exc)
            report.n_unreadable_lines += 1
    if n == 0 and asc:
        raise InputError(_not_asc(path), path)


_CANDUMP_LINE = re.compile(r"^\(\s*[-+0-9.eE]+\)\s+\S+\s+[0-9A-Fa-f]+#")
"""A candump ``-l`` line: ``(time) interface id#data``."""


def _not_asc(path: Path) -> str:
    """Why an ``.asc`` file gave no frame: what an ASC frame line is, what the file holds."""
    n_lines, first = 0, ""
    with path.open("rb") as handle:
        for raw in handle:
            n_lines += 1
            if not first and raw.strip():
                first = raw.strip()[:80].decode("utf-8", "replace")
    expected = (
        "no CAN frame in this ASC log: Vector ASC frame lines look like "
        "'0.010000 1 123 Rx d 8 11 22 33 44 55 66 77 88', after a 'date' and a 'base hex "
        f"timestamps absolute' header; none of its {n_lines} lines is one"
    )
    if not first:
        return expected
    kind = ", a candump -l line: name the file .log" if _CANDUMP_LINE.match(first) else ""
    return f"{expected} (its first line: {first!r}{kind})"


def iter_can_frames(path: str | Path, report: CanDecodeReport):
    """``(time, arbitration id, payload, channel, line)`` of every usable data frame of a
    candump ``-l``, ASC, BLF or python-can CSV log, one at a time (``line`` None for ASC/BLF).

    Error and remote frames are dropped; frames with a non-finite time or an id beyond 29 bits
    are counted as unreadable."""
    path = Path(path)
    regular_file(path, "CAN log")
    suffix = path.suffix.lower()
    if suffix in _LINE_FORMATS:
        messages = _line_messages(path, _LINE_FORMATS[suffix], report)
    elif suffix in (".asc", ".blf"):
        messages = _record_messages(path, report)
    else:
        raise InputError(f"unknown CAN log format {suffix!r} (.log, .asc, .blf or .csv)", path)
    for message, line in messages:
        if message.is_error_frame or message.is_remote_frame:
            continue
        if not math.isfinite(message.timestamp):
            _unreadable(report, path, line, f"time {message.timestamp}")
            continue
        if not 0 <= message.arbitration_id <= MAX_ARBITRATION_ID:
            _unreadable(report, path, line, f"id 0x{message.arbitration_id:X} beyond 29 bits")
            continue
        channel = str(message.channel) if message.channel is not None else ""
        yield message.timestamp, message.arbitration_id, bytes(message.data), channel, line


def read_can_log(path: str | Path) -> CanFrames:
    """Read every data frame of a candump ``-l``, ASC, BLF or python-can CSV log."""
    report = CanDecodeReport()
    t, ids, data, channels = array("d"), array("q"), [], []
    for time, frame_id, payload, channel, _ in iter_can_frames(path, report):
        t.append(time)
        ids.append(frame_id)
        data.append(payload)
        channels.append(channel)
    return CanFrames(
        t=np.frombuffer(t, dtype=float).copy(),
        arbitration_id=np.frombuffer(ids, dtype=np.int64).copy(),
        data=data,
        channel=np.array(channels, dtype=str),
        n_unreadable=report.n_unreadable_lines,
        source=str(path),
    )


def frames_from_arrays(t, address, data, channel=None, source: str = "CAN arrays") -> CanFrames:
    """Frames from columns such as comma2k19's ``raw_can`` (``data`` may be numpy ``S8``)."""
    address = np.asarray(address, dtype=np.int64)
    payloads = [bytes(d) for d in np.asarray(data, dtype=object)]
    channels = np.zeros(len(address), dtype=int) if channel is None else np.asarray(channel)
    return CanFrames(
        np.asarray(t, dtype=float), address, payloads, channels.astype(str), source=source
    )


DBC_MAX_LINE_CHARS = 16 * 1024
"""Longest DBC line accepted: cantools' parser takes seconds per megabyte-long line."""


def load_dbc(path: str | Path) -> cantools.database.can.Database:
    """A DBC (or other cantools format, by suffix) read as bounded UTF-8 text; any parser error
    is an :class:`InputError` naming the file."""
    path = Path(path)
    text = read_text(path, "CAN database", SMALL_MAX_BYTES, DBC_MAX_LINE_CHARS)
    formats = {".dbc": "dbc", ".kcd": "kcd", ".sym": "sym", ".arxml": "arxml", ".cdd": "cdd"}
    try:
        with warnings.catch_warnings():
            # Without a known suffix cantools tries every format, its CDD parser among them,
            # which warns that it is deprecated: noise beside our error, nothing the user did.
            warnings.filterwarnings("ignore", category=DeprecationWarning, module=r"cantools\.")
            return cantools.database.load_string(
                text, database_format=formats.get(path.suffix.lower()), strict=False
            )
    except Exception as exc:  # cantools wraps its parsers' errors inconsistently
        raise InputError(
            f"cannot load the CAN database: {type(exc).__name__}: {exc}", path
        ) from exc


def si_factor(unit: str | None, where: str) -> tuple[float, str]:
    """Factor and SI unit for a DBC unit string; unknown units are an input error."""
    key = (unit or "").strip().lower().replace(" ", "")
    if key not in UNIT_TO_SI:
        raise SignalError(f"signal {where} has unit {unit!r}, which has no known SI conversion")
    return UNIT_TO_SI[key]


def _resolve_signals(db, refs: list[SignalRef], report: CanDecodeReport):
    """Per frame id the DBC message and the references in it, and per reference the factor and
    SI unit of its DBC unit; a message or signal the DBC lacks, or a unit without an SI
    conversion, is a :class:`SignalError`."""
    by_message: dict[str, list[SignalRef]] = {}
    for ref in refs:
        by_message.setdefault(ref.message, []).append(ref)
    messages, factors = {}, {}
    for message_name, message_refs in by_message.items():
        try:
            message = db.get_message_by_name(message_name)
        except KeyError as exc:
            raise SignalError(f"message {message_name!r} is not in the DBC") from exc
        for ref in message_refs:
            try:
                signal = message.get_signal_by_name(ref.signal)
            except KeyError as exc:
                raise SignalError(f"signal {ref} is not in the DBC") from exc
            factors[ref] = si_factor(signal.unit, str(ref))
            report.dbc_units[str(ref)] = signal.unit or ""
        messages[message.frame_id] = (message, message_refs)
    return messages, factors


def check_dbc(dbc_path: str | Path, yaw_rate: str, wheel_speed: str) -> None:
    """Load a DBC and check that it defines the yaw-rate signal (``MSG.SIG``, an angular rate)
    and the wheel-speed signals (``MSG.A,MSG.B``, speeds): what decoding a log with it needs,
    checked before the log is read; an :class:`InputError` naming the DBC otherwise."""
    db = load_dbc(dbc_path)
    try:
        expected = {SignalRef.parse(yaw_rate): "rad/s"}
        expected |= {ref: "m/s" for ref in parse_signal_list(wheel_speed)}
        factors = _resolve_signals(db, list(expected), CanDecodeReport())[1]
        wrong = [
            f"{ref} is in {factors[ref][1]}, not {unit}"
            for ref, unit in expected.items()
            if factors[ref][1] != unit
        ]
        if wrong:
            raise SignalError("; ".join(wrong))
    except InputError as exc:
        raise SignalError(str(exc), dbc_path) from exc


class _StreamDecoder:
    """Decodes frames one at a time into compact per-message arrays (time, line, one value per
    referenced signal), counting short, undecodable and foreign-channel frames."""

    def __init__(self, db, refs, channel, report, short_frames, source):
        self.channel = channel
        self.report = report
        self.short_frames = checked(ShortFrames, short_frames, "short_frames")
        self.source = source
        self.first_short: tuple[float, int, int, int] | None = None
        self.undecodable: Counter[int] = Counter(report.undecodable_by_id)
        self.messages, self.factors = _resolve_signals(db, refs, report)
        self.t = {frame_id: array("d") for frame_id in self.messages}
        self.lines = {frame_id: array("q") for frame_id in self.messages}
        self.values = {frame_id: array("d") for frame_id in self.messages}

    def add(self, t: float, frame_id: int, payload: bytes, channel: str, line: int | None):
        if self.channel is not None and channel != self.channel:
            return
        self.report.n_frames += 1
        entry = self.messages.get(frame_id)
        if entry is None:
            return
        message, refs = entry
        if len(payload) < message.length:
            if self.first_short is None:
                self.first_short = (t, frame_id, len(payload), message.length)
            if self.short_frames is ShortFrames.SKIP:
                self.report.n_short_skipped += 1
                return
            payload = payload + bytes(message.length - len(payload))
            self.report.n_padded += 1
        try:
            decoded = message.decode(payload, decode_choices=False)
            sample = [float(decoded[ref.signal]) for ref in refs]
            if not all(map(math.isfinite, sample)):
                # a float signal's NaN or infinity: no measurement (a SensorSeries refuses it)
                raise ValueError("non-finite signal value")
        except (
            cantools.database.errors.DecodeError,
            KeyError,
            ValueError,
            TypeError,
            OverflowError,
        ):
            self.undecodable[frame_id] += 1
            self.report.n_undecodable += 1
            return
        self.report.n_decoded += 1
        self.t[frame_id].append(t)
        self.lines[frame_id].append(-1 if line is None else line)
        self.values[frame_id].extend(sample)

    def finish(self, path: str | Path | None = None) -> dict[SignalRef, SensorSeries]:
        """Per reference, a series in SI units in time order (the ``"sort"`` policy)."""
        out: dict[SignalRef, SensorSeries] = {}
        for frame_id, (message, refs) in self.messages.items():
            t = np.frombuffer(self.t[frame_id], dtype=float)
            lines = np.frombuffer(self.lines[frame_id], dtype=np.int64)
            table = np.frombuffer(self.values[frame_id], dtype=float).reshape(-1, len(refs))
            t, table, order = order_samples(
                t,
                table,
                path,
                f"CAN message {message.name}",
                lines if path is not None and np.all(lines > 0) else None,
                policy="sort",
            )
            self.report.time_order[message.name] = order
            for k, ref in enumerate(refs):
                factor, unit = self.factors[ref]
                out[ref] = SensorSeries(t.copy(), table[:, k] * factor, str(ref), unit)
        self.report.undecodable_by_id = dict(self.undecodable)
        self._log()
        return out

    def _log(self) -> None:
        report = self.report
        if self.first_short is not None:
            t, frame_id, length, expected = self.first_short
            skip = self.short_frames is ShortFrames.SKIP
            log.warning(
                "%s: %d frames shorter than their DBC length %s (first at t = %.6f s: id 0x%X, "
                "%d of %d bytes)%s",
                self.source,
                report.n_short_skipped if skip else report.n_padded,
                "skipped" if skip else "zero-padded",
                t,
                frame_id,
                length,
                expected,
                "; short_frames='pad' if the log drops trailing zero bytes" if skip else "",
            )
        if report.n_undecodable:
            log.warning("CAN decoding: %s", report.summary())


def decode_signals(
    frames: CanFrames,
    db: cantools.database.can.Database,
    refs: list[SignalRef],
    channel: str | None = None,
    report: CanDecodeReport | None = None,
    short_frames: ShortFrames | str = ShortFrames.SKIP,
) -> dict[SignalRef, SensorSeries]:
    """Decode the referenced signals to SI units; one series per reference, sorted by time.

    ``short_frames``: ``"skip"`` (default) or ``"pad"`` frames shorter than the DBC length."""
    report = report if report is not None else CanDecodeReport()
    report.n_unreadable_lines += frames.n_unreadable
    decoder = _StreamDecoder(db, refs, channel, report, short_frames, frames.source)
    for row in range(len(frames)):
        decoder.add(
            frames.t[row],
            int(frames.arbitration_id[row]),
            frames.data[row],
            str(frames.channel[row]),
            None,
        )
    return decoder.finish()


def mean_of_series(series: list[SensorSeries], name: str = "") -> SensorSeries:
    """Mean of several signals on the first one's times (others linearly interpolated)."""
    base = series[0]
    inside = np.ones(len(base), dtype=bool)
    total = base.value.copy()
    for other in series[1:]:
        if other.t.shape == base.t.shape and np.array_equal(other.t, base.t):
            total += other.value
            continue
        if len(other) == 0:
            inside[:] = False
            continue
        inside &= (base.t >= other.t[0]) & (base.t <= other.t[-1])
        total += np.interp(base.t, other.t, other.value)
    return SensorSeries(base.t[inside], total[inside] / len(series), name, base.unit)


def decode_motion(
    frames: CanFrames,
    db: cantools.database.can.Database,
    yaw_rate: SignalRef | None = None,
    wheel_speed: list[SignalRef] | None = None,
    yaw_rate_sign: float = 1.0,
    yaw_rate_offset_s: float = 0.0,
    speed_offset_s: float = 0.0,
    channel: str | None = None,
    short_frames: ShortFrames | str = ShortFrames.SKIP,
) -> CanMotion:
    """Yaw rate and speed from decoded frames, in SI, time-shifted by per-sensor offsets.

    ``yaw_rate_sign`` multiplies the decoded yaw rate so that the result is counter-clockwise
    positive; ``wheel_speed`` signals are averaged (e.g. the two rear wheels).
    """
    _check_sign(yaw_rate_sign)
    wheels = list(wheel_speed or [])
    report = CanDecodeReport()
    decoded = decode_signals(
        frames, db, ([yaw_rate] if yaw_rate else []) + wheels, channel, report, short_frames
    )
    return _motion(
        decoded, report, yaw_rate, wheels, yaw_rate_sign, yaw_rate_offset_s, speed_offset_s
    )


def _check_sign(yaw_rate_sign: float) -> None:
    if yaw_rate_sign not in (1.0, -1.0):
        raise InputError(f"yaw_rate_sign must be +1 or -1, not {yaw_rate_sign!r}")


def _single(decoded, ref, unit, kind, offset_s, sign, name, bounds, report) -> SensorSeries | None:
    """The decoded signal ``ref`` (None if not asked for) in ``unit``, times sign, shifted,
    without isolated samples beyond ``bounds``."""
    if ref is None:
        return None
    raw = decoded[ref]
    if raw.unit != unit:
        raise SignalError(f"{kind} signal {ref} is in {raw.unit}, not {UNIT_NAMES[unit]}")
    series = SensorSeries(raw.t + offset_s, sign * raw.value, name, unit)
    return _within_bounds(series, ref, bounds, report)


def _within_bounds(
    series: SensorSeries, ref: SignalRef, bounds: SignalBounds, report: CanDecodeReport
) -> SensorSeries:
    """``series`` without its samples beyond ``bounds`` when they are isolated (counted in the
    report and logged); when they are more, an :class:`InputError` naming the signal and the
    time of the first one (on GPS time when the offset is applied)."""
    beyond = bounds.outside(series.value)
    n_out = int(beyond.sum())
    if not n_out:
        return series
    first = int(np.flatnonzero(beyond)[0])
    where = (
        f"{n_out} of the {len(series)} samples of {ref} are outside what a vehicle can report, "
        f"{bounds} (the first, {series.value[first]:.4g} {series.unit}, at t = "
        f"{series.t[first]:.6f} s)"
    )
    if too_many_out_of_range(n_out, len(series)):
        raise InputError(f"{where}: check the DBC factor and unit")
    report.out_of_range[str(ref)] = f"CAN {where}: skipped"
    log.warning("CAN decoding: %s: skipped", where)
    keep = ~beyond
    return SensorSeries(series.t[keep], series.value[keep], series.name, series.unit)


def _motion(
    decoded: dict[SignalRef, SensorSeries],
    report: CanDecodeReport,
    yaw_rate: SignalRef | None,
    wheels: list[SignalRef],
    yaw_rate_sign: float,
    yaw_rate_offset_s: float,
    speed_offset_s: float,
    acceleration: SignalRef | None = None,
) -> CanMotion:
    """Yaw rate (signed, shifted), mean wheel speed (shifted) and the longitudinal acceleration
    (shifted as the yaw rate: both come from the same inertial sensor cluster) from decoded
    series."""
    yaw_series = _single(
        decoded,
        yaw_rate,
        "rad/s",
        "yaw-rate",
        yaw_rate_offset_s,
        yaw_rate_sign,
        "yaw_rate_rad_s",
        YAW_RATE,
        report,
    )
    speed_series = None
    if wheels:
        parts = [decoded[ref] for ref in wheels]
        bad = [str(ref) for ref, s in zip(wheels, parts, strict=True) if s.unit != "m/s"]
        if bad:
            raise SignalError(f"wheel-speed signals {bad} are not speeds")
        parts = [
            _within_bounds(part.shifted(speed_offset_s), ref, SPEED, report)
            for ref, part in zip(wheels, parts, strict=True)
        ]
        speed_series = mean_of_series(parts, "speed_mps")
    acceleration_series = _single(
        decoded,
        acceleration,
        "m/s^2",
        "acceleration",
        yaw_rate_offset_s,
        1.0,
        "forward_acceleration_mps2",
        FORWARD_ACCELERATION,
        report,
    )
    return CanMotion(yaw_series, speed_series, report, acceleration_series)


def _require_frames(
    decoded: dict[SignalRef, SensorSeries],
    report: CanDecodeReport,
    channel: str | None,
    path: str | Path,
) -> None:
    """An :class:`InputError` when the log gave no frame at all, or none of a message whose
    signals were asked for (the counts of what was read say why)."""
    on_channel = f" on channel {channel!r}" if channel is not None else ""
    if report.n_frames == 0:
        raise InputError(
            f"no CAN frame could be read from the log{on_channel} ({report.summary()})", path
        )
    empty = sorted({ref.message for ref, series in decoded.items() if not len(series)})
    if empty:
        raise InputError(
            f"no decodable frame of message(s) {', '.join(empty)}{on_channel} in the log "
            f"({report.summary()})",
            path,
        )


def read_can_motion(
    log_path: str | Path,
    dbc_path: str | Path,
    yaw_rate: str | None = None,
    wheel_speed: str | None = None,
    yaw_rate_sign: float = 1.0,
    yaw_rate_offset_s: float = 0.0,
    speed_offset_s: float = 0.0,
    channel: str | None = None,
    short_frames: ShortFrames | str = ShortFrames.SKIP,
    forward_acceleration: str | None = None,
) -> CanMotion:
    """Read a CAN log and decode yaw rate (``MSG.SIG``), mean wheel speed (``MSG.A,MSG.B``) and,
    if named, the longitudinal acceleration (``MSG.SIG``, forward positive, as an accelerometer
    measures it: gravity's share on a slope included), frame by frame (no frame is held beyond
    its decoding)."""
    _check_sign(yaw_rate_sign)
    db = load_dbc(dbc_path)
    report = CanDecodeReport()
    try:
        yaw_ref = SignalRef.parse(yaw_rate) if yaw_rate else None
        wheels = parse_signal_list(wheel_speed) if wheel_speed else []
        acceleration_ref = SignalRef.parse(forward_acceleration) if forward_acceleration else None
        decoder = _StreamDecoder(
            db,
            ([yaw_ref] if yaw_ref else [])
            + wheels
            + ([acceleration_ref] if acceleration_ref else []),
            channel,
            report,
            short_frames,
            str(log_path),
        )
    except SignalError as exc:
        raise SignalError(str(exc), dbc_path) from exc
    for frame in iter_can_frames(log_path, report):
        decoder.add(*frame)
    decoded = decoder.finish(log_path)
    try:
        motion = _motion(
            decoded,
            report,
            yaw_ref,
            wheels,
            yaw_rate_sign,
            yaw_rate_offset_s,
            speed_offset_s,
            acceleration_ref,
        )
    except SignalError as exc:
        raise SignalError(str(exc), dbc_path) from exc
    except InputError as exc:  # beyond a vehicle's range
        raise InputError(str(exc), log_path) from exc
    _require_frames(decoded, report, channel, log_path)
    log.info("%s: %s", log_path, motion.report.summary())
    return motion
