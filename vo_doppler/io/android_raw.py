"""Android raw GNSS measurements (``GnssClock`` + ``GnssMeasurement`` fields) → observations.

Rules of the Android documentation (``android.location.GnssMeasurement``/``GnssClock``) and
Google's white paper "Using GNSS raw measurements on Android devices" (2017, sec. 5):

- GPS time of reception t_Rx = TimeNanos + TimeOffsetNanos − (FullBiasNanos + BiasNanos)
  (integer nanoseconds kept exact; the epoch time is the same without TimeOffsetNanos).
- ReceivedSvTimeNanos is the satellite's time of week (GPS, Galileo, QZSS, NavIC, SBAS), of
  BeiDou time (BDT = GPST − 14 s) or of the GLONASS day (UTC(SU) + 3 h), valid only when the
  State flags say so: TOW_DECODED (8) or TOW_KNOWN (16384) for week-based systems, and
  GLO_TOD_DECODED (128) or GLO_TOD_KNOWN (32768) for GLONASS, with CODE_LOCK (1) and without
  MSEC_AMBIGUOUS (16). Pseudorange ρ = c·(t_Rx mod period − t_Tx) with a week/day rollover
  fix; rows outside 1 ms…0.5 s of travel time are dropped and counted.
- Doppler: PseudorangeRateMetersPerSecond ρ̇ is a range rate (positive receding), so the RINEX
  Doppler is D = −ρ̇·f/c (Hz, positive approaching, RINEX 3.05 sec. 5.2.10), f the row's
  CarrierFrequencyHz; the GNSS stage's ρ̇ = −λ·D gives ρ̇ back with its nominal λ (equal to
  c/f within 3·10⁻⁸ for the phones' reported frequencies). Rows whose uncertainty is not
  positive and below 1 km/s (phones write c there for "unknown"), or whose ρ̇ is beyond any
  satellite's (``RANGE_RATE``), are dropped and counted.
- Carrier phase L = AccumulatedDeltaRangeMeters·f/c when ADR_STATE_VALID (1); LLI bit 0 when
  RESET (2) or CYCLE_SLIP (4), or in an epoch whose HardwareClockDiscontinuityCount differs
  from the previous epoch's.
- C/N0 → ``S`` rows. The receiver-reported σ of D (PseudorangeRateUncertaintyMetersPerSecond,
  converted to Hz) and of C (ReceivedSvTimeUncertaintyNanos·c, NaN when not positive and
  finite) are returned as a RowSigma. C/N0 outside ``CN0`` and carrier phases outside
  ``CARRIER_PHASE`` are dropped and counted (bounds: :mod:`vo_doppler.bounds`).

Signals: band from CarrierFrequencyHz, attribute from CodeType, or for logs without CodeType
the usual phone signal of that band (``DEFAULT_ATTRIBUTE``). Satellite numbers: SBAS 120–158 →
S20–S58, QZSS 193–200 → J01–J08; GLONASS rows with an unknown slot (Svid 93–106, FCN + 100) are
dropped, and so are rows whose number is outside the system's (``PRN_RANGE``: Svid 0 …);
GLONASS channel k = (f − 1602 MHz)/0.5625 MHz.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from vo_doppler.bounds import (
    CARRIER_PHASE,
    CN0,
    GPS_TIME,
    MEASUREMENT_SIGMA,
    RANGE_RATE,
    SIGNAL_TRAVEL_TIME,
)
from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.io.obs_rows import observations_from_rows
from vo_doppler.io.rinex_common import PRN_RANGE
from vo_doppler.model.gpstime import BDT_MINUS_GPST_S, gps_minus_utc
from vo_doppler.model.observations import Observations
from vo_doppler.model.row_sigma import RowSigma

NANOS_PER_WEEK = 604_800 * 10**9
NANOS_PER_DAY = 86_400 * 10**9
CONSTELLATIONS = {1: "G", 2: "S", 3: "R", 4: "J", 5: "C", 6: "E", 7: "I"}
STATE_CODE_LOCK = 1
STATE_TOW_DECODED = 8
STATE_MSEC_AMBIGUOUS = 16
STATE_GLO_TOD_DECODED = 128
STATE_TOW_KNOWN = 16384
STATE_GLO_TOD_KNOWN = 32768
ADR_VALID, ADR_RESET, ADR_CYCLE_SLIP = 1, 2, 4
MAX_PRR_UNCERTAINTY_MPS = 1000.0
TRAVEL_TIME_RANGE_S = (SIGNAL_TRAVEL_TIME.low, SIGNAL_TRAVEL_TIME.high)
GPS_TIME_RANGE_S = (GPS_TIME.low, GPS_TIME.high)  # 1980-01-06 … 2100
# band centres (Hz) per system → RINEX band digit (RINEX 3.05 sec. 5.1)
BANDS = {
    "G": ((1575.42e6, "1"), (1227.60e6, "2"), (1176.45e6, "5")),
    "J": ((1575.42e6, "1"), (1227.60e6, "2"), (1176.45e6, "5"), (1278.75e6, "6")),
    "E": ((1575.42e6, "1"), (1176.45e6, "5"), (1207.14e6, "7"), (1278.75e6, "6")),
    "C": ((1561.098e6, "2"), (1575.42e6, "1"), (1176.45e6, "5"), (1207.14e6, "7")),
    "S": ((1575.42e6, "1"), (1176.45e6, "5")),
    "I": ((1176.45e6, "5"),),
    "R": ((1602.0e6, "1"), (1246.0e6, "2")),
}
BAND_TOLERANCE_HZ = {"R": 5e6}
DEFAULT_ATTRIBUTE = {"1": "C", "2": "C", "5": "Q", "6": "C", "7": "Q"}
DEFAULT_ATTRIBUTE_BY_SYSTEM = {("C", "2"): "I", ("C", "1"): "P", ("C", "5"): "P", ("I", "5"): "A"}
GLONASS_G1_HZ, GLONASS_G1_STEP_HZ = 1602.0e6, 0.5625e6


@dataclass(frozen=True)
class RawColumns:
    """The Raw-record columns a reader found, one array per field, and each row's line number.

    Integer clock fields are exact int64 (``None`` where a file cannot give them exactly, as
    GSDC's CSV, which then supplies ``arrival_ns`` and ``pseudorange_m`` itself).
    """

    path: Path
    line: np.ndarray
    constellation: np.ndarray
    svid: np.ndarray
    state: np.ndarray
    time_nanos: np.ndarray | None
    full_bias_nanos: np.ndarray | None
    bias_nanos: np.ndarray
    time_offset_nanos: np.ndarray
    received_sv_time_nanos: np.ndarray | None
    received_sv_time_uncertainty_nanos: np.ndarray
    cn0: np.ndarray
    prr: np.ndarray
    prr_uncertainty: np.ndarray
    adr_state: np.ndarray
    adr: np.ndarray
    frequency: np.ndarray
    code_type: np.ndarray
    leap_second: np.ndarray
    clock_discontinuity: np.ndarray
    arrival_ns: np.ndarray | None = None
    pseudorange_m: np.ndarray | None = None


def signal_codes(system: np.ndarray, frequency: np.ndarray, code_type: np.ndarray) -> np.ndarray:
    """Two-character RINEX band + attribute per row ('' where the band is unknown)."""
    out = np.full(system.shape, "", dtype="U2")
    for s, table in BANDS.items():
        rows = system == s
        tolerance = BAND_TOLERANCE_HZ.get(s, 1e6)
        for centre, band in table:
            hit = rows & (np.abs(frequency - centre) < tolerance)
            default = DEFAULT_ATTRIBUTE_BY_SYSTEM.get((s, band), DEFAULT_ATTRIBUTE[band])
            attribute = np.where(np.char.str_len(code_type) == 1, code_type, default)
            out[hit] = np.char.add(band, attribute[hit])
    return out


def numbered(system: np.ndarray, prn: np.ndarray) -> np.ndarray:
    """Rows whose satellite number lies within its system's (``PRN_RANGE``)."""
    ok = np.zeros(system.shape, dtype=bool)
    for letter, (low, high) in PRN_RANGE.items():
        rows = system == letter
        ok[rows] = (prn[rows] >= low) & (prn[rows] <= high)
    return ok


def satellite_ids(constellation: np.ndarray, svid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """System letter ('' when unknown) and RINEX satellite number of Android's Svid."""
    system = np.array([CONSTELLATIONS.get(int(c), "") for c in constellation], dtype="U1")
    prn = np.asarray(svid).astype(np.int64)
    prn[system == "S"] -= 100
    prn[system == "J"] -= 192
    return system, prn


def raw_observations(raw: RawColumns, receiver_type: str, problems: list[str]):
    """(Observations, RowSigma) of the Raw records (module docstring)."""
    path = raw.path
    system, prn = satellite_ids(raw.constellation, raw.svid)
    usable = (system != "") & numbered(system, prn) & np.isfinite(raw.frequency)
    usable &= ~((system == "R") & (raw.svid > 90))
    band = signal_codes(system, raw.frequency, raw.code_type)
    usable &= np.char.str_len(band) == 2
    _count(problems, path, ~usable, "Raw rows of unknown constellation, satellite or signal")
    epoch_time, pseudorange = _times_and_ranges(raw, system, problems)
    _check_order(path, raw.line, epoch_time)
    f = raw.frequency
    doppler = -raw.prr * f / SPEED_OF_LIGHT
    doppler_ok = np.isfinite(doppler) & ~RANGE_RATE.outside(raw.prr)
    doppler_ok &= (raw.prr_uncertainty > 0) & (raw.prr_uncertainty < MAX_PRR_UNCERTAINTY_MPS)
    _count(problems, path, usable & ~doppler_ok, "Doppler rows without a usable uncertainty")
    carrier = raw.adr * f / SPEED_OF_LIGHT
    carrier_ok = ((raw.adr_state.astype(np.int64) & ADR_VALID) > 0) & ~CARRIER_PHASE.outside(
        carrier
    )
    cn0_ok = ~CN0.outside(raw.cn0)
    _count(problems, path, usable & np.isfinite(raw.cn0) & ~cn0_ok, "C/N0 outside 0-100 dB-Hz")
    code_sigma = np.where(
        MEASUREMENT_SIGMA.outside(raw.received_sv_time_uncertainty_nanos),
        np.nan,
        raw.received_sv_time_uncertainty_nanos,
    )
    slip = (raw.adr_state.astype(np.int64) & (ADR_RESET | ADR_CYCLE_SLIP)) > 0
    slip |= _clock_reset(raw.clock_discontinuity, epoch_time)
    kinds = (
        ("D", doppler, doppler_ok, raw.prr_uncertainty * f / SPEED_OF_LIGHT, -1),
        ("C", pseudorange, np.isfinite(pseudorange), code_sigma, -1),
        ("L", carrier, carrier_ok, np.full(f.shape, np.nan), slip),
        ("S", raw.cn0, cn0_ok, np.full(f.shape, np.nan), -1),
    )
    columns: dict[str, list[np.ndarray]] = {k: [] for k in "tsnpcvlq"}
    for kind, value, ok, sigma, lli in kinds:
        rows = usable & ok
        columns["t"].append(epoch_time[rows])
        columns["s"].append(system[rows])
        columns["p"].append(prn[rows])
        columns["c"].append(np.char.add(kind, band[rows]))
        columns["v"].append(value[rows])
        columns["l"].append(np.broadcast_to(np.asarray(lli, dtype=np.int8), f.shape)[rows])
        columns["q"].append(sigma[rows] * (SPEED_OF_LIGHT * 1e-9 if kind == "C" else 1.0))
    joined = {k: np.concatenate(v) for k, v in columns.items() if v}
    glonass = usable & (system == "R")
    channels = {
        int(p): int(np.round((fr - GLONASS_G1_HZ) / GLONASS_G1_STEP_HZ))
        for p, fr in zip(prn[glonass], f[glonass], strict=True)
        if abs(fr - GLONASS_G1_HZ) < 5e6
    }
    obs: Observations = observations_from_rows(
        path,
        receiver_type,
        joined["t"],
        joined["s"],
        joined["p"],
        joined["c"],
        joined["v"],
        joined["l"],
        channels,
        tuple(problems),
        n_lines=int(raw.line.max(initial=0)),
    )
    sigma = RowSigma(
        joined["t"], joined["s"], joined["p"].astype(np.int16), joined["c"], joined["q"]
    )
    return obs, sigma


def _times_and_ranges(raw: RawColumns, system: np.ndarray, problems: list[str]):
    """Epoch GPS time (s) and pseudorange (m, NaN where the State flags forbid one)."""
    state = raw.state.astype(np.int64)
    locked = (state & STATE_CODE_LOCK > 0) & (state & STATE_MSEC_AMBIGUOUS == 0)
    week_ok = state & (STATE_TOW_DECODED | STATE_TOW_KNOWN) > 0
    day_ok = state & (STATE_GLO_TOD_DECODED | STATE_GLO_TOD_KNOWN) > 0
    glonass = system == "R"
    valid = locked & np.where(glonass, day_ok, week_ok)
    if raw.time_nanos is None or raw.full_bias_nanos is None or raw.received_sv_time_nanos is None:
        if raw.arrival_ns is None or raw.pseudorange_m is None:
            raise InputError("Raw records without clock fields", raw.path)
        epoch_time, travel_s = raw.arrival_ns * 1e-9, raw.pseudorange_m / SPEED_OF_LIGHT
    else:
        epoch_time, travel_s = _travel_times(raw, system)
    low, high = TRAVEL_TIME_RANGE_S
    in_range = (travel_s > low) & (travel_s < high)
    _count(problems, raw.path, valid & ~in_range, "pseudoranges outside 1 ms-0.5 s dropped")
    return epoch_time, np.where(valid & in_range, travel_s * SPEED_OF_LIGHT, np.nan)


def _travel_times(raw: RawColumns, system: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Epoch time and signal travel time (s) from the exact integer clock fields."""
    whole = raw.time_nanos - raw.full_bias_nanos
    wrapped = np.abs(raw.time_nanos.astype(float) - raw.full_bias_nanos.astype(float) - whole) > 1e6
    if np.any(wrapped):
        raise InputError("TimeNanos − FullBiasNanos overflows", raw.path, int(raw.line[wrapped][0]))
    epoch_time = whole * 1e-9 - raw.bias_nanos * 1e-9
    glonass = system == "R"
    period = np.where(glonass, NANOS_PER_DAY, NANOS_PER_WEEK)
    receive = np.mod(whole, NANOS_PER_WEEK)
    receive[system == "C"] += int(BDT_MINUS_GPST_S * 1e9)
    leap = np.where(np.isfinite(raw.leap_second), raw.leap_second, gps_minus_utc(epoch_time))
    receive[glonass] = np.mod(
        np.mod(whole[glonass], NANOS_PER_DAY)
        + 3 * 3600 * 10**9
        - (leap[glonass] * 1e9).astype(np.int64),
        NANOS_PER_DAY,
    )
    travel = receive - raw.received_sv_time_nanos
    travel = np.mod(travel + period // 2, period) - period // 2
    return epoch_time, (travel + raw.time_offset_nanos - raw.bias_nanos) * 1e-9


def _clock_reset(count: np.ndarray, epoch_time: np.ndarray) -> np.ndarray:
    """Rows of the epochs whose HardwareClockDiscontinuityCount differs from the previous
    epoch's: the receiver clock restarted, so no carrier phase continues across it."""
    epochs, first, index = np.unique(epoch_time, return_index=True, return_inverse=True)
    per_epoch = count[first]
    changed = np.zeros(epochs.size, dtype=bool)
    changed[1:] = np.isfinite(per_epoch[1:]) & (per_epoch[1:] != per_epoch[:-1])
    return changed[index]


def _check_order(path: Path, line: np.ndarray, epoch_time: np.ndarray) -> None:
    """Epoch times finite, between 1980 and 2100 (``GPS_TIME_RANGE_S``), never going back."""
    low, high = GPS_TIME_RANGE_S
    wrong = ~((epoch_time > low) & (epoch_time < high))
    if np.any(wrong):
        bad = int(line[np.flatnonzero(wrong)[0]])
        raise InputError("Raw record without a usable clock (FullBiasNanos/TimeNanos)", path, bad)
    back = np.flatnonzero(np.diff(epoch_time) < -1e-6)
    if back.size:
        raise InputError("Raw record earlier than the one before it", path, int(line[back[0] + 1]))


def _count(problems: list[str], path: Path, rows: np.ndarray, what: str) -> None:
    if np.any(rows):
        problems.append(f"{path}: {int(np.sum(rows))} {what}")
