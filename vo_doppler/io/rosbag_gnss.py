"""Raw GNSS topics of a ROS bag → :class:`Observations`, broadcast ephemerides, Klobuchar
parameters and the receiver's Doppler σ.

``gnss_comm`` (GVINS' interface, :mod:`vo_doppler.io.rosbag_types`):

- ``GnssMeasMsg`` → one row per (satellite, frequency, observable). The epoch is the
  measurement's own GPS time (``time.week`` · 604800 + ``time.tow``), not a ROS stamp. The
  satellite number is gnss_comm's (RTKLIB's ``sat_no``): GPS 1–32, GLONASS 33–59, Galileo
  60–97, BeiDou 98–160. The band comes from ``freqs`` (Hz; a GLONASS FDMA carrier gives its
  channel), the attribute from ``code`` read as RTKLIB's code number (1 = ``1C``, 14 = ``2C``,
  24 = ``5I`` …, ``RTKLIB_CODES``) when it names that band, otherwise the band's usual
  civil signal (``DEFAULT_ATTRIBUTE``). Values: ``psr`` → ``C`` (0 = none), ``cp`` → ``L``
  (cycles, 0 = none), ``dopp`` → ``D`` (Hz, the RINEX sign: positive approaching), ``CN0`` →
  ``S`` (dB-Hz, 0 = none), ``LLI`` kept on ``L``; values outside the UBX reader's plausible
  ranges are dropped and counted. ``dopp_std`` (Hz) × wavelength → the Doppler σ (m/s) where
  it is positive.
- ``GnssEphemMsg`` → Keplerian records (``A`` → √A, ``OMG0``/``omg``/``OMG_dot``/``i_dot``,
  ``tgd0`` → TGD or Galileo's BGD E5a/E1 or BeiDou's TGD1, ``tgd1`` → Galileo's BGD E5b/E1 or
  BeiDou's TGD2 in RINEX's IODC slot, ``iodc`` → BeiDou's AODC in the fit-interval slot); toc
  is gnss_comm's GPS time (BeiDou's written back on BDT as RINEX wants). Not in the message:
  the L2 P flag (0) and the GPS/QZSS fit interval (4 h, the normal one).
- ``GnssGloEphemMsg`` → GLONASS records (RINEX 3.04 Table A10): ``toe`` (gnss_comm's GPS
  time of tb) → the epoch, ``tau_n`` → −τn, ``gamma`` → γn, ``ttr`` → the message frame
  time (seconds of the UTC week), ``pos``/``vel``/``acc`` (m, m/s, m/s² in PZ-90, as gnss_comm
  holds them) → the state vector, ``health``, ``freqo`` → the frequency number, ``age``. Not
  in a 3.04 record: ``delta_tau_n`` and ``ura`` (the 3.05 fifth line).
- ``StampedFloat64Array`` (the receiver's ionosphere parameters, 8 values) → the navigation
  file's Klobuchar α/β (the last message).

An epoch without a single measurement cannot travel in a ``GnssMeasMsg`` (the time is in each
satellite's entry): it is not in the observations. ``RxmRAWX`` carries its time: it is kept.

``ublox_msgs``: ``RxmRAWX`` → rows exactly as the UBX log reader decodes RXM-RAWX
(:mod:`vo_doppler.io.ubx`: signal codes, LLI from the lock time and half-cycle flag, the value
ranges; a ROS 1 definition without ``sigId`` is read as signal 0, the L1 C/A of an M8);
``RxmSFRBX`` → ephemerides by the UBX reader's decoder (:mod:`vo_doppler.io.sfrbx`): GPS and
QZSS LNAV subframes 1–3 (the week from the RAWX messages), Galileo I/NAV words 1–5, BeiDou D1
subframes 1–3 of the MEO/IGSO satellites (BeiDou epochs written back on BDT), GLONASS strings
1–4 (``gnssId`` 6, ``svId`` the slot, ``freqId`` − 7 the frequency number; their day from the
first RAWX epoch); refused data named by message index, what is not decoded (BeiDou GEO, SBAS,
NavIC …) counted; ``doStdev`` (0.002·2ⁿ Hz) × wavelength → the Doppler σ.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from vo_doppler.io.gps_lnav import KEPLER_NAMES
from vo_doppler.io.rinex_nav import KEPLER_FIELDS
from vo_doppler.io.rinex_write import GLONASS_RECORD_FIELDS, GlonassRecord, KeplerRecord
from vo_doppler.io.rosbag_bag import Bag
from vo_doppler.io.rosbag_types import field as get
from vo_doppler.io.rosbag_types import has_field
from vo_doppler.io.sfrbx import SfrbxMessage, decode_sfrbx
from vo_doppler.io.ubx import VALUE_RANGES, _RawxRows
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.gpstime import BDT_MINUS_GPST_S, SECONDS_PER_WEEK, gps_minus_utc
from vo_doppler.model.observations import Observations

SPEED_OF_LIGHT = 299_792_458.0
SAT_RANGES = (("G", 1, 32), ("R", 33, 27), ("E", 60, 38), ("C", 98, 63))
"""gnss_comm / RTKLIB satellite numbers: (system, first number, satellites)."""
RTKLIB_CODES = (
    "",
    "1C",
    "1P",
    "1W",
    "1Y",
    "1M",
    "1N",
    "1S",
    "1L",
    "1E",
    "1A",
    "1B",
    "1X",
    "1Z",
    "2C",
    "2D",
    "2S",
    "2L",
    "2X",
    "2P",
    "2W",
    "2Y",
    "2M",
    "2N",
    "5I",
    "5Q",
    "5X",
    "7I",
    "7Q",
    "7X",
    "6A",
    "6B",
    "6C",
    "6X",
    "6Z",
    "6S",
    "6L",
    "8L",
    "8Q",
    "8X",
    "2I",
    "2Q",
    "6I",
    "6Q",
    "3I",
    "3Q",
    "3X",
    "1I",
    "1Q",
)
"""RTKLIB's observation code numbers (``obscodes``): index → RINEX 3 band + attribute."""
CARRIERS_HZ: dict[str, dict[str, float]] = {
    "G": {"1": 1575.42e6, "2": 1227.60e6, "5": 1176.45e6},
    "J": {"1": 1575.42e6, "2": 1227.60e6, "5": 1176.45e6, "6": 1278.75e6},
    "S": {"1": 1575.42e6, "5": 1176.45e6},
    "E": {"1": 1575.42e6, "5": 1176.45e6, "7": 1207.14e6, "8": 1191.795e6, "6": 1278.75e6},
    "C": {"2": 1561.098e6, "1": 1575.42e6, "5": 1176.45e6, "7": 1207.14e6, "6": 1268.52e6},
    "I": {"5": 1176.45e6, "9": 2492.028e6},
}
"""Carrier frequencies (Hz) of the RINEX 3 bands (ICDs; RINEX 3.05 Table 4)."""
GLONASS_BANDS = {"1": (1602.0e6, 0.5625e6), "2": (1246.0e6, 0.4375e6)}
DEFAULT_ATTRIBUTE = {"1": "C", "2": "C", "5": "Q", "6": "C", "7": "Q", "8": "Q", "9": "A"}
DEFAULT_ATTRIBUTE_BDS = {"2": "I", "7": "I", "6": "I", "1": "P", "5": "P"}
FREQUENCY_TOLERANCE_HZ = 1.0e5
FIT_HOURS = {"G": 4.0, "J": 4.0}
"""The fit interval GnssEphemMsg does not carry: 4 h, the normal one (fit flag 0, IS-GPS-200
sec. 20.3.3.4.3.1; IS-QZSS the same)."""


