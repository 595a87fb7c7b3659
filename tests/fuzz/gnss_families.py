"""Fuzz families of the newer GNSS readers: SP3, RINEX clock, UBX, Android GnssLogger, GSDC
``device_gnss.csv``, KITTI raw OXTS folders and comma2k19 ``raw_gnss_ublox`` arrays.

Every seed comes from the real recordings in ``../shared/data``: the SP3 file of the comma2k19
day as distributed, a RINEX clock file holding that file's clocks, a UBX log made of the
Yamatogawa receiver's own measurements (RXM-RAWX), its broadcast ephemerides (RXM-SFRBX, with
two GLONASS satellites' strings added) and fixes at its surveyed position (NAV-PVT), both
Android logs, the GSDC table, an OXTS folder holding the comma2k19 receiver's fixes and a
slice of the comma2k19 raw measurement array.
Formats that are folders or binary arrays are fuzzed through a text or one-file form that
``read`` unpacks (see each family). Registered by ``families.py`` with::

    register_gnss(register, Family, Seed, check_observations, check_navigation)
"""

from __future__ import annotations

import io
from collections.abc import Callable
from pathlib import Path

import numpy as np
from pyubx2 import UBXMessage

from tests.conftest import shared_data_dir
from tests.helpers import glonass_strings as glo
from tests.helpers.lnav import encode_ephemeris, sfrbx
from tests.helpers.precise_text import calendar, clock_text
from vo_doppler.io.android import read_gnsslogger
from vo_doppler.io.comma2k19 import RAW_GNSS, read_raw_gnss
from vo_doppler.io.gsdc import read_device_gnss
from vo_doppler.io.kitti_oxts import OXTS_FIELDS, read_oxts
from vo_doppler.io.rinex_clock import read_rinex_clock
from vo_doppler.io.rinex_common import PRN_RANGE
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.sp3 import read_sp3
from vo_doppler.io.ubx import read_ubx
from vo_doppler.model.gpstime import SECONDS_PER_WEEK, gps_minus_utc

COMMA = "comma2k19_example1"
SP3 = f"{COMMA}/Sta20124_1400_1845.sp3"
YAMATOGAWA = "yamatogawa_ublox_walk"
ANDROID = "android_pixel7pro"
GPS_SECONDS = (0.0, 4096 * SECONDS_PER_WEEK)
ORBIT_RADIUS_M = (1.0e7, 5.0e7)
MAX_CLOCK_S = 0.01
"""GNSS satellite clocks stay within about 1 ms of system time."""
OXTS_SEPARATOR = b"--- data"
UBX_EPOCHS = 40
RAW_GNSS_ROWS = 600


def _shared(relative: str) -> Path:
    return shared_data_dir() / relative


def _present(*relatives: str) -> bool:
    return all(_shared(r).exists() for r in relatives)


def _bad_times(t: np.ndarray, what: str, strictly: bool = True) -> list[str]:
    t = np.asarray(t, dtype=float)
    if not np.isfinite(t).all():
        return [f"{what} times not finite"]
    if t.size and (t.min() < GPS_SECONDS[0] or t.max() > GPS_SECONDS[1]):
        return [f"{what} times outside GPS weeks 0–4095"]
    steps = np.diff(t)
    if steps.size and ((steps <= 0).any() if strictly else (steps < 0).any()):
        return [f"{what} times go backwards" + (" or repeat" if strictly else "")]
    return []


def _bad_ids(what: str, sat_id: np.ndarray) -> list[str]:
    for sat in np.asarray(sat_id).tolist():
        low, high = PRN_RANGE.get(sat[:1], (0, -1))
        if not (sat[1:].isdigit() and low <= int(sat[1:]) <= high):
            return [f"{what}: satellite {sat!r} does not exist"]
    return []


def _bad_clocks(what: str, clock_s: np.ndarray) -> list[str]:
    known = clock_s[~np.isnan(clock_s)]
    if known.size and not (np.abs(known) < MAX_CLOCK_S).all():
        return [f"{what}: a clock beyond ±{MAX_CLOCK_S} s"]
    return []


