"""TU Chemnitz smartLoc raw CSV files (``*_raw.csv``): raw u-blox measurements with ground truth.

A smartLoc raw file (Reisdorf et al., "The problem of comparable GNSS results – an approach for a
uniform dataset with low-cost and reference data", VEHITS 2016) is ``;``-separated UTF-8 text
with one header line naming the columns. Every data row holds one raw u-blox RXM-RAWX
measurement of one satellite and, repeated on every row of its epoch, the reference
trajectory's state at that epoch:

- ground truth: ``GPSWeek``, ``GPSSecondsOfWeek``, longitude and latitude (degrees, WGS 84),
  height above the ellipsoid (m), heading (rad, 0 = east, counter-clockwise: the ENU yaw),
  acceleration (m/s²), velocity (m/s) and yaw rate (rad/s), each followed by a ``Cov`` column
  (its variance; not read);
- the measurement: ``rcvTow`` (s) and ``week`` (the receiver's epoch, as in a UBX log),
  ``leapS``, ``numMeas``, ``recStat``, ``prMes`` (m), ``cpMes`` (cycles), ``doMes`` (Hz,
  positive for an approaching satellite: the RINEX sign), ``gnssId`` as a name (``GPS``,
  ``SBAS``, ``Galileo``, ``BeiDou``, ``IMES``, ``QZSS``, ``Glonass``), ``svId``, ``freqId``
  (GLONASS only: channel k = freqId − 7), ``locktime`` (ms), ``cno`` (dB-Hz), ``prStdev`` (m),
  ``cpStdev`` (cycles), ``doStdev`` (Hz), ``trkStat`` (bit 0 pseudorange valid, bit 1 carrier
  valid) and the NLOS label: ``0`` line of sight, ``1`` NLOS, ``#`` no information.

Columns are found by the identifier in their header name (``(prMes)``, ``(GT Lat)``,
``GPSWeek`` …), so their order does not matter; a missing one is an error naming it.

:func:`read_smartloc` gives :class:`Observations` (one epoch per receiver time tag; the
u-blox M8 measures one signal per satellite: GPS/QZSS/SBAS/Galileo L1 → ``C1C L1C D1C S1C``,
GLONASS L1 → the same codes with the channel in the header, BeiDou B1I → ``C2I L2I D2I S2I``).
Every row of the file is a measurement: pseudorange only when ``trkStat`` says valid, carrier
likewise. Their ``row_fields`` keep, per observation row: ``nlos`` (1 NLOS, 0 line of sight,
−1 no information: the label of the measurement the row came from), ``sigma`` (the receiver's
σ in the row's unit: m, cycles, Hz; NaN for C/N0), and for the Doppler rows (NaN on the others)
``wavelength_m`` λ, ``range_rate_mps`` = −λ·D and ``range_rate_sigma_mps`` = λ·σ_D, λ the
signal's wavelength
(:func:`vo_doppler.gnss.signals.carrier_frequency`; a GLONASS signal's by its channel). The
ground truth comes as a :class:`SmartLocTruth`, one state per epoch.

Every value is checked: a field that is not a number, outside what the format can hold (a GPS
week beyond 4095, a second of week beyond 604,800, a GLONASS freqId beyond 0–13) or beyond the
bounds of :mod:`vo_doppler.bounds` (latitude, longitude, height, speed, yaw rate,
acceleration, C/N0, a σ not within 1e-9 … 1e7), or an epoch whose rows disagree
on the ground truth is an :class:`InputError` naming the file, line and column; epochs must
not go back in time. A pseudorange, carrier phase or Doppler beyond the u-blox ranges of
:data:`vo_doppler.io.ubx.VALUE_RANGES` is dropped and counted in ``problems``, as the UBX
reader does; so is an IMES row (not a satellite) or a GLONASS row without a known slot
(svId 255).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vo_doppler.bounds import (
    CN0,
    FORWARD_ACCELERATION,
    HEIGHT,
    LATITUDE_DEG,
    LONGITUDE_DEG,
    MEASUREMENT_SIGMA,
    SPEED,
    YAW_RATE,
    SignalBounds,
)
from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.io.obs_rows import observations_from_rows
from vo_doppler.io.rinex_common import PRN_RANGE
from vo_doppler.io.textfile import read_text
from vo_doppler.io.ubx import VALUE_RANGES
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.gpstime import SECONDS_PER_WEEK
from vo_doppler.model.observations import Observations
from vo_doppler.model.signals import carrier_frequency

SEPARATOR = ";"
LAST_WEEK = 4095
COLUMNS: dict[str, str] = {
    # name used here → identifier found in the header name of the column
    "gt_week": "GPSWeek",
    "gt_tow": "GPSSecondsOfWeek",
    "lon": "(GT Lon)",
    "lat": "(GT Lat)",
    "height": "(GT Height)",
    "heading": "(GT Heading)",
    "acceleration": "(GT Acceleration)",
    "speed": "(GT Velocity)",
    "yaw_rate": "(GT Yaw-rate)",
    "tow": "(rcvTow)",
    "week": "(week)",
    "pseudorange": "(prMes)",
    "carrier": "(cpMes)",
    "doppler": "(doMes)",
    "gnss": "(gnssId)",
    "sv": "(svId)",
    "freq": "(freqId)",
    "cn0": "(cno)",
    "pseudorange_sigma": "(prStdev)",
    "carrier_sigma": "(cpStdev)",
    "doppler_sigma": "(doStdev)",
    "tracking": "(trkStat)",
    "nlos": "NLOS",
}
SYSTEMS = {
    "GPS": "G",
    "SBAS": "S",
    "Galileo": "E",
    "BeiDou": "C",
    "QZSS": "J",
    "Glonass": "R",
    "GLONASS": "R",
}
SIGNAL = {"G": "1C", "S": "1C", "E": "1C", "J": "1C", "R": "1C", "C": "2I"}
"""RINEX 3 band + attribute of the one signal a u-blox M8 tracks per system (B1I: band 2 from
RINEX 3.03 on)."""
SV_OFFSET = {"S": 100}
"""u-blox svId − RINEX number (SBAS PRN 120–158 → S20–S58); QZSS and the rest are numbered as
in RINEX already (u-blox M8 QZSS svId 1–10)."""
UNKNOWN_GLONASS_SLOT = 255
NLOS_LABELS = {"0": 0, "1": 1, "#": -1}
GROUND_TRUTH_COLUMNS = (
    "gt_week",
    "gt_tow",
    "lon",
    "lat",
    "height",
    "heading",
    "acceleration",
    "speed",
    "yaw_rate",
)


@dataclass(frozen=True)
class SmartLocTruth:
    """The reference state per epoch: ``t`` GPS s (the ground truth's own time columns),
    ``lat_rad``, ``lon_rad``, ``height_m`` (WGS 84 ellipsoidal), ``yaw_rad`` (the file's
    heading: counter-clockwise from east), ``speed_mps``, ``yaw_rate_rad_s`` (counter-clockwise
    positive), ``acceleration_mps2``; ``line`` the first file line of each epoch."""

    t: np.ndarray
    lat_rad: np.ndarray
    lon_rad: np.ndarray
    height_m: np.ndarray
    yaw_rad: np.ndarray
    speed_mps: np.ndarray
    yaw_rate_rad_s: np.ndarray
    acceleration_mps2: np.ndarray
    line: np.ndarray

    def __len__(self) -> int:
        return int(self.t.size)


@dataclass(frozen=True)
class SmartLocRecording:
    """What a smartLoc raw file holds: observations (with the per-row fields of the module
    docstring), the ground truth per epoch, the number of measurement rows read, and the
    skipped-data messages (each naming the file)."""

    observations: Observations
    truth: SmartLocTruth
    n_rows: int
    glonass_channels: dict[int, int]
    problems: tuple[str, ...]
    path: Path

    def doppler_sigma(self) -> ReportedSigma:
        """The σ of every Doppler row's range rate (m/s), as ``gnss.doppler_sigma`` takes it."""
        rows = self.observations.subset(
            np.flatnonzero(np.isfinite(self.observations.row_fields["range_rate_sigma_mps"]))
        )
        codes = np.array(rows.codes, dtype="U3")[rows.code]
        return ReportedSigma(
            rows.time, rows.satellites(), codes, rows.row_fields["range_rate_sigma_mps"]
        )


def is_smartloc_header(line: str) -> bool:
    """Whether ``line`` is a smartLoc raw file's header line."""
    return line.startswith("GPSWeek") and all(
        key in line for key in ("(doMes)", "(gnssId)", "NLOS")
    )


def read_smartloc(path: str | Path) -> SmartLocRecording:
    """Read a smartLoc raw CSV file (module docstring)."""
    path = Path(path)
    lines = read_text(path, "smartLoc raw CSV").splitlines()
    if not lines or not lines[0].strip():
        raise InputError("empty file: expected a smartLoc raw CSV header line", path, 1)
    columns = _columns(lines[0], path)
    width = len(lines[0].split(SEPARATOR))
    rows = _Rows(path)
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = line.split(SEPARATOR)
        if len(fields) != width:
            raise InputError(
                f"{len(fields)} fields, the header has {width} ({SEPARATOR!r}-separated)",
                path,
                number,
            )
        rows.add(number, {name: fields[k].strip() for name, k in columns.items()})
    if not rows.time:
        raise InputError("no measurement rows", path)
    return rows.recording()


def _columns(header: str, path: Path) -> dict[str, int]:
    names = [name.strip() for name in header.split(SEPARATOR)]
    found = {}
    for key, identifier in COLUMNS.items():
        matches = [k for k, name in enumerate(names) if _names(name, key, identifier)]
        if not matches:
            raise InputError(
                f"no column {identifier!r} in the header: not a smartLoc raw CSV "
                "(GPSWeek;GPSSecondsOfWeek;… (prMes) … (doMes) … NLOS)",
                path,
                1,
            )
        if len(matches) > 1:
            raise InputError(f"two columns named {identifier!r} in the header", path, 1)
        found[key] = matches[0]
    return found


def _names(name: str, key: str, identifier: str) -> bool:
    """Whether the header name ``name`` is the column ``key`` (not its ``Cov`` column)."""
    if key in ("gt_week", "gt_tow", "nlos"):
        return name.startswith(identifier)
    return identifier in name and " Cov " not in name


class _Rows:
    """Checked rows gathered while reading (one per measurement)."""

    def __init__(self, path: Path):
        self.path = path
        self.time: list[float] = []
        self.system: list[str] = []
        self.prn: list[int] = []
        self.values: list[tuple[float, float, float, float]] = []
        self.sigmas: list[tuple[float, float, float]] = []
        self.nlos: list[int] = []
        self.channels: dict[int, tuple[int, int]] = {}
        self.truth: list[tuple[float, ...]] = []
        self.truth_text: dict[float, tuple[int, tuple[str, ...]]] = {}
        self.dropped: dict[str, list[int]] = {}
        self.n_rows = 0

    def _number(self, row: dict[str, str], name: str, line: int) -> float:
        text = row[name]
        try:
            value = float(text)
        except ValueError:
            raise InputError(
                f"column {COLUMNS[name]}: {text[:30]!r} is not a number", self.path, line
            ) from None
        if not math.isfinite(value):
            raise InputError(
                f"column {COLUMNS[name]}: {text[:30]!r} is not finite", self.path, line
            )
        return value

    def _bounded(
        self, row: dict[str, str], name: str, line: int, low: float, high: float, unit: str = ""
    ) -> float:
        value = self._number(row, name, line)
        if not low <= value <= high:
            where = f"column {COLUMNS[name]}: {value:g}" + (f" {unit}" if unit else "")
            raise InputError(f"{where} outside {low:g} … {high:g}", self.path, line)
        return value

    def _within(self, row: dict[str, str], name: str, line: int, bounds: SignalBounds) -> float:
        """The column's value, checked against the bounds of :mod:`vo_doppler.bounds`."""
        return self._bounded(row, name, line, bounds.low, bounds.high, bounds.unit)

    def _integer(self, row: dict[str, str], name: str, line: int, low: int, high: int) -> int:
        value = self._bounded(row, name, line, low, high)
        if not value.is_integer():
            raise InputError(
                f"column {COLUMNS[name]}: {value:g} is not a whole number", self.path, line
            )
        return int(value)

    def _time(self, row: dict[str, str], week: str, tow: str, line: int) -> float:
        w = self._integer(row, week, line, 0, LAST_WEEK)
        seconds = self._number(row, tow, line)
        if not 0.0 <= seconds < SECONDS_PER_WEEK:
            raise InputError(
                f"column {COLUMNS[tow]}: {seconds:g} s is not a second of the week", self.path, line
            )
        return w * SECONDS_PER_WEEK + seconds

    def _drop(self, why: str, line: int) -> None:
        self.dropped.setdefault(why, []).append(line)

    def add(self, line: int, row: dict[str, str]) -> None:
        t = self._time(row, "week", "tow", line)
        if self.time and t < self.time[-1]:
            raise InputError(
                f"measurement time {t:.3f} s goes back from {self.time[-1]:.3f} s of the rows "
                "before (smartLoc files list epochs in time order)",
                self.path,
                line,
            )
        self._truth(row, t, line)
        name = row["gnss"]
        if name == "IMES":
            self._drop("IMES rows (not a satellite)", line)
            return
        if name not in SYSTEMS:
            raise InputError(
                f"column {COLUMNS['gnss']}: unknown system {name[:20]!r} (one of "
                f"{', '.join(sorted(set(SYSTEMS) | {'IMES'}))})",
                self.path,
                line,
            )
        system = SYSTEMS[name]
        sv = self._integer(row, "sv", line, 0, 255)
        if system == "R" and sv == UNKNOWN_GLONASS_SLOT:
            self._drop("GLONASS rows with an unknown slot (svId 255)", line)
            return
        prn = sv - SV_OFFSET.get(system, 0)
        low, high = PRN_RANGE[system]
        if not low <= prn <= high:
            raise InputError(
                f"column {COLUMNS['sv']}: no {name} satellite {sv} "
                f"(svId {low + SV_OFFSET.get(system, 0)}–{high + SV_OFFSET.get(system, 0)})",
                self.path,
                line,
            )
        if system == "R":
            channel = self._integer(row, "freq", line, 0, 13) - 7
            first = self.channels.setdefault(prn, (channel, line))
            if first[0] != channel:
                raise InputError(
                    f"GLONASS slot {prn} on channel {channel}, but {first[0]} on line {first[1]}",
                    self.path,
                    line,
                )
        tracking = self._integer(row, "tracking", line, 0, 255)
        values = [
            self._measured(row, "pseudorange", "C", line, tracking & 1),
            self._measured(row, "carrier", "L", line, tracking & 2),
            self._measured(row, "doppler", "D", line, True),
            self._within(row, "cn0", line, CN0),
        ]
        sigmas = tuple(
            self._within(row, name, line, MEASUREMENT_SIGMA)
            for name in ("pseudorange_sigma", "carrier_sigma", "doppler_sigma")
        )
        label = row["nlos"]
        if label not in NLOS_LABELS:
            raise InputError(f"NLOS label {label[:10]!r} is not 0, 1 or #", self.path, line)
        self.time.append(t)
        self.system.append(system)
        self.prn.append(prn)
        self.values.append(tuple(values))
        self.sigmas.append(sigmas)
        self.nlos.append(NLOS_LABELS[label])
        self.n_rows += 1

    def _measured(self, row: dict[str, str], name: str, kind: str, line: int, valid) -> float:
        value = self._number(row, name, line)
        if not valid:
            return math.nan
        low, high = VALUE_RANGES[kind]
        if not low <= value <= high:
            self._drop(f"{COLUMNS[name]} values outside {low:g} … {high:g}", line)
            return math.nan
        return value

    def _truth(self, row: dict[str, str], t: float, line: int) -> None:
        text = tuple(row[name] for name in GROUND_TRUTH_COLUMNS)
        if t in self.truth_text:
            first, known = self.truth_text[t]
            if text != known:
                changed = next(
                    COLUMNS[name]
                    for name, a, b in zip(GROUND_TRUTH_COLUMNS, text, known, strict=True)
                    if a != b
                )
                raise InputError(
                    f"ground truth {changed} differs from line {first} of the same epoch",
                    self.path,
                    line,
                )
            return
        self.truth_text[t] = (line, text)
        gt_t = self._time(row, "gt_week", "gt_tow", line)
        if self.truth and gt_t <= self.truth[-1][0]:
            raise InputError(
                f"ground-truth time {gt_t:.3f} s does not follow the previous epoch's "
                f"{self.truth[-1][0]:.3f} s",
                self.path,
                line,
            )
        state = (
            gt_t,
            math.radians(self._within(row, "lat", line, LATITUDE_DEG)),
            math.radians(self._within(row, "lon", line, LONGITUDE_DEG)),
            self._within(row, "height", line, HEIGHT),
            self._bounded(row, "heading", line, -2 * math.pi, 2 * math.pi, "rad"),
            self._within(row, "speed", line, SPEED),
            self._within(row, "yaw_rate", line, YAW_RATE),
            self._within(row, "acceleration", line, FORWARD_ACCELERATION),
            float(line),
        )
        self.truth.append(state)

    def recording(self) -> SmartLocRecording:
        n = len(self.time)
        time = np.repeat(np.array(self.time), 4)
        system = np.repeat(np.array(self.system, dtype="U1"), 4)
        prn = np.repeat(np.array(self.prn, dtype=np.int16), 4)
        codes = np.array([k + SIGNAL[s] for s in self.system for k in "CLDS"], dtype="U3")
        value = np.array(self.values, dtype=float).reshape(-1)
        sigma = np.column_stack([np.array(self.sigmas, dtype=float), np.full(n, np.nan)])
        channels = {prn: channel for prn, (channel, _) in self.channels.items()}
        wavelength = np.array(
            [
                SPEED_OF_LIGHT / carrier_frequency(s, "D" + SIGNAL[s], channels.get(p))
                for s, p in zip(self.system, self.prn, strict=True)
            ]
        )
        doppler = np.array(self.values, dtype=float)[:, 2]
        range_rate = np.full((n, 4), np.nan)
        range_rate_sigma = np.full((n, 4), np.nan)
        wavelengths = np.full((n, 4), np.nan)
        wavelengths[:, 2] = wavelength
        range_rate[:, 2] = -wavelength * doppler
        range_rate_sigma[:, 2] = wavelength * sigma[:, 2]
        problems = tuple(
            f"{self.path}: {len(lines)} {why} skipped (first on line {lines[0]})"
            for why, lines in self.dropped.items()
        )
        observations = observations_from_rows(
            self.path,
            "U-BLOX (smartLoc)",
            time,
            system,
            prn,
            codes,
            value,
            glonass_channels=channels,
            problems=problems,
            n_lines=0,
            row_fields={
                "nlos": np.repeat(np.array(self.nlos, dtype=np.int8), 4),
                "sigma": sigma.reshape(-1),
                "range_rate_mps": range_rate.reshape(-1),
                "range_rate_sigma_mps": range_rate_sigma.reshape(-1),
                "wavelength_m": wavelengths.reshape(-1),
            },
        )
        truth = np.array(self.truth, dtype=float).reshape(-1, 9)
        return SmartLocRecording(
            observations,
            SmartLocTruth(*(truth[:, k] for k in range(8)), line=truth[:, 8].astype(int)),
            self.n_rows,
            channels,
            observations.problems,
            self.path,
        )