@dataclass
class BagGnss:
    """The raw GNSS of a bag: observations, ephemerides to write, Klobuchar α/β, Doppler σ."""

    observations: Observations
    ephemerides: list[KeplerRecord | GlonassRecord]
    klobuchar: np.ndarray | None
    doppler_sigma: ReportedSigma | None
    source: str
    problems: list[str] = field(default_factory=list)


def satellite(number: int) -> tuple[str, int] | None:
    """gnss_comm satellite number → (system, PRN), None when out of every range."""
    for system, first, count in SAT_RANGES:
        if first <= number < first + count:
            return system, number - first + 1
    return None


def satellite_number(system: str, prn: int) -> int:
    """(system, PRN) → gnss_comm satellite number (the inverse of :func:`satellite`)."""
    for name, first, count in SAT_RANGES:
        if name == system and 1 <= prn <= count:
            return first + prn - 1
    raise ValueError(f"{system}{prn:02d} has no gnss_comm satellite number")


def band_of(system: str, frequency_hz: float) -> tuple[str, int | None] | None:
    """RINEX band digit (and GLONASS channel) of a carrier frequency; None when unknown."""
    if system == "R":
        for band, (base, step) in GLONASS_BANDS.items():
            channel = round((frequency_hz - base) / step)
            near = abs(base + channel * step - frequency_hz) < 1.0e3
            if near and -7 <= channel <= 6:
                return band, channel
        return None
    for band, carrier in CARRIERS_HZ.get(system, {}).items():
        if abs(carrier - frequency_hz) < FREQUENCY_TOLERANCE_HZ:
            return band, None
    return None