def _bad_radius(what: str, position: np.ndarray) -> list[str]:
    rows = position.reshape(-1, 3)
    known = rows[~np.isnan(rows).any(axis=1)]
    radius = np.linalg.norm(known, axis=1)
    low, high = ORBIT_RADIUS_M
    if radius.size and not ((radius > low) & (radius < high)).all():
        return [f"{what}: a satellite off any GNSS orbit"]
    if np.isnan(rows).any(axis=1).sum() != np.isnan(rows).all(axis=1).sum():
        return [f"{what}: a position only partly known"]
    return []


# SP3 and RINEX clock


def check_sp3(orbits, path: Path) -> list[str]:
    bad = _bad_times(orbits.t, "SP3 epoch") + _bad_ids("SP3", orbits.sat_id)
    return bad + _bad_radius("SP3", orbits.position) + _bad_clocks("SP3", orbits.clock_s)


def clock_seed_text() -> bytes:
    """The comma2k19 day's SP3 clocks as a RINEX 3.04 clock file."""
    orbits = read_sp3(_shared(SP3))
    ids = [str(s) for s in orbits.sat_id]
    return clock_text(orbits.t, ids, orbits.clock_s).encode()


def check_clock(clocks, path: Path) -> list[str]:
    bad = _bad_times(clocks.t, "clock epoch") + _bad_ids("clock", clocks.sat_id)
    return bad + _bad_clocks("clock", clocks.bias_s)


# UBX


def _ubx_rawx(week: int, tow: float, rows: list[tuple[int, dict[str, float]]]) -> bytes:
    fields: dict[str, float] = {}
    for k, (prn, value) in enumerate(rows, start=1):
        s = f"_{k:02d}"
        fields |= {f"gnssId{s}": 0, f"svId{s}": prn, f"sigId{s}": 0, f"locktime{s}": 20000}
        fields |= {f"prStd{s}": 4, f"cpStd{s}": 2, f"doStd{s}": 5, f"halfCyc{s}": 1}
        fields |= {f"cno{s}": int(value.get("S1", 0)), f"doMes{s}": value.get("D1", 0.0)}
        fields |= {f"prMes{s}": value.get("C1", 0.0), f"prValid{s}": int("C1" in value)}
        fields |= {f"cpMes{s}": value.get("L1", 0.0), f"cpValid{s}": int("L1" in value)}
    return UBXMessage(
        "RXM", "RXM-RAWX", 0, rcvTow=tow, week=week, leapS=15, numMeas=len(rows), version=1,
        **fields,
    ).serialize()  # fmt: skip


def _ubx_pvt(t: float, lat_deg: float, lon_deg: float, height_m: float) -> bytes:
    y, mo, d, h, mi, s = calendar(t - float(gps_minus_utc(t)))
    return UBXMessage(
        "NAV", "NAV-PVT", 0, iTOW=round(np.mod(t, SECONDS_PER_WEEK) * 1000), year=y,
        month=mo, day=d, hour=h, min=mi, second=int(s), nano=0, validDate=1, validTime=1,
        fullyResolved=1, fixType=3, gnssFixOk=1, numSV=8, lon=lon_deg, lat=lat_deg,
        height=int(height_m * 1000), hMSL=int(height_m * 1000), hAcc=3000, vAcc=5000,
        gSpeed=0, headMot=0.0, sAcc=200, headAcc=180.0,
    ).serialize()  # fmt: skip


