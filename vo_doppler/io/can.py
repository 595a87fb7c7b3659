"""CAN bus logs → vehicle yaw rate and speed, decoded with a DBC.

Log formats are read by python-can (candump ``-l`` ``.log``, Vector ``.asc`` and ``.blf``,
python-can ``.csv``); signals are decoded by cantools. A signal is named ``MESSAGE.SIGNAL``;
several wheel-speed signals are averaged. Values are converted from the DBC unit to SI
(km/h → m/s, deg/s → rad/s). The yaw rate leaves this module counter-clockwise positive
(docs/design.md): ``yaw_rate_sign=-1`` flips a bus that reports clockwise-positive yaw rate.

Frames shorter than their DBC length are skipped, counted and named in a warning (their
missing bytes would decode as made-up values); ``short_frames="pad"`` zero-pads them instead,
for sources known to drop trailing zero bytes (comma2k19's ``raw_can`` arrays). Frames that
cannot be decoded, and log lines that cannot be read, are counted, logged and skipped — the
result keeps every frame that could be decoded.
"""

from __future__ import annotations

import io
import logging
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import can
import cantools
import numpy as np

from vo_doppler.errors import InputError
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
class CanDecodeReport:
    """What happened to the frames: used, short (skipped or zero-padded), undecodable (by id),
    ignored."""

    n_frames: int = 0
    n_decoded: int = 0
    n_short_skipped: int = 0
    n_padded: int = 0
    n_undecodable: int = 0
    n_unreadable_lines: int = 0
    undecodable_by_id: dict[int, int] = field(default_factory=dict)

    def summary(self) -> str:
        ids = ", ".join(f"0x{k:X}×{v}" for k, v in sorted(self.undecodable_by_id.items()))
        return (
            f"{self.n_frames} frames, {self.n_decoded} decoded, "
            f"{self.n_short_skipped} short skipped, {self.n_padded} short zero-padded, "
            f"{self.n_undecodable} undecodable{f' ({ids})' if ids else ''}, "
            f"{self.n_unreadable_lines} unreadable log lines"
        )


@dataclass
class CanMotion:
    """Yaw rate (rad/s, counter-clockwise positive) and speed (m/s) decoded from a CAN log."""

    yaw_rate: SensorSeries | None
    speed: SensorSeries | None
    report: CanDecodeReport


@dataclass(frozen=True)
class SignalRef:
    """A DBC signal named ``MESSAGE.SIGNAL``."""

    message: str
    signal: str

    @classmethod
    def parse(cls, text: str) -> SignalRef:
        message, dot, signal = text.strip().partition(".")
        if not dot or not message or not signal:
            raise InputError(f"signal {text!r} is not of the form MESSAGE.SIGNAL")
        return cls(message, signal)

    def __str__(self) -> str:
        return f"{self.message}.{self.signal}"


def parse_signal_list(text: str) -> list[SignalRef]:
    """``"MSG.A,MSG.B"`` → two references."""
    return [SignalRef.parse(part) for part in text.split(",") if part.strip()]


def _iterate_line_format(path: Path, reader_cls) -> tuple[list[can.Message], int]:
    """Read a line-oriented log, skipping (and counting) lines the reader rejects."""
    text = path.read_text(errors="replace")
    header = ""
    if reader_cls is can.CSVReader:
        first_newline = text.find("\n") + 1
        header, text = text[:first_newline], text[first_newline:]
    messages: list[can.Message] = []
    unreadable = 0
    position = 0
    while position < len(text):
        stream = io.StringIO(header + text[position:])
        reader = reader_cls(stream)
        try:
            messages.extend(reader)
            break
        except (ValueError, IndexError, KeyError, TypeError) as exc:
            resumed_at = stream.tell() - len(header)
            bad_line = text.count("\n", 0, position + resumed_at)
            log.warning("%s:%d: unreadable CAN log line skipped (%s)", path, bad_line, exc)
            unreadable += 1
            position += max(resumed_at, 1)
    return messages, unreadable