def carrier_hz(system: str, band: str, channel: int | None = None) -> float:
    """Carrier frequency of a band (GLONASS by its channel), NaN when unknown."""
    if system == "R":
        if band not in GLONASS_BANDS or channel is None:
            return np.nan
        base, step = GLONASS_BANDS[band]
        return base + channel * step
    return CARRIERS_HZ.get(system, {}).get(band, np.nan)


class _Rows(_RawxRows):
    """The UBX reader's row lists (and their :meth:`observations`), filled from gnss_comm
    messages, with the Doppler σ in m/s."""

    def __init__(self) -> None:
        super().__init__()
        self.sigma: list[tuple[float, str, str, float]] = []
        self.n_dropped = 0

    def add(self, t: float, system: str, prn: int, code: str, value: float, lli: int = -1):
        low, high = VALUE_RANGES[code[0]]
        if not low <= value <= high:
            self.n_dropped += 1
            return
        self.time.append(t)
        self.system.append(system)
        self.prn.append(prn)
        self.code.append(code)
        self.value.append(float(value))
        self.sigma_value.append(np.nan)
        self.lli.append(lli)


def _sigma(rows: list[tuple[float, str, str, float]]) -> ReportedSigma | None:
    """The σ rows, the first of each (epoch, satellite, code) kept as the observations keep
    the first of a repeated measurement."""
    first: dict[tuple[float, str, str], float] = {}
    for t, sat, code, sigma in rows:
        first.setdefault((t, sat, code), sigma)
    if not first:
        return None
    t, sat, code, sigma = zip(*((*key, value) for key, value in first.items()), strict=True)
    return ReportedSigma(np.array(t), np.array(sat), np.array(code), np.array(sigma))


def read_gnss_comm(
    bag: Bag, meas_topic: str, ephem_topics: list[str], iono_topic: str | None
) -> BagGnss:
    """The gnss_comm topics (module docstring)."""
    rows = _Rows()
    problems: list[str] = []
    n_unknown = 0
    for index, _, message in bag.messages(meas_topic):
        for obs in get(message, "meas", ()) or ():
            n_unknown += _gnss_comm_obs(bag, meas_topic, index, obs, rows)
    if n_unknown:
        problems.append(f"{meas_topic}: {n_unknown} signals of an unknown satellite or frequency")
    if rows.n_dropped:
        problems.append(f"{meas_topic}: {rows.n_dropped} values out of range dropped")
    ephemerides: list[KeplerRecord | GlonassRecord] = []
    for topic in ephem_topics:
        for index, _, message in bag.messages(topic):
            if has_field(message, "pos_x"):
                ephemerides.append(_gnss_comm_glonass(bag, topic, index, message))
            else:
                ephemerides.append(_gnss_comm_ephemeris(bag, topic, index, message))
    klobuchar = _klobuchar(bag, iono_topic) if iono_topic else None
    return BagGnss(
        rows.observations(bag.path, problems),
        ephemerides,
        klobuchar,
        _sigma(rows.sigma),
        f"gnss_comm ({meas_topic}, {', '.join(ephem_topics) or 'no ephemeris topic'})",
        problems,
    )


def _array(bag: Bag, topic: str, index: int, obs, name: str, n: int) -> np.ndarray:
    values = np.asarray(get(obs, name, ()), dtype=float).ravel()
    if values.size == 0:
        return np.full(n, np.nan)
    if values.size != n:
        raise bag.error(
            topic, index, f"satellite {get(obs, 'sat')}: {n} frequencies but {values.size} {name}"
        )
    return values