def _ephemerides(t0: float, prns: set[int]) -> list[bytes]:
    """The broadcast ephemeris of each observed satellite nearest the first epoch, as LNAV
    subframes 1–3."""
    kepler = read_nav(_shared(f"{YAMATOGAWA}/brdc0060.10n")).kepler
    messages = []
    for prn in sorted(prns):
        rows = np.flatnonzero((kepler.system == "G") & (kepler.prn == prn))
        if not rows.size:
            continue
        r = rows[np.argmin(np.abs(kepler.toc[rows] - t0))]
        eph = {key: float(values[r]) for key, values in kepler.params.items()}
        eph |= {"toc_sow": float(np.mod(kepler.toc[r], SECONDS_PER_WEEK)), "ura_index": 0}
        tow_count = int(np.mod(t0, SECONDS_PER_WEEK) // 6)
        messages += [sfrbx(prn, words) for words in encode_ephemeris(eph, tow_count)]
    return messages


def _glonass_strings(t0: float) -> list[bytes]:
    """RXM-SFRBX messages of GLONASS strings 1–4 of two satellites (the test helper's record,
    tb the quarter hour after ``t0``): the log carries no GLONASS, these make the seed hold
    the string decoder's input too."""
    toc = glo.tb_quarter_hour(t0)
    return [
        glo.ubx_sfrbx(slot, channel, string)
        for slot, channel in ((3, -5), (14, 2))
        for string in glo.encode_strings(slot, toc, glo.example_at(toc))
    ]


def ubx_seed() -> bytes:
    """The first epochs of the Yamatogawa receiver's RINEX file as the UBX log it came from,
    with two GLONASS satellites' strings."""
    obs = read_obs(_shared(f"{YAMATOGAWA}/yamatogawa_rover.obs"))
    x, y, z = obs.header.approx_position
    lat = float(np.degrees(np.arctan2(z, np.hypot(x, y) * (1 - 0.00669438))))
    lon = float(np.degrees(np.arctan2(y, x)))
    out = _ephemerides(float(obs.epoch_time[0]), set(obs.prn[obs.system == "G"].tolist()))
    out += _glonass_strings(float(obs.epoch_time[0]))
    for t in obs.epoch_time[:UBX_EPOCHS]:
        here = (obs.time == t) & (obs.system == "G")
        rows: dict[int, dict[str, float]] = {}
        for prn, code, value in zip(obs.prn[here], obs.code[here], obs.value[here], strict=True):
            rows.setdefault(int(prn), {})[obs.codes[code]] = float(value)
        week, tow = divmod(float(t), SECONDS_PER_WEEK)
        out.append(_ubx_rawx(int(week), tow, sorted(rows.items())))
        out.append(_ubx_pvt(float(t), lat, lon, 50.0))
    return b"".join(out)


def make_check_ubx(check_observations, check_navigation):
    def check_ubx(recording, path: Path) -> list[str]:
        bad = (
            []
            if recording.observations is None
            else check_observations(recording.observations, path)
        )
        bad += check_navigation(recording.navigation, path)
        fix = recording.solution
        bad += _bad_times(fix.t, "NAV-PVT")
        if fix.t.size and not (np.abs(fix.lat) <= np.pi / 2).all():
            bad.append("NAV-PVT latitude out of range")
        sigma = recording.sigma.sigma[~np.isnan(recording.sigma.sigma)]
        if sigma.size and not (np.isfinite(sigma) & (sigma > 0)).all():
            bad.append("reported σ not positive and finite")
        return bad

    return check_ubx


# Android GnssLogger and GSDC


def make_check_android(check_observations):
    def check_android(log, path: Path) -> list[str]:
        bad = check_observations(log.observations, path)
        if log.yaw_rate is not None:
            bad += _bad_times(log.yaw_rate.t, "gyro", strictly=False)
            if not np.isfinite(log.yaw_rate.value).all():
                bad.append("yaw rate not finite")
        return bad + _unnamed(log.problems, path)

    return check_android


def make_check_gsdc(check_observations):
    def check_gsdc(recording, path: Path) -> list[str]:
        bad = check_observations(recording.observations, path)
        table = recording.satellites
        bad += _bad_times(table.time, "satellite state", strictly=False)
        bad += _bad_radius("GSDC", np.asarray(table.position))
        if not (np.isfinite(table.velocity).all() and np.isfinite(table.clock_drift).all()):
            bad.append("satellite velocity or clock drift not finite")
        receiver = recording.receiver_ecef[~np.isnan(recording.receiver_ecef).any(axis=1)]
        radius = np.linalg.norm(receiver, axis=1)
        if radius.size and not ((radius > 6.0e6) & (radius < 7.0e6)).all():
            bad.append("WLS receiver position off the Earth's surface")
        return bad + _unnamed(recording.problems, path)

    return check_gsdc


def _unnamed(problems, path: Path) -> list[str]:
    return [f"problem does not name the file: {p!r}" for p in problems if str(path) not in p]


# KITTI OXTS: a folder, fuzzed as one text file


def oxts_seed() -> bytes:
    """The comma2k19 receiver's first 100 fixes (10 Hz) as an OXTS folder in one text:
    ``timestamps.txt`` lines, a separator, one data line per frame."""
    value = np.load(_shared(f"{COMMA}/processed_log/GNSS/live_gnss_ublox/value"))[:100]
    stamps, packets = [], []
    for lat, lon, speed, utc_ms, alt, course in value:
        whole, ms = divmod(round(utc_ms), 1000)
        stamp = np.datetime64(whole, "s").astype(str).replace("T", " ")
        stamps.append(f"{stamp}.{ms:03d}000000")
        yaw = np.angle(np.exp(1j * (np.pi / 2 - np.radians(course))))
        fields = dict.fromkeys(OXTS_FIELDS, 0.0)
        fields |= {"lat": lat, "lon": lon, "alt": alt, "yaw": yaw, "vf": speed}
        fields |= {
            "vn": speed * np.cos(np.radians(course)),
            "ve": speed * np.sin(np.radians(course)),
        }
        fields |= {"navstat": 4, "numsats": 9, "posmode": 4, "velmode": 4, "orimode": 6}
        packets.append(" ".join(f"{fields[name]:.12g}" for name in OXTS_FIELDS))
    text = "\n".join([*stamps, OXTS_SEPARATOR.decode(), *packets]) + "\n"
    return text.encode()


def read_oxts_bundle(path: Path):
    """Unpack the one-file form into ``<path>.d/{timestamps.txt,data/NNNNNNNNNN.txt}`` (every
    line after the separator one data file, as written) and read that folder."""
    folder = Path(f"{path}.d")
    data = folder / "data"
    data.mkdir(parents=True, exist_ok=True)
    for old in data.iterdir():
        old.unlink()
    stamps, _, packets = path.read_bytes().partition(b"\n" + OXTS_SEPARATOR + b"\n")
    (folder / "timestamps.txt").write_bytes(stamps + b"\n")
    for k, line in enumerate(packets.split(b"\n")[:10_000]):
        if line:
            (data / f"{k:010d}.txt").write_bytes(line + b"\n")
    return read_oxts(folder)


def check_oxts(record, path: Path) -> list[str]:
    bad = _bad_times(record.t, "OXTS")
    if not np.isfinite(record.poses).all():
        bad.append("poses not finite")
    for name in ("yaw_rate", "speed"):
        if not np.isfinite(getattr(record, name).value).all():
            bad.append(f"{name} not finite")
    return bad


# comma2k19 raw_gnss_ublox: a numpy array, fuzzed as its text


def raw_gnss_seed() -> bytes:
    value = np.load(_shared(f"{COMMA}/{'/'.join(RAW_GNSS)}/value"))[:RAW_GNSS_ROWS]
    out = io.StringIO()
    np.savetxt(out, value, fmt="%.17g")
    return out.getvalue().encode()


def as_npy(text: bytes) -> bytes:
    """The array the text shows (a field that is not a number is NaN, short rows are padded
    with NaN), saved as ``.npy``."""
    rows = []
    for line in text.split(b"\n"):
        fields = line.split()
        if fields:
            rows.append([_number(f) for f in fields[:64]])
    width = max((len(r) for r in rows), default=0)
    array = np.full((len(rows), width), np.nan)
    for k, row in enumerate(rows):
        array[k, : len(row)] = row
    out = io.BytesIO()
    np.save(out, array)
    return out.getvalue()


def _number(text: bytes) -> float:
    try:
        return float(text)
    except ValueError:
        return float("nan")


def read_raw_gnss_file(path: Path):
    """The array placed as ``<path>.d/processed_log/GNSS/raw_gnss_ublox/value``, read."""
    base = Path(f"{path}.d")
    folder = base.joinpath(*RAW_GNSS)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "value").write_bytes(path.read_bytes())
    return read_raw_gnss(base)