def _iterate_binary_or_asc(path: Path) -> tuple[list[can.Message], int]:
    """ASC and BLF: python-can cannot resume after a corrupt record, so keep what came first.

    ASC times are made absolute from the ``Begin Triggerblock`` date, like BLF times.
    """
    messages: list[can.Message] = []
    reader = (
        can.ASCReader(path, relative_timestamp=False)
        if path.suffix.lower() == ".asc"
        else can.BLFReader(path)
    )
    try:
        for message in reader:
            messages.append(message)
    except Exception as exc:  # python-can raises many types on corrupt files
        log.warning("%s: reading stopped after %d frames: %s", path, len(messages), exc)
        return messages, 1
    return messages, 0


def read_can_log(path: str | Path) -> CanFrames:
    """Read every data frame of a candump ``-l``, ASC, BLF or python-can CSV log."""
    path = Path(path)
    if not path.is_file():
        raise InputError("CAN log not found", path)
    suffix = path.suffix.lower()
    if suffix in _LINE_FORMATS:
        messages, unreadable = _iterate_line_format(path, _LINE_FORMATS[suffix])
    elif suffix in (".asc", ".blf"):
        messages, unreadable = _iterate_binary_or_asc(path)
    else:
        raise InputError(f"unknown CAN log format {suffix!r} (.log, .asc, .blf or .csv)", path)
    frames = [m for m in messages if not (m.is_error_frame or m.is_remote_frame)]
    return CanFrames(
        t=np.array([m.timestamp for m in frames], dtype=float),
        arbitration_id=np.array([m.arbitration_id for m in frames], dtype=np.int64),
        data=[bytes(m.data) for m in frames],
        channel=np.array([str(m.channel) if m.channel is not None else "" for m in frames]),
        n_unreadable=unreadable,
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


def load_dbc(path: str | Path) -> cantools.database.can.Database:
    path = Path(path)
    try:
        return cantools.database.load_file(str(path), strict=False)
    except (OSError, cantools.database.UnsupportedDatabaseFormatError) as exc:
        raise InputError(f"cannot load DBC: {exc}", path) from exc


def si_factor(unit: str | None, where: str) -> tuple[float, str]:
    """Factor and SI unit for a DBC unit string; unknown units are an input error."""
    key = (unit or "").strip().lower().replace(" ", "")
    if key not in UNIT_TO_SI:
        raise InputError(f"signal {where} has unit {unit!r}, which has no known SI conversion")
    return UNIT_TO_SI[key]


def decode_signals(
    frames: CanFrames,
    db: cantools.database.can.Database,
    refs: list[SignalRef],
    channel: str | None = None,
    report: CanDecodeReport | None = None,
    short_frames: str = "skip",
) -> dict[SignalRef, SensorSeries]:
    """Decode the referenced signals to SI units; one series per reference, sorted by time.

    ``short_frames``: ``"skip"`` (default) or ``"pad"`` frames shorter than the DBC length."""
    if short_frames not in ("skip", "pad"):
        raise ValueError(f"short_frames must be 'skip' or 'pad', not {short_frames!r}")
    report = report if report is not None else CanDecodeReport()
    first_short: tuple[float, int, int, int] | None = None
    by_message: dict[str, list[SignalRef]] = {}
    for ref in refs:
        by_message.setdefault(ref.message, []).append(ref)
    selected = np.ones(len(frames), dtype=bool)
    if channel is not None:
        selected &= frames.channel == channel
    report.n_frames += int(selected.sum())
    report.n_unreadable_lines += frames.n_unreadable
    undecodable: Counter[int] = Counter(report.undecodable_by_id)
    out: dict[SignalRef, SensorSeries] = {}
    for message_name, message_refs in by_message.items():
        try:
            message = db.get_message_by_name(message_name)
        except KeyError as exc:
            raise InputError(f"message {message_name!r} is not in the DBC") from exc
        factors = {}
        for ref in message_refs:
            try:
                signal = message.get_signal_by_name(ref.signal)
            except KeyError as exc:
                raise InputError(f"signal {ref} is not in the DBC") from exc
            factors[ref] = si_factor(signal.unit, str(ref))
        rows = np.flatnonzero(selected & (frames.arbitration_id == message.frame_id))
        times: list[float] = []
        values: list[list[float]] = []
        for row in rows:
            payload = frames.data[row]
            if len(payload) < message.length:
                if first_short is None:
                    first_short = (frames.t[row], message.frame_id, len(payload), message.length)
                if short_frames == "skip":
                    report.n_short_skipped += 1
                    continue
                payload = payload + bytes(message.length - len(payload))
                report.n_padded += 1
            try:
                decoded = message.decode(payload, decode_choices=False)
                sample = [float(decoded[ref.signal]) for ref in message_refs]
            except (cantools.database.errors.DecodeError, KeyError, ValueError, TypeError):
                undecodable[message.frame_id] += 1
                report.n_undecodable += 1
                continue
            times.append(frames.t[row])
            values.append(sample)
        report.n_decoded += len(times)
        order = np.argsort(times, kind="stable")
        table = np.asarray(values, dtype=float).reshape(-1, len(message_refs))[order]
        for k, ref in enumerate(message_refs):
            factor, unit = factors[ref]
            out[ref] = SensorSeries(np.asarray(times)[order], table[:, k] * factor, str(ref), unit)
    report.undecodable_by_id = dict(undecodable)
    if first_short is not None:
        t, frame_id, length, expected = first_short
        action = "skipped" if short_frames == "skip" else "zero-padded"
        log.warning(
            "%s: %d frames shorter than their DBC length %s (first at t = %.6f s: id 0x%X, "
            "%d of %d bytes)%s",
            frames.source,
            report.n_short_skipped if short_frames == "skip" else report.n_padded,
            action,
            t,
            frame_id,
            length,
            expected,
            "; short_frames='pad' if the log drops trailing zero bytes"
            if short_frames == "skip"
            else "",
        )
    if report.n_undecodable:
        log.warning("CAN decoding: %s", report.summary())
    return out


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
    short_frames: str = "skip",
) -> CanMotion:
    """Yaw rate and speed from decoded frames, in SI, time-shifted by per-sensor offsets.

    ``yaw_rate_sign`` multiplies the decoded yaw rate so that the result is counter-clockwise
    positive; ``wheel_speed`` signals are averaged (e.g. the two rear wheels).
    """
    if yaw_rate_sign not in (1.0, -1.0):
        raise ValueError("yaw_rate_sign must be +1 or -1")
    wheels = list(wheel_speed or [])
    refs = ([yaw_rate] if yaw_rate else []) + wheels
    report = CanDecodeReport()
    decoded = decode_signals(frames, db, refs, channel, report, short_frames)
    yaw_series = None
    if yaw_rate is not None:
        raw = decoded[yaw_rate]
        if raw.unit != "rad/s":
            raise InputError(f"yaw-rate signal {yaw_rate} is in {raw.unit}, not an angular rate")
        yaw_series = SensorSeries(
            raw.t + yaw_rate_offset_s, yaw_rate_sign * raw.value, "yaw_rate_rad_s", "rad/s"
        )
    speed_series = None
    if wheels:
        parts = [decoded[ref] for ref in wheels]
        bad = [str(ref) for ref, s in zip(wheels, parts, strict=True) if s.unit != "m/s"]
        if bad:
            raise InputError(f"wheel-speed signals {bad} are not speeds")
        speed_series = mean_of_series(parts, "speed_mps").shifted(speed_offset_s)
    return CanMotion(yaw_series, speed_series, report)


def read_can_motion(
    log_path: str | Path,
    dbc_path: str | Path,
    yaw_rate: str | None = None,
    wheel_speed: str | None = None,
    yaw_rate_sign: float = 1.0,
    yaw_rate_offset_s: float = 0.0,
    speed_offset_s: float = 0.0,
    channel: str | None = None,
    short_frames: str = "skip",
) -> CanMotion:
    """Read a CAN log and decode yaw rate (``MSG.SIG``) and mean wheel speed (``MSG.A,MSG.B``)."""
    frames = read_can_log(log_path)
    db = load_dbc(dbc_path)
    motion = decode_motion(
        frames,
        db,
        SignalRef.parse(yaw_rate) if yaw_rate else None,
        parse_signal_list(wheel_speed) if wheel_speed else None,
        yaw_rate_sign,
        yaw_rate_offset_s,
        speed_offset_s,
        channel,
        short_frames,
    )
    log.info("%s: %s", log_path, motion.report.summary())
    return motion