def _gnss_comm_obs(bag: Bag, topic: str, index: int, obs, rows: _Rows) -> int:
    """Rows of one GnssObsMsg; returns the number of signals not understood."""
    time = get(obs, "time")
    week, tow = float(get(time, "week", np.nan)), float(get(time, "tow", np.nan))
    if not (0 < week < 8192 and np.isfinite(tow) and 0.0 <= tow < SECONDS_PER_WEEK):
        raise bag.error(topic, index, f"measurement time out of range (week {week}, {tow})")
    t = week * SECONDS_PER_WEEK + tow
    sat = satellite(int(get(obs, "sat", 0)))
    freqs = np.asarray(get(obs, "freqs", ()), dtype=float).ravel()
    if sat is None:
        return max(freqs.size, 1)
    system, prn = sat
    n = freqs.size
    psr, cp = _array(bag, topic, index, obs, "psr", n), _array(bag, topic, index, obs, "cp", n)
    dopp, cn0 = _array(bag, topic, index, obs, "dopp", n), _array(bag, topic, index, obs, "CN0", n)
    dopp_std = _array(bag, topic, index, obs, "dopp_std", n)
    lli = _array(bag, topic, index, obs, "LLI", n)
    code = _array(bag, topic, index, obs, "code", n)
    unknown = 0
    for j in range(n):
        band = band_of(system, freqs[j])
        if band is None:
            unknown += 1
            continue
        digit, channel = band
        if channel is not None:
            rows.channels[prn] = channel
        signal = _signal(system, digit, code[j])
        if psr[j] != 0.0:
            rows.add(t, system, prn, "C" + signal, psr[j])
        if cp[j] != 0.0:
            flag = int(lli[j]) if np.isfinite(lli[j]) else -1
            rows.add(t, system, prn, "L" + signal, cp[j], flag)
        rows.add(t, system, prn, "D" + signal, dopp[j])
        if cn0[j] != 0.0:
            rows.add(t, system, prn, "S" + signal, cn0[j])
        if np.isfinite(dopp_std[j]) and dopp_std[j] > 0.0 and np.isfinite(dopp[j]):
            sigma = dopp_std[j] * SPEED_OF_LIGHT / freqs[j]
            rows.sigma.append((t, f"{system}{prn:02d}", "D" + signal, sigma))
    return unknown


def _signal(system: str, band: str, code: float) -> str:
    """Band + attribute: RTKLIB's code number when it names this band, else the default."""
    number = int(code) if np.isfinite(code) else 0
    if 0 < number < len(RTKLIB_CODES) and RTKLIB_CODES[number][0] == band:
        return RTKLIB_CODES[number]
    table = DEFAULT_ATTRIBUTE_BDS if system == "C" else DEFAULT_ATTRIBUTE
    return band + table.get(band, "C")


def _gnss_comm_ephemeris(bag: Bag, topic: str, index: int, m) -> KeplerRecord:
    sat = satellite(int(get(m, "sat", 0)))
    if sat is None or sat[0] == "R":
        raise bag.error(
            topic,
            index,
            f"ephemeris of satellite number {get(m, 'sat')}: not a "
            "GPS, Galileo or BeiDou satellite",
        )
    system, prn = sat
    toc = _gnss_time(m, "toc")
    a = float(get(m, "A", np.nan))
    tgd1 = float(get(m, "tgd1", 0.0))
    params = {
        "af0": get(m, "af0"),
        "af1": get(m, "af1"),
        "af2": get(m, "af2"),
        "iode": get(m, "iode"),
        "crs": get(m, "crs"),
        "delta_n": get(m, "delta_n"),
        "m0": get(m, "M0"),
        "cuc": get(m, "cuc"),
        "e": get(m, "e"),
        "cus": get(m, "cus"),
        "sqrt_a": np.sqrt(a) if a > 0 else np.nan,
        "toe_sow": get(m, "toe_tow"),
        "cic": get(m, "cic"),
        "omega0": get(m, "OMG0"),
        "cis": get(m, "cis"),
        "i0": get(m, "i0"),
        "crc": get(m, "crc"),
        "omega": get(m, "omg"),
        "omega_dot": get(m, "OMG_dot"),
        "idot": get(m, "i_dot"),
        "codes": get(m, "code"),
        "week": get(m, "week"),
        "l2p_flag": 0.0,
        "accuracy": get(m, "ura"),
        "health": get(m, "health"),
        "tgd": get(m, "tgd0"),
        "iodc": tgd1 if system in "EC" else get(m, "iodc"),
        "transmission_sow": float(get(get(m, "ttr"), "tow", 0.0)),
        "fit_interval": get(m, "iodc") if system == "C" else FIT_HOURS.get(system, 0.0),
    }
    try:
        values = {k: float(v) for k, v in params.items()}
    except (TypeError, ValueError) as exc:
        raise bag.error(topic, index, f"ephemeris field is not a number: {exc}") from exc
    bad = [k for k in ("sqrt_a", "e", "toe_sow") if not np.isfinite(values[k])]
    if bad or not np.isfinite(toc) or not 0.0 <= values["e"] < 1.0:
        raise bag.error(
            topic,
            index,
            f"ephemeris of {system}{prn:02d} without a usable "
            f"{', '.join(bad) or 'eccentricity or toc'}",
        )
    if system == "C":
        toc += BDT_MINUS_GPST_S  # RINEX writes BeiDou epochs on BDT
    assert {n for g in KEPLER_FIELDS for n in g} <= set(values)
    return KeplerRecord(system, prn, toc, values)