def check_raw_gnss(raw, path: Path) -> list[str]:
    bad = _bad_times(raw.t, "raw GNSS row", strictly=False)
    for letter in ("G", "R"):
        prn = raw.prn[raw.system == letter]
        low, high = PRN_RANGE[letter]
        if prn.size and (prn.min() < low or prn.max() > high):
            bad.append(f"{letter} number outside {low}–{high}")
    channel = raw.glonass_channel[raw.system == "R"]
    if channel.size and not ((channel >= -7) & (channel <= 6)).all():
        bad.append("GLONASS channel outside −7…6")
    if not (np.isfinite(raw.range_rate).all() and (np.abs(raw.range_rate) < 1.0e4).all()):
        bad.append("pseudorange rate not finite or beyond 10 km/s")
    if not (np.isfinite(raw.range_rate_sigma).all() and (raw.range_rate_sigma > 0).all()):
        bad.append("pseudorange rate σ not positive and finite")
    pseudorange = raw.pseudorange[~np.isnan(raw.pseudorange)]
    if pseudorange.size and not ((pseudorange > 1.0e6) & (pseudorange < 1.0e8)).all():
        bad.append("pseudorange outside 1,000–100,000 km")
    if raw.cn0.size and not ((raw.cn0 >= 0) & (raw.cn0 <= 100)).all():
        bad.append("C/N0 outside 0–100 dB-Hz")
    return bad


