"""Google Smartphone Decimeter Challenge ``device_gnss.csv``: measurements with satellite states.

The file (GSDC 2022/2023 data description) repeats the Android Raw columns (see
:mod:`vo_doppler.io.android_raw`) and adds per row: ``ArrivalTimeNanosSinceGpsEpoch``,
``RawPseudorangeMeters`` (used as the pseudorange, since the CSV writes the 19-digit clock
fields as 15-digit floats), ``SvPosition*EcefMeters``/``SvVelocity*EcefMetersPerSecond`` at the
transmission time in the Earth-fixed frame of that time, ``SvClockBiasMeters``,
``SvClockDriftMetersPerSecond`` and the file's own WLS receiver position per epoch. Pseudoranges
still need the State flags' approval (Android rules); Doppler, C/N0 and carrier as in
``android_raw``. The satellite states come back as a :class:`SatelliteTable` (one row per epoch
and satellite), so no navigation file is needed.
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from vo_doppler.bounds import (
    RECEIVER_RADIUS,
    SATELLITE_CLOCK_BIAS,
    SATELLITE_CLOCK_DRIFT,
    SATELLITE_ORBIT_RADIUS,
    SATELLITE_SPEED,
    SIGNAL_TRAVEL_TIME,
)
from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.io.android import Records, raw_columns, records
from vo_doppler.io.android_raw import numbered, raw_observations, satellite_ids
from vo_doppler.io.textfile import read_text
from vo_doppler.model.observations import Observations
from vo_doppler.model.row_sigma import RowSigma
from vo_doppler.model.satellite_table import SatelliteTable

REQUIRED = (
    "ArrivalTimeNanosSinceGpsEpoch",
    "RawPseudorangeMeters",
    *(f"SvPosition{a}EcefMeters" for a in "XYZ"),
    *(f"SvVelocity{a}EcefMetersPerSecond" for a in "XYZ"),
    "SvClockBiasMeters",
    "SvClockDriftMetersPerSecond",
)
ORBIT_RADIUS_RANGE_M = (SATELLITE_ORBIT_RADIUS.low, SATELLITE_ORBIT_RADIUS.high)


@dataclass(frozen=True)
class GsdcRecording:
    """Observations, receiver-reported σ, satellite states per (epoch, satellite), the file's
    WLS receiver position per observation epoch (NaN where absent), skipped-data messages."""

    observations: Observations
    sigma: RowSigma
    satellites: SatelliteTable
    receiver_ecef: np.ndarray
    problems: tuple[str, ...]
    path: Path


def read_device_gnss(path: str | Path) -> GsdcRecording:
    """Read one ``device_gnss.csv``."""
    path = Path(path)
    rows = _read_csv(path)
    missing = [name for name in REQUIRED if name not in rows.names]
    if missing:
        raise InputError(f"not a GSDC device_gnss.csv: no column {missing[0]}", path, 1)
    problems: list[str] = []
    timed = np.isfinite(rows.numbers("ArrivalTimeNanosSinceGpsEpoch", path))
    if not np.any(timed):
        raise InputError("no row with an ArrivalTimeNanosSinceGpsEpoch", path)
    if not np.all(timed):
        problems.append(f"{path}: {int(np.sum(~timed))} Raw rows without an arrival time dropped")
    rows = rows.subset(timed).usable(("ConstellationType", "Svid"), path, problems)
    number = lambda name: rows.numbers(name, path)  # noqa: E731
    arrival_ns = number("ArrivalTimeNanosSinceGpsEpoch")
    columns = replace(
        raw_columns(rows, path),
        time_nanos=None,
        full_bias_nanos=None,
        received_sv_time_nanos=None,
        arrival_ns=arrival_ns,
        pseudorange_m=number("RawPseudorangeMeters"),
    )
    observations, sigma = raw_observations(columns, "Android (GSDC device_gnss.csv)", problems)
    satellites = _satellite_table(rows, path, arrival_ns, problems)
    wls = np.stack([number(f"WlsPosition{a}EcefMeters") for a in "XYZ"], axis=1)
    radius = np.linalg.norm(wls, axis=1)
    off = np.isfinite(radius) & RECEIVER_RADIUS.outside(radius)
    if np.any(off):
        raise InputError(
            "WLS receiver position off the Earth's surface", path, int(rows.line[off][0])
        )
    epoch = np.searchsorted(observations.epoch_time, arrival_ns * 1e-9)
    receiver = np.full((observations.epoch_time.size, 3), np.nan)
    good = np.isfinite(wls).all(axis=1) & (epoch < receiver.shape[0])
    receiver[epoch[good]] = wls[good]
    return GsdcRecording(observations, sigma, satellites, receiver, tuple(problems), path)


def _read_csv(path: Path) -> Records:
    text = read_text(path, "GSDC device_gnss.csv")
    try:
        table = list(csv.reader(io.StringIO(text, newline="")))
    except csv.Error as exc:
        raise InputError(f"cannot read CSV: {exc}", path) from exc
    if not table:
        raise InputError("empty file", path)
    names = tuple(name.strip() for name in table[0][1:])
    body, lines = [], []
    for number, row in enumerate(table[1:], start=2):
        if not row or row[0] != "Raw":
            continue
        if len(row) - 1 != len(names):
            raise InputError(f"{len(row) - 1} fields for {len(names)} columns", path, number)
        body.append(row[1:])
        lines.append(number)
    if not body:
        raise InputError("no Raw rows", path)
    return records(names, body, lines, path)


def _satellite_table(
    rows: Records, path: Path, arrival_ns: np.ndarray, problems: list[str]
) -> SatelliteTable:
    """One row per (epoch, satellite), validated: finite states; a radius off any GNSS orbit is
    an :class:`InputError` naming the line; rows with a satellite speed, clock bias or drift,
    signal travel time or satellite number no GNSS satellite has (bounds of
    :mod:`vo_doppler.bounds`) are dropped and counted in ``problems``."""
    number = lambda name: rows.numbers(name, path)  # noqa: E731
    position = np.stack([number(f"SvPosition{a}EcefMeters") for a in "XYZ"], axis=1)
    velocity = np.stack([number(f"SvVelocity{a}EcefMetersPerSecond") for a in "XYZ"], axis=1)
    bias = number("SvClockBiasMeters") / SPEED_OF_LIGHT
    drift = number("SvClockDriftMetersPerSecond") / SPEED_OF_LIGHT
    travel = number("RawPseudorangeMeters") / SPEED_OF_LIGHT
    ok = np.isfinite(position).all(axis=1) & np.isfinite(velocity).all(axis=1)
    ok &= np.isfinite(bias) & np.isfinite(drift) & np.isfinite(travel)
    radius = np.linalg.norm(np.nan_to_num(position), axis=1)
    low, high = ORBIT_RADIUS_RANGE_M
    wrong = ok & ((radius < low) | (radius > high))
    if np.any(wrong):
        raise InputError("satellite position off any GNSS orbit", path, int(rows.line[wrong][0]))
    system, prn = satellite_ids(number("ConstellationType"), number("Svid"))
    possible = ~SATELLITE_SPEED.outside(np.linalg.norm(velocity, axis=1))
    possible &= ~SATELLITE_CLOCK_BIAS.outside(bias) & ~SATELLITE_CLOCK_DRIFT.outside(drift)
    possible &= ~SIGNAL_TRAVEL_TIME.outside(travel) & numbered(system, prn)
    impossible = ok & ~possible
    if np.any(impossible):
        problems.append(
            f"{path}: {int(impossible.sum())} satellite states with a speed, clock, signal travel "
            f"time or satellite number no GNSS satellite has dropped (first: line "
            f"{int(rows.line[impossible][0])})"
        )
    ok &= possible
    t = arrival_ns * 1e-9
    key = np.char.add(np.char.add(t.astype(str), system), prn.astype(str))
    _, first = np.unique(key, return_index=True)
    keep = np.sort(first[ok[first] & (system[first] != "")])
    return SatelliteTable(
        t[keep],
        system[keep],
        prn[keep].astype(np.int16),
        position[keep],
        velocity[keep],
        bias[keep],
        drift[keep],
        travel[keep],
    )