def _gnss_time(message, name: str) -> float:
    time = get(message, name)
    return float(get(time, "week", 0)) * SECONDS_PER_WEEK + float(get(time, "tow", np.nan))


def _gnss_comm_glonass(bag: Bag, topic: str, index: int, m) -> GlonassRecord:
    """A GnssGloEphemMsg as a GLONASS record (module docstring)."""
    sat = satellite(int(get(m, "sat", 0)))
    if sat is None or sat[0] != "R":
        raise bag.error(
            topic, index, f"GLONASS ephemeris of satellite number {get(m, 'sat')}: not GLONASS"
        )
    toe, ttr = _gnss_time(m, "toe"), _gnss_time(m, "ttr")
    leap = float(gps_minus_utc(toe)) if np.isfinite(toe) else 0.0
    params = {
        "minus_tau_n": -float(get(m, "tau_n", np.nan)),
        "gamma_n": get(m, "gamma"),
        "frame_time": np.mod(ttr - leap, SECONDS_PER_WEEK),
        "health": get(m, "health"),
        "channel": get(m, "freqo"),
        "age": get(m, "age"),
    }
    for axis in "xyz":
        params |= {
            axis: get(m, f"pos_{axis}"),
            f"v{axis}": get(m, f"vel_{axis}"),
            f"a{axis}": get(m, f"acc_{axis}"),
        }
    try:
        values = {k: float(v) for k, v in params.items()}
    except (TypeError, ValueError) as exc:
        raise bag.error(topic, index, f"GLONASS ephemeris field is not a number: {exc}") from exc
    bad = [k for k, v in values.items() if not np.isfinite(v)]
    if bad or not np.isfinite(toe):
        raise bag.error(
            topic,
            index,
            f"GLONASS ephemeris of R{sat[1]:02d} without a usable {', '.join(bad) or 'toe'}",
        )
    return GlonassRecord(sat[1], toe, values)


def _klobuchar(bag: Bag, topic: str) -> np.ndarray | None:
    last = None
    for index, _, message in bag.messages(topic):
        data = np.asarray(get(message, "data", ()), dtype=float).ravel()
        if data.size != 8 or not np.all(np.isfinite(data)):
            raise bag.error(topic, index, f"{data.size} ionosphere values, not 8 finite ones")
        last = data
    return last


_TRACKING = {"prValid": 0, "cpValid": 1, "halfCyc": 2, "subHalfCyc": 3}
"""pyubx2's names of the RXM-RAWX trkStat bits."""
_STDEV = {"prStd": "prStdev", "cpStd": "cpStdev", "doStd": "doStdev"}


class _RawxView:
    """A ublox_msgs RxmRAWX seen with pyubx2's attribute names (``prMes_01``, ``prValid_01``…),
    so that the UBX reader's RXM-RAWX decoding is used unchanged."""

    def __init__(self, message) -> None:
        self.meas = list(get(message, "meas", ()) or ())
        self.rcvTow = float(get(message, "rcvTOW", np.nan))
        self.week = int(get(message, "week", 0))
        self.numMeas = len(self.meas)

    def __getattr__(self, name: str):
        base, _, number = name.rpartition("_")
        meas = self.meas[int(number) - 1]
        if base in _TRACKING:
            return (int(get(meas, "trkStat", 0)) >> _TRACKING[base]) & 1
        if base in _STDEV:
            return int(get(meas, _STDEV[base], 0)) & 0x0F
        if base == "sigId" and not has_field(meas, "sigId"):
            return 0
        value = get(meas, base)
        if value is None:
            raise AttributeError(name)
        return value