def register_gnss(register, family_cls, seed_cls, check_observations, check_navigation) -> None:
    """Register the families whose real seed files are present."""

    def seed(name: str, load: Callable[[], bytes], pack=None, suffix: str = ""):
        return (
            seed_cls(name, load, suffix=suffix)
            if pack is None
            else seed_cls(name, load, pack, suffix)
        )

    def family(name, present, seeds, read, check):
        if present:
            register(family_cls(name, seeds, read, check))

    sp3 = _shared(SP3)
    family("sp3", _present(SP3), lambda: [seed("Sta20124.sp3", sp3.read_bytes, suffix=".sp3")],
           read_sp3, check_sp3)  # fmt: skip
    family(
        "rinex-clock",
        _present(SP3),
        lambda: [seed("Sta20124 clocks.clk", clock_seed_text, suffix=".clk")],
        read_rinex_clock,
        check_clock,
    )
    family(
        "ubx",
        _present(f"{YAMATOGAWA}/yamatogawa_rover.obs", f"{YAMATOGAWA}/brdc0060.10n"),
        lambda: [seed("yamatogawa.ubx", ubx_seed, suffix=".ubx")],
        read_ubx,
        make_check_ubx(check_observations, check_navigation),
    )
    android = [f"{ANDROID}/gnss_log.txt", f"{ANDROID}/pixel6_gnsslogger.txt"]
    family(
        "android",
        _present(*android),
        lambda: [seed(Path(a).name, _shared(a).read_bytes, suffix=".txt") for a in android],
        read_gnsslogger,
        make_check_android(check_observations),
    )
    gsdc = f"{ANDROID}/device_gnss.csv"
    family(
        "gsdc",
        _present(gsdc),
        lambda: [seed("device_gnss.csv", _shared(gsdc).read_bytes, suffix=".csv")],
        read_device_gnss,
        make_check_gsdc(check_observations),
    )
    live = f"{COMMA}/processed_log/GNSS/live_gnss_ublox/value"
    family(
        "kitti-oxts",
        _present(live),
        lambda: [seed("comma2k19 fixes as OXTS", oxts_seed, suffix=".oxts")],
        read_oxts_bundle,
        check_oxts,
    )
    family(
        "comma-raw-gnss",
        _present(f"{COMMA}/{'/'.join(RAW_GNSS)}/value"),
        lambda: [seed("raw_gnss_ublox value", raw_gnss_seed, as_npy, ".npy")],
        read_raw_gnss_file,
        check_raw_gnss,
    )
