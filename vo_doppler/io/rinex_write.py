"""RINEX 3.04 writers: mixed navigation file (GPS/Galileo/QZSS/BeiDou Keplerian records and
GLONASS state vectors) and observation file (code, Doppler, signal strength).

Formats follow RINEX 3.04 (IGS/RTCM, 2018): header records with the label in columns 61–80
(sec. 5.1), navigation records per Tables A6/A8 (system+PRN, epoch, then 7 "broadcast orbit"
lines of four D19.12 numbers) and A10 (GLONASS: the epoch tb in UTC, then 3 lines; positions,
velocities and accelerations in km, km/s, km/s²), observation epochs per Table A3 (``>``
epoch record, then one line per satellite of F14.3 value + LLI + signal-strength digit per
observable).

Values are written with the precision the format allows (D19.12 ≈ 13 significant digits for
navigation data, 1e-3 for observations), so a value read back equals :func:`nav_number` of
the value exactly, and an observation equals the value rounded to 1e-3.
"""

from __future__ import annotations

import datetime as dt
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vo_doppler.io.rinex_nav import GLONASS_FIELDS, KEPLER_FIELDS
from vo_doppler.model.observations import Observations

GPS_EPOCH = dt.datetime(1980, 1, 6)
PROGRAM = "vo-doppler sim"


def header_line(content: str, label: str) -> str:
    """One header record: content in columns 1–60, label in 61–80."""
    return f"{content:<60.60}{label:<20}\n"


def nav_number(value: float) -> str:
    """A D19.12 field (RINEX 3.04 Table A6): ``' 1.234567890123D-04'``; magnitudes below
    1e-99 (a three-digit exponent would not fit) are written as zero."""
    if abs(value) < 1e-99:
        value = 0.0
    return f"{value:19.12E}".replace("E", "D")


def rounded_nav_value(value: float) -> float:
    """The value a reader gets back from :func:`nav_number`."""
    return float(nav_number(value).replace("D", "E"))


def gps_calendar(gps_seconds: float) -> tuple[int, int, int, int, int, float]:
    """GPS seconds → (year, month, day, hour, minute, second) read as GPS time (µs resolution)."""
    whole = np.floor(gps_seconds)
    micro = round((gps_seconds - whole) * 1e6)
    stamp = GPS_EPOCH + dt.timedelta(seconds=int(whole), microseconds=micro)
    second = stamp.second + stamp.microsecond * 1e-6
    return stamp.year, stamp.month, stamp.day, stamp.hour, stamp.minute, second


def _program_line(gps_seconds: float, program: str = PROGRAM) -> str:
    """'PGM / RUN BY / DATE' dated at the data's first epoch, so output is reproducible."""
    year, month, day, hour, minute, second = gps_calendar(gps_seconds)
    stamp = f"{year:04d}{month:02d}{day:02d} {hour:02d}{minute:02d}{int(second):02d} GPS"
    return header_line(f"{program:<20}{'vo-doppler':<20}{stamp:<20}", "PGM / RUN BY / DATE")


@dataclass(frozen=True)
class KeplerRecord:
    """One broadcast ephemeris of a Keplerian system (names as ``rinex_nav.KEPLER_FIELDS``).

    ``toc`` is the clock reference time in GPS seconds; ``params`` holds every field of
    ``KEPLER_FIELDS`` (SI units and radians, as in the file; ``toe_sow`` seconds of week).
    """

    system: str
    prn: int
    toc: float
    params: dict[str, float]


GLONASS_RECORD_FIELDS = GLONASS_FIELDS[:4]
"""The GLONASS record of RINEX 3.04 (Table A10): its fifth line (status flags, Δτn, URAI,
health flags) appeared in 3.05."""
KILOMETRE_FIELDS = frozenset(("x", "y", "z", "vx", "vy", "vz", "ax", "ay", "az"))


@dataclass(frozen=True)
class GlonassRecord:
    """One GLONASS broadcast ephemeris (names as ``rinex_nav.GLONASS_FIELDS``' first four
    lines): ``toc`` is its reference time tb in GPS seconds (written in UTC, as RINEX wants);
    ``params`` in SI units as the reader returns them (m, m/s, m/s²; ``minus_tau_n`` s,
    ``frame_time`` s of the UTC week, ``channel`` the frequency number)."""

    prn: int
    toc: float
    params: dict[str, float]
    system: str = "R"


