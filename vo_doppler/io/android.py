"""Android GnssLogger logs: ``Raw`` rows → observations, gyro rows → yaw rate on GPS time.

File layout (GnssLogger app, Google): ``#``-comment lines, among them one header per record
type (``# Raw,utcTimeMillis,TimeNanos,…``), then data lines whose first field names the record
type. Columns are found by their header names, so logs of different app versions read alike.
Raw rows go through :mod:`vo_doppler.io.android_raw` (clock rules, Doppler sign).

Gyro: ``UncalGyro`` rows (rates with the bias still in, which the heading stage calibrates) or,
without them, ``Gyro`` rows. Their ``elapsedRealtimeNanos`` (Android boot clock) is put on GPS
time with the Raw rows' ``ChipsetElapsedRealtimeNanos`` (the same clock, same instant as the
GNSS epoch): offset = median(t_GPS − elapsed) over the epochs; logs without that column use the
rows' ``utcTimeMillis`` plus the leap seconds (1 ms resolution).

Yaw rate ψ̇ = u·ω, with u the phone-frame unit vector of the vehicle's up axis:
- given a mounting rotation R (phone → vehicle, vehicle z up): u = third row of R;
- estimated (``mounting_method`` says which): the principal axis of the angular-rate
  covariance when it dominates (largest eigenvalue ≥ 3× the next: while driving, turns about
  the vertical dominate roll and pitch rates), its sign taken along the mean accelerometer
  reading (the reaction to gravity points up); otherwise the mean accelerometer direction
  itself. A log without accelerometer rows needs the mounting rotation.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.io.android_raw import RawColumns, raw_observations
from vo_doppler.io.textfile import read_text
from vo_doppler.model.gpstime import unix_to_gps_seconds
from vo_doppler.model.observations import Observations
from vo_doppler.model.row_sigma import RowSigma
from vo_doppler.model.series import SensorSeries

DOMINANCE_RATIO = 3.0
RAW_INTEGERS = ("ConstellationType", "Svid", "TimeNanos", "FullBiasNanos", "ReceivedSvTimeNanos")
GYRO_RECORDS = ("UncalGyro", "Gyro")
ACCEL_RECORDS = ("UncalAccel", "Accel")
USED_RECORDS = ("Raw", *GYRO_RECORDS, *ACCEL_RECORDS)
MAX_FIELD_CHARS = 64


@dataclass(frozen=True)
class AndroidLog:
    """A GnssLogger file: observations, receiver-reported σ, yaw rate (None without gyro rows),
    the up axis used (phone frame) and how it was found, skipped-data messages."""

    observations: Observations
    sigma: RowSigma
    yaw_rate: SensorSeries | None
    up_axis: np.ndarray | None
    mounting_method: str
    problems: tuple[str, ...]
    path: Path


@dataclass(frozen=True)
class Records:
    """Data lines of one record type: field texts (rows × columns) by header name."""

    names: tuple[str, ...]
    fields: np.ndarray
    line: np.ndarray

    def subset(self, rows: np.ndarray) -> Records:
        return Records(self.names, self.fields[rows], self.line[rows])

    def text(self, name: str) -> np.ndarray:
        if name not in self.names:
            return np.full(len(self.line), "", dtype="U1")
        return self.fields[:, self.names.index(name)]

    def numbers(self, name: str, path: Path) -> np.ndarray:
        """A column as floats (NaN where blank); a non-number names its line."""
        text = self.text(name)
        out = np.full(text.shape, np.nan)
        filled = np.char.str_len(np.char.strip(text)) > 0
        try:
            out[filled] = text[filled].astype(float)
        except ValueError:
            for k in np.flatnonzero(filled):
                try:
                    out[k] = float(text[k])
                except ValueError:
                    raise InputError(
                        f"{name} is not a number: {text[k]!r}", path, int(self.line[k])
                    ) from None
        return out

    def integers(self, name: str, path: Path) -> np.ndarray | None:
        """A column as exact int64, or None when any row lacks it or is not an integer."""
        text = np.char.strip(self.text(name))
        if not np.all(self.is_integer(name)):
            return None
        return np.array([int(v) for v in text], dtype=np.int64)

    def is_integer(self, name: str) -> np.ndarray:
        """Rows whose field is a decimal integer that fits in int64."""
        return np.array([_fits_int64(str(v)) for v in self.text(name)], dtype=bool)

    def usable(self, names: tuple[str, ...], path: Path, problems: list[str]) -> Records:
        """The rows whose given fields are all integers; the others are counted and dropped."""
        keep = np.ones(len(self.line), dtype=bool)
        for name in names:
            keep &= self.is_integer(name)
        if not np.any(keep):
            raise InputError(f"no Raw row with integer {', '.join(names)}", path)
        if not np.all(keep):
            problems.append(
                f"{path}: {int(np.sum(~keep))} Raw rows without integer {', '.join(names)}"
            )
        return self.subset(keep)


def _fits_int64(text: str) -> bool:
    try:
        value = int(text)
    except ValueError:
        return False
    return -(2**63) <= value < 2**63


def read_gnsslogger(path: str | Path, mounting: np.ndarray | None = None) -> AndroidLog:
    """Read a GnssLogger text log; ``mounting`` is the 3×3 phone → vehicle rotation if known."""
    path = Path(path)
    records = read_records(path)
    if "Raw" not in records:
        raise InputError("no Raw records (GnssMeasurement rows) in the log", path)
    problems: list[str] = []
    raw = records["Raw"].usable(RAW_INTEGERS, path, problems)
    observations, sigma = raw_observations(raw_columns(raw, path), "Android GnssLogger", problems)
    gyro_kind = next((k for k in GYRO_RECORDS if k in records), None)
    if gyro_kind is None:
        return AndroidLog(observations, sigma, None, None, "none", tuple(problems), path)
    gyro = records[gyro_kind]
    t = sensor_gps_time(gyro, raw, path)
    omega = np.stack([gyro.numbers(f"{gyro_kind}{a}RadPerSec", path) for a in "XYZ"], axis=1)
    _check_sensor(path, gyro, t, omega)
    accel = _accelerometer(records, path)
    up, method = up_axis(omega, accel, mounting, path)
    yaw_rate = SensorSeries(t, omega @ up, "yaw_rate", "rad/s")
    return AndroidLog(observations, sigma, yaw_rate, up, method, tuple(problems), path)


def read_records(path: Path) -> dict[str, Records]:
    """The record types this reader uses (``USED_RECORDS``), columns named by their ``#`` header
    lines. Other record types (``Nav`` rows carry a variable number of data bytes, ``Fix``,
    ``Status`` …) need a header line but are not parsed further."""
    text = read_text(path, "GnssLogger file")
    headers: dict[str, tuple[str, ...]] = {}
    rows: dict[str, list[list[str]]] = {}
    lines: dict[str, list[int]] = {}
    for number, line in enumerate(text.splitlines(), start=1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            parts = [p.strip() for p in stripped.lstrip("#").split(",")]
            if len(parts) > 2 and parts[0].isidentifier():
                headers[parts[0]] = tuple(parts[1:])
            continue
        parts = stripped.split(",")
        kind = parts[0]
        if kind not in headers:
            raise InputError(f"record type {kind[:20]!r} without a header line", path, number)
        if kind not in USED_RECORDS:
            continue
        if len(parts) - 1 > len(headers[kind]):
            raise InputError(
                f"{len(parts) - 1} fields for {len(headers[kind])} {kind} columns", path, number
            )
        rows.setdefault(kind, []).append(parts[1:] + [""] * (len(headers[kind]) + 1 - len(parts)))
        lines.setdefault(kind, []).append(number)
    return {kind: records(headers[kind], rows[kind], lines[kind], path) for kind in rows}


def records(names: tuple[str, ...], rows: list[list[str]], lines: list[int], path: Path) -> Records:
    """The rows as a :class:`Records` table; a field longer than ``MAX_FIELD_CHARS`` names its
    line (the table's string width is its longest field, times every row and column)."""
    for row, number in zip(rows, lines, strict=True):
        longest = max(row, key=len, default="")
        if len(longest) > MAX_FIELD_CHARS:
            raise InputError(
                f"a field of {len(longest)} characters (at most {MAX_FIELD_CHARS})", path, number
            )
    return Records(names, np.array(rows, dtype=str), np.array(lines))


def raw_columns(raw: Records, path: Path) -> RawColumns:
    """The Raw fields the clock rules need, typed."""
    number = lambda name: raw.numbers(name, path)  # noqa: E731
    return RawColumns(
        path=path,
        line=raw.line,
        constellation=number("ConstellationType"),
        svid=number("Svid"),
        state=np.nan_to_num(number("State")),
        time_nanos=raw.integers("TimeNanos", path),
        full_bias_nanos=raw.integers("FullBiasNanos", path),
        bias_nanos=np.nan_to_num(number("BiasNanos")),
        time_offset_nanos=np.nan_to_num(number("TimeOffsetNanos")),
        received_sv_time_nanos=raw.integers("ReceivedSvTimeNanos", path),
        received_sv_time_uncertainty_nanos=number("ReceivedSvTimeUncertaintyNanos"),
        cn0=number("Cn0DbHz"),
        prr=number("PseudorangeRateMetersPerSecond"),
        prr_uncertainty=np.nan_to_num(
            number("PseudorangeRateUncertaintyMetersPerSecond"), nan=np.inf
        ),
        adr_state=np.nan_to_num(number("AccumulatedDeltaRangeState")),
        adr=number("AccumulatedDeltaRangeMeters"),
        frequency=_frequency(raw, path),
        code_type=np.char.strip(raw.text("CodeType")),
        leap_second=number("LeapSecond"),
        clock_discontinuity=number("HardwareClockDiscontinuityCount"),
    )


def _frequency(raw: Records, path: Path) -> np.ndarray:
    """CarrierFrequencyHz; logs from before dual-frequency phones lack it: GPS-like L1 assumed."""
    frequency = raw.numbers("CarrierFrequencyHz", path)
    missing = ~np.isfinite(frequency) & (raw.numbers("ConstellationType", path) != 3)
    frequency[missing] = 1575.42e6
    return frequency


def sensor_gps_time(sensor: Records, raw: Records, path: Path) -> np.ndarray:
    """GPS seconds of sensor rows (module docstring: boot clock tied to the GNSS epochs)."""
    elapsed = sensor.numbers("elapsedRealtimeNanos", path)
    chipset = raw.numbers("ChipsetElapsedRealtimeNanos", path)
    time_nanos = raw.integers("TimeNanos", path)
    full_bias = raw.integers("FullBiasNanos", path)
    tied = np.isfinite(chipset) & (chipset > 0)
    if np.any(tied) and time_nanos is not None and full_bias is not None:
        gps_ns = (time_nanos - full_bias)[tied] - np.nan_to_num(raw.numbers("BiasNanos", path))[
            tied
        ]
        offset = np.median(gps_ns.astype(float) - chipset[tied])
        return (elapsed + offset) * 1e-9
    return unix_to_gps_seconds(sensor.numbers("utcTimeMillis", path) * 1e-3)


def _check_sensor(path: Path, rows: Records, t: np.ndarray, values: np.ndarray) -> None:
    bad = ~np.isfinite(t) | ~np.isfinite(values).all(axis=1)
    if np.any(bad):
        raise InputError(
            "sensor row with a missing or non-finite value", path, int(rows.line[bad][0])
        )
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        raise InputError(
            "sensor row not after the one before it (an earlier or repeated time)",
            path,
            int(rows.line[back[0] + 1]),
        )


def _accelerometer(records: dict[str, Records], path: Path) -> np.ndarray | None:
    kind = next((k for k in ACCEL_RECORDS if k in records), None)
    if kind is None:
        return None
    rows = records[kind]
    values = np.stack([rows.numbers(f"{kind}{a}Mps2", path) for a in "XYZ"], axis=1)
    return values[np.isfinite(values).all(axis=1)]


def up_axis(
    omega: np.ndarray, accel: np.ndarray | None, mounting: np.ndarray | None, path: Path
) -> tuple[np.ndarray, str]:
    """Phone-frame unit vector of the vehicle's up axis and the method (module docstring)."""
    if mounting is not None:
        rotation = np.asarray(mounting, dtype=float)
        if rotation.shape != (3, 3) or not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-6):
            raise InputError("mounting must be a 3×3 rotation matrix (phone → vehicle)", path)
        return rotation[2].copy(), "given"
    if accel is None or len(accel) == 0:
        raise InputError(
            "no accelerometer rows to orient the gyro: give the mounting rotation", path
        )
    gravity = np.mean(accel, axis=0)
    gravity /= np.linalg.norm(gravity)
    values, vectors = (
        np.linalg.eigh(np.cov(omega.T)) if len(omega) > 3 else (np.zeros(3), np.eye(3))
    )
    if values[2] >= DOMINANCE_RATIO * values[1] and values[2] > 0:
        axis = vectors[:, 2]
        return axis * np.sign(axis @ gravity), "largest angular-rate variance, sign from gravity"
    return gravity, "mean accelerometer direction"