def read_ublox(bag: Bag, rawx_topic: str, sfrbx_topic: str | None) -> BagGnss:
    """The ublox_msgs topics (module docstring)."""
    raw = _RawxRows()
    problems: list[str] = []
    sigma: list[tuple[float, str, str, float]] = []
    epochs: list[float] = []
    for index, _, message in bag.messages(rawx_topic):
        view = _RawxView(message)
        tow, week = view.rcvTow, view.week
        if not (np.isfinite(tow) and 0.0 <= tow < SECONDS_PER_WEEK and 0 < week < 8192):
            raise bag.error(rawx_topic, index, f"RxmRAWX time out of range (week {week}, {tow})")
        if raw.time and week * SECONDS_PER_WEEK + tow < raw.time[-1]:
            raise bag.error(rawx_topic, index, "RxmRAWX epoch before the previous one")
        epochs.append(week * SECONDS_PER_WEEK + tow)
        first = len(raw.time)
        try:
            raw.add(view, index, bag.path, problems)
        except (AttributeError, KeyError, IndexError, TypeError, ValueError) as exc:
            raise bag.error(rawx_topic, index, f"unusable RxmRAWX measurement: {exc}") from exc
        for k in range(first, len(raw.time)):
            if raw.code[k][0] == "D" and np.isfinite(raw.sigma_value[k]):
                channel = raw.channels.get(raw.prn[k]) if raw.system[k] == "R" else None
                lam = SPEED_OF_LIGHT / carrier_hz(raw.system[k], raw.code[k][1], channel)
                if np.isfinite(lam):
                    sat = f"{raw.system[k]}{raw.prn[k]:02d}"
                    sigma.append((raw.time[k], sat, raw.code[k], raw.sigma_value[k] * lam))
    if not raw.time:
        raise bag.error(rawx_topic, 0, "no RxmRAWX measurement in the topic")
    ephemerides = (
        _sfrbx_ephemerides(bag, sfrbx_topic, raw.week, epochs[0], problems) if sfrbx_topic else []
    )
    observations = raw.observations(bag.path, problems)
    epoch_time = np.unique(np.concatenate([observations.epoch_time, epochs]))
    observations = replace(  # epochs without a measurement kept (RxmRAWX carries their time)
        observations, epoch_time=epoch_time, epoch_flag=np.zeros(epoch_time.size, np.int8)
    )
    return BagGnss(
        observations,
        ephemerides,
        None,
        _sigma(sigma),
        f"ublox_msgs ({rawx_topic}, {sfrbx_topic or 'no RxmSFRBX topic'})",
        problems,
    )


def _sfrbx_ephemerides(bag: Bag, topic: str, week: int | None, reference: float, problems):
    """The broadcast ephemerides of the RxmSFRBX topic (:mod:`vo_doppler.io.sfrbx`, as the UBX
    reader decodes them), problems named by message index."""
    messages = []
    for index, _, message in bag.messages(topic):
        words = tuple(int(w) for w in np.asarray(get(message, "dwrd", ()), dtype=np.int64).ravel())
        number = [int(get(message, name, 0) or 0) for name in ("gnssId", "svId", "sigId", "freqId")]
        messages.append(SfrbxMessage(index, *number, words))
    decoded = decode_sfrbx(messages, week, reference)
    for index, text in decoded.problems:
        where = topic if index is None else f"{topic}, message {index}"
        problems.append(f"{where}: {text}")
    kepler = decoded.kepler
    out: list[KeplerRecord | GlonassRecord] = []
    for k in range(len(kepler)):
        params = {name: float(kepler[name][k]) for name in KEPLER_NAMES if name != "toe"}
        system, toc = str(kepler.system[k]), float(kepler.toc[k])
        if system == "C":
            toc += BDT_MINUS_GPST_S  # RINEX writes BeiDou epochs on BDT
        out.append(KeplerRecord(system, int(kepler.prn[k]), toc, params))
    glonass = decoded.glonass
    for k in range(len(glonass)):
        params = {name: float(glonass[name][k]) for line in GLONASS_RECORD_FIELDS for name in line}
        out.append(GlonassRecord(int(glonass.prn[k]), float(glonass.toc[k]), params))
    return out