def write_nav(
    path: str | Path,
    records: Sequence[KeplerRecord | GlonassRecord],
    leap_seconds: int = 18,
    klobuchar: np.ndarray | None = None,
) -> None:
    """Write a RINEX 3.04 mixed navigation file (Keplerian records on GPS-time epochs,
    GLONASS records on UTC epochs: ``leap_seconds`` before GPS time).

    ``klobuchar`` (α0–α3, β0–β3) goes into the 'IONOSPHERIC CORR' GPSA/GPSB records.
    """
    lines = [
        header_line(
            f"{3.04:9.2f}{'':11}{'N: GNSS NAV DATA':<20}{'M: MIXED':<20}", "RINEX VERSION / TYPE"
        ),
        _program_line(min((r.toc for r in records), default=0.0)),
    ]
    if klobuchar is not None:
        for name, part in (("GPSA", klobuchar[:4]), ("GPSB", klobuchar[4:])):
            text = "".join(f"{v:12.4E}".replace("E", "D") for v in part)
            lines.append(header_line(f"{name} {text}", "IONOSPHERIC CORR"))
    lines.append(header_line(f"{leap_seconds:6d}", "LEAP SECONDS"))
    lines.append(header_line("", "END OF HEADER"))
    for record in records:
        glonass = isinstance(record, GlonassRecord)
        epoch = record.toc - leap_seconds if glonass else record.toc
        year, month, day, hour, minute, second = gps_calendar(epoch)
        first = (
            f"{record.system}{record.prn:02d} {year:4d} {month:02d} {day:02d} {hour:02d} "
            f"{minute:02d} {round(second):02d}"
        )
        fields = GLONASS_RECORD_FIELDS if glonass else KEPLER_FIELDS
        groups = [
            [record.params[name] / (1000.0 if name in KILOMETRE_FIELDS else 1.0) for name in group]
            for group in fields
        ]
        lines.append(first + "".join(nav_number(v) for v in groups[0]) + "\n")
        lines.extend("    " + "".join(nav_number(v) for v in group) + "\n" for group in groups[1:])
    Path(path).write_text("".join(lines))


@dataclass(frozen=True)
class ObsEpochs:
    """Observations to write, one row per (epoch, satellite).

    ``epoch_time`` GPS seconds of the epoch tags (receiver time); ``epoch`` index of each row's
    epoch; ``satellite`` ids such as 'G05'; ``values`` (rows, n_codes) with NaN for blank
    fields; ``codes`` per system, the same order for every system (e.g. C1C D1C S1C).
    """

    epoch_time: np.ndarray
    epoch: np.ndarray
    satellite: np.ndarray
    values: np.ndarray
    codes: tuple[str, ...]


KIND_ORDER = "CLDS"
"""Order of the observable kinds within one signal in the written files."""


def observation_epochs(obs: Observations) -> ObsEpochs:
    """Columnar observations as RINEX epoch rows: one row per (epoch, satellite) holding the
    value of each code (NaN where none), the codes ordered by signal, then C, L, D, S, the same
    for every system; the epochs of ``obs.epoch_time`` (one without a row is written empty)."""
    codes = tuple(sorted(obs.codes, key=lambda c: (c[1:], KIND_ORDER.find(c[0]))))
    column = {code: codes.index(code) for code in obs.codes}
    lines: dict[tuple[int, str], np.ndarray] = {}
    epochs = np.searchsorted(obs.epoch_time, obs.time)
    for epoch, sat, code, value in zip(
        epochs.tolist(), obs.satellites().tolist(), obs.code.tolist(), obs.value, strict=True
    ):
        values = lines.setdefault((epoch, sat), np.full(len(codes), np.nan))
        values[column[obs.codes[code]]] = value
    keys = list(lines)
    return ObsEpochs(
        obs.epoch_time,
        np.array([k[0] for k in keys], dtype=int),
        np.array([k[1] for k in keys], dtype="U3"),
        np.array([lines[k] for k in keys]).reshape(len(keys), len(codes)),
        codes,
    )


def signal_strength_digit(cn0_dbhz: np.ndarray) -> np.ndarray:
    """RINEX 3.04 sec. 5.7 signal-strength indicator 1–9 from C/N0 (dB-Hz): ⌊C/N0 / 6⌋."""
    return np.clip(np.floor(np.asarray(cn0_dbhz) / 6.0), 1, 9).astype(int)


