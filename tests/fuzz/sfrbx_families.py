"""Fuzz families of the RXM-SFRBX navigation-data decoders (issue 31): UBX logs of one RXM-RAWX
epoch and the navigation data of Galileo (``ubx-inav``: I/NAV pages of words 0–5, an alert page)
or BeiDou (``ubx-bds-d1``: D1 subframes 1–5 of MEO/IGSO satellites, a GEO satellite's D2
subframe), encoded from the Hong Kong F9P day's real broadcast records (its RINEX navigation
files) or, without the shared data, from the test helpers' records. Mutated as ``ubx-frames`` is
(frame contents changed, checksums made valid again: bits flipped in the words, fields set to
extreme patterns, satellite numbers changed, payloads cut) and as bytes. A successful read may
hold only ephemerides that pass the UBX family's checks and lie on their system's orbits.

Registered by ``families.py`` with one line::

    register_sfrbx(register, Family, Seed, check_observations, check_navigation)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from pyubx2 import UBXMessage

from tests.conftest import shared_data_dir
from tests.fuzz.bound_families import UBX_MUTATIONS, check_ubx_bounds
from tests.fuzz.gnss_families import make_check_ubx
from tests.helpers import beidou_d1 as bds
from tests.helpers import galileo_inav as gal
from vo_doppler.bounds import (
    BEIDOU_ECCENTRICITY,
    BEIDOU_INCLINATION,
    BEIDOU_SQRT_A,
    GALILEO_ECCENTRICITY,
    GALILEO_INCLINATION,
    GALILEO_SQRT_A,
)
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.ubx import read_ubx

HK = "hk_tst_static_f9p"
W = 604800.0
SATELLITES = 8
"""Satellites per seed (the first records of the day's file)."""


def _real(suffix: str):
    """The first record of each satellite of the day's RINEX file (None without it)."""
    path = shared_data_dir() / HK / f"hksc155c.20{suffix}"
    if not path.is_file():
        return None
    kepler = read_nav(path).kepler
    first: dict[int, int] = {}
    for k in range(len(kepler)):
        first.setdefault(int(kepler.prn[k]), k)
    return kepler, sorted(first.values())


def _rawx(t: float) -> bytes:
    week, tow = divmod(t, W)
    return UBXMessage(
        "RXM", "RXM-RAWX", 0, rcvTow=tow, week=int(week), leapS=18, numMeas=1, version=1,
        prMes_01=21e6, doMes_01=-500.0, gnssId_01=0, svId_01=9, cno_01=40, prValid_01=1,
    ).serialize()  # fmt: skip


def _records(suffix: str, example: dict, first: int, sent: float, keep, offset: float) -> list:
    """(satellite number, RINEX parameters with ``toc_sow`` on the system's time, the system
    time of the message sending them) of each satellite ``keep`` accepts: the first records of
    the day's file ``suffix``, else ``example`` moved along its orbit, sent at ``sent``;
    ``offset`` the system time minus GPS time (s)."""
    real = _real(suffix)
    if real is None:
        return [
            (first + k, example | {"m0": 0.7 * k - 3.0, "omega0": -0.3 * k}, sent)
            for k in range(SATELLITES)
        ]
    kepler, rows = real
    out = []
    for k in rows:
        number = int(kepler.prn[k])
        if keep(number) and len(out) < SATELLITES:
            eph = {name: float(v[k]) for name, v in kepler.params.items()}
            eph |= {"toc_sow": float((kepler.toc[k] + offset) % W)}
            out.append((number, eph, float(kepler["toe"][k]) + offset - 600.0))
    return out


def _with_epochs(t0: float, frames: list[bytes]) -> bytes:
    """The navigation frames with a RAWX epoch a second before every satellite's (the epochs
    in order: reordering mutations make the log go back in time, an error)."""
    out = b""
    for k, start in enumerate(range(0, len(frames), len(frames) // SATELLITES)):
        out += _rawx(t0 + k) + b"".join(frames[start : start + len(frames) // SATELLITES])
    return out


def inav_seed() -> bytes:
    """RAWX epochs, words 1–5 and 0 of each satellite's record (E1-B and E5b pages), and an
    alert page."""
    records = _records("l", gal.EXAMPLE, 1, 2357 * W + 439_000.0, lambda svid: True, 0.0)
    frames = []
    for svid, eph, gst in records:
        words = gal.encode_ephemeris(svid, eph, gst)
        words.append(gal.encode_word(0, {"time": 2, "wn": int(gst // W) - 1024, "tow": gst % W}))
        sig_id = 1 + 4 * (svid % 2)
        frames += [gal.ubx_sfrbx(svid, gal.sfrbx_words(w), sig_id=sig_id) for w in words]
    alert = gal.ubx_sfrbx(records[0][0], gal.sfrbx_words(words[0], alert=True))
    return _with_epochs(records[0][2], frames) + alert


def bds_seed() -> bytes:
    """RAWX epochs, subframes 1–5 of each satellite's frame, and a GEO satellite's subframe."""
    records = _records(
        "b", bds.EXAMPLE, 6, 1001 * W + 446_100.0, lambda prn: 6 <= prn <= 58, -14.0 - 1356 * W
    )
    frames = []
    for prn, eph, sent in records:
        wn, sow = int(sent // W), int(sent % W) // 6 * 6
        subframes = bds.encode_subframes(eph, wn, sow)
        subframes += [bds.almanac_subframe(n, sow + 6 * (n - 1)) for n in (4, 5)]
        frames += [bds.ubx_sfrbx(prn, words, sig_id=0) for words in subframes]
    geo = bds.ubx_sfrbx(3, subframes[0], sig_id=1)
    return _with_epochs(records[0][2] + 1356 * W + 14.0, frames) + geo


ORBITS = {
    "E": (GALILEO_SQRT_A, GALILEO_ECCENTRICITY, GALILEO_INCLINATION),
    "C": (BEIDOU_SQRT_A, BEIDOU_ECCENTRICITY, BEIDOU_INCLINATION),
}


def check_orbits(recording, path: Path) -> list[str]:
    """Galileo and BeiDou records on their system's orbits, their toe on their second of week."""
    kepler = recording.navigation.kepler
    bad = []
    for system, bounds in ORBITS.items():
        rows = kepler.system == system
        for name, limits in zip(("sqrt_a", "e", "i0"), bounds, strict=True):
            if limits.outside(kepler.params[name][rows]).any():
                bad.append(f"{system} {name} outside {limits}")
    shift = np.where(kepler.system == "C", 14.0, 0.0)
    if not np.array_equal((kepler["toe"] - shift) % W, kepler["toe_sow"]):
        bad.append("toe not on its second of week")
    return bad


def register_sfrbx(register, family_cls, seed_cls, check_observations, check_navigation) -> None:
    """Register ``ubx-inav`` and ``ubx-bds-d1``."""
    check_ubx = make_check_ubx(check_observations, check_navigation)

    def check(recording, path: Path) -> list[str]:
        found = check_ubx(recording, path) + check_ubx_bounds(recording, path)
        return found + check_orbits(recording, path)

    for name, seed in (("ubx-inav", inav_seed), ("ubx-bds-d1", bds_seed)):
        register(
            family_cls(
                name,
                lambda seed=seed, name=name: [seed_cls(f"{name}.ubx", seed, suffix=".ubx")],
                read_ubx,
                check,
                mutations=dict(UBX_MUTATIONS),
            )
        )