def write_obs(
    path: str | Path,
    data: ObsEpochs,
    approx_position: np.ndarray,
    interval_s: float,
    marker_name: str = "SIM",
    receiver: str = "SIMULATED",
    antenna_height_m: float = 0.0,
    glonass_channels: dict[int, int] | None = None,
    program: str = PROGRAM,
    observer: str = "simulation",
    antenna: str = "SIMULATED",
) -> None:
    """Write a RINEX 3.04 mixed observation file (GPS time).

    ``program``, ``observer`` and ``antenna`` fill the header's PGM, OBSERVER / AGENCY and
    ANT # / TYPE records (defaults: a simulation's; an importer names the recording's).

    The signal-strength digit of every observable comes from the row's ``S`` observable (the
    C/N0), when there is one. ``glonass_channels`` (slot → frequency channel) are written as
    ``GLONASS SLOT / FRQ #`` records (RINEX 3.04 Table A2), eight slots per line.
    """
    systems = sorted({s[0] for s in data.satellite.tolist()})
    x, y, z = approx_position
    first = gps_calendar(float(data.epoch_time[0]))
    lines = [
        header_line(
            f"{3.04:9.2f}{'':11}{'OBSERVATION DATA':<20}{'M: MIXED':<20}", "RINEX VERSION / TYPE"
        ),
        _program_line(float(data.epoch_time[0]), program),
        header_line(marker_name, "MARKER NAME"),
        header_line("NON_PHYSICAL", "MARKER TYPE"),
        header_line(f"{'vo-doppler':<20}{observer:<40}", "OBSERVER / AGENCY"),
        header_line(f"{'0':<20}{receiver:<20}{'1.0':<20}", "REC # / TYPE / VERS"),
        header_line(f"{'0':<20}{antenna:<20}", "ANT # / TYPE"),
        header_line(f"{x:14.4f}{y:14.4f}{z:14.4f}", "APPROX POSITION XYZ"),
        header_line(f"{antenna_height_m:14.4f}{0.0:14.4f}{0.0:14.4f}", "ANTENNA: DELTA H/E/N"),
    ]
    for system in systems:
        lines.append(
            header_line(
                f"{system}  {len(data.codes):3d}" + "".join(f" {c}" for c in data.codes),
                "SYS / # / OBS TYPES",
            )
        )
    lines += [
        header_line("DBHZ", "SIGNAL STRENGTH UNIT"),
        header_line(f"{interval_s:10.3f}", "INTERVAL"),
        header_line(
            "{:6d}{:6d}{:6d}{:6d}{:6d}{:13.7f}     GPS".format(*first), "TIME OF FIRST OBS"
        ),
    ]
    for system in systems:
        lines.append(header_line(system, "SYS / PHASE SHIFT"))
    slots = sorted((glonass_channels or {}).items())
    for start in range(0, len(slots), 8):
        count = f"{len(slots):3d} " if start == 0 else " " * 4
        chunk = "".join(f"R{slot:02d} {channel:2d} " for slot, channel in slots[start : start + 8])
        lines.append(header_line(count + chunk, "GLONASS SLOT / FRQ #"))
    lines.append(header_line("", "END OF HEADER"))
    strength = next((k for k, c in enumerate(data.codes) if c.startswith("S")), None)
    ssi = (
        signal_strength_digit(np.nan_to_num(data.values[:, strength], nan=0.0))
        if strength is not None
        else np.zeros(len(data.epoch), dtype=int)
    )
    order = np.lexsort((data.satellite, data.epoch))
    bounds = np.searchsorted(data.epoch[order], np.arange(len(data.epoch_time) + 1))
    for k, t in enumerate(data.epoch_time):
        rows = order[bounds[k] : bounds[k + 1]]
        year, month, day, hour, minute, second = gps_calendar(float(t))
        date = f"{year:4d} {month:02d} {day:02d} {hour:02d} {minute:02d}{second:11.7f}"
        lines.append(f"> {date}  0{rows.size:3d}\n")
        for row in rows:
            fields = [
                "" if np.isnan(v) else f"{v:14.3f} {ssi[row] if ssi[row] else ' '}"
                for v in data.values[row]
            ]
            text = "".join(f"{f:<16}" for f in fields).rstrip()
            lines.append(f"{data.satellite[row]}{text}\n")
    Path(path).write_text("".join(lines))
