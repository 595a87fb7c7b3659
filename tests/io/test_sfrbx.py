"""RXM-SFRBX navigation data end to end (vo_doppler.io.sfrbx through the UBX reader and the ROS
bag reader): a UBX log of GPS, QZSS, Galileo and BeiDou navigation data encoded from known
ephemerides gives every satellite's ephemeris, whose satellite positions match the source
ephemeris' to 1 mm; the same messages in a ROS bag give the same records; refused and
undecoded messages are named by byte offset or message index. With the shared data, real
Galileo and BeiDou broadcast records (the Hong Kong F9P day's RINEX navigation files) come back
through pages and subframes with positions within 1 mm of the RINEX ones."""

from __future__ import annotations

import numpy as np
import pytest
from pyubx2 import UBXMessage

from tests.conftest import shared_data_dir
from tests.helpers import beidou_d1 as bds
from tests.helpers import galileo_inav as gal
from tests.helpers import lnav
from tests.helpers.rosbag_writer import SmallBag, bag_path, ublox_rawx, ublox_sfrbx
from vo_doppler.gnss.ephemeris import satellite_states
from vo_doppler.io.glonass_strings import GLONASS_NAMES
from vo_doppler.io.gps_lnav import KEPLER_NAMES
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rosbag_bag import Bag
from vo_doppler.io.rosbag_gnss import read_ublox
from vo_doppler.io.sfrbx import SfrbxMessage, decode_sfrbx
from vo_doppler.io.ubx import read_ubx
from vo_doppler.model.navigation import Navigation, NavRecords

W = 604800.0
WEEK, TOW = 2200, 345_012.0
T0 = WEEK * W + TOW
GST = T0 - 12.0
BDT_WN, BDT_SOW = WEEK - 1356, 344_982
"""BDT of BeiDou subframe 1: 44 s before T0 (BDT = GPST − 14 s), on a 6-s subframe start."""
QZSS = lnav.EXAMPLE | {"sqrt_a": 6493.25, "e": 0.075, "i0": 0.7191, "omega": 4.7e-1}
GALILEO = {
    11: gal.EXAMPLE | {"toe_sow": 345_600.0, "toc_sow": 345_600.0},
    26: gal.EXAMPLE | {"toe_sow": 345_600.0, "toc_sow": 345_600.0, "m0": -0.7, "omega0": 2.6},
}
BEIDOU = {
    21: bds.EXAMPLE | {"toe_sow": 345_600.0, "toc_sow": 345_600.0},
    38: bds.EXAMPLE
    | {"toe_sow": 345_600.0, "toc_sow": 345_600.0, "sqrt_a": 6493.4, "i0": 0.96, "m0": 0.4},
}
"""C21 a MEO satellite, C38 an IGSO one."""


def _rawx() -> bytes:
    return UBXMessage(
        "RXM", "RXM-RAWX", 0, rcvTow=TOW, week=WEEK, leapS=18, numMeas=1, version=1,
        prMes_01=21e6, doMes_01=0.0, gnssId_01=0, svId_01=9, cno_01=40, prValid_01=1,
    ).serialize()  # fmt: skip


def _galileo_pages() -> list[tuple[int, list[int]]]:
    return [
        (svid, gal.sfrbx_words(word))
        for svid, eph in GALILEO.items()
        for word in gal.encode_ephemeris(svid, eph, GST)
    ]


def _beidou_subframes() -> list[tuple[int, list[int]]]:
    return [
        (prn, words)
        for prn, eph in BEIDOU.items()
        for words in bds.encode_subframes(eph, BDT_WN, BDT_SOW)
    ]


def _log(bad_page: bool = True) -> tuple[bytes, dict[str, int]]:
    """The UBX log and the byte offsets of its notable messages."""
    out = _rawx()
    out += b"".join(lnav.sfrbx(9, w) for w in lnav.encode_ephemeris(lnav.EXAMPLE, 57_502))
    out += b"".join(lnav.sfrbx(1, w, gnss_id=5) for w in lnav.encode_ephemeris(QZSS, 57_502))
    where = {}
    if bad_page:
        where["bad page"] = len(out)
        word = gal.encode_word(1, GALILEO[11] | {"iode": 161})
        out += gal.ubx_sfrbx(11, gal.sfrbx_words(word, flip=40))
    out += b"".join(gal.ubx_sfrbx(svid, words) for svid, words in _galileo_pages())
    out += b"".join(bds.ubx_sfrbx(prn, words) for prn, words in _beidou_subframes())
    where["geo"] = len(out)
    out += bds.ubx_sfrbx(3, bds.encode_subframes(BEIDOU[21], BDT_WN, BDT_SOW)[0])
    return out, where


def _source() -> Navigation:
    """The ephemerides the log was encoded from, at the values the messages carry."""
    rows = []

    def add(system, prn, params, toc, toe):
        rows.append((system, prn, toc, params | {"toe": toe}))

    q = lnav.quantised(lnav.EXAMPLE)
    add("G", 9, q | {"health": 0.0}, WEEK * W + q["toc_sow"], WEEK * W + q["toe_sow"])
    q = lnav.quantised(QZSS)
    add("J", 1, q | {"health": 0.0}, WEEK * W + q["toc_sow"], WEEK * W + q["toe_sow"])
    for svid, eph in GALILEO.items():
        q = gal.quantised(eph)
        add("E", svid, q, WEEK * W + q["toc_sow"], WEEK * W + q["toe_sow"])
    for prn, eph in BEIDOU.items():
        q = bds.quantised(eph)
        add("C", prn, q, WEEK * W + q["toc_sow"] + 14.0, WEEK * W + q["toe_sow"] + 14.0)
    params = {
        name: np.array([p.get(name, 0.0) for *_, p in rows], dtype=float) for name in KEPLER_NAMES
    }
    kepler = NavRecords(
        np.array([s for s, *_ in rows]),
        np.array([p for _, p, *_ in rows], dtype=np.int16),
        np.array([t for _, _, t, _ in rows]),
        params,
        np.zeros(len(rows), dtype=np.int64),
    )
    return Navigation(kepler, _no_glonass())


def _no_glonass() -> NavRecords:
    empty = np.zeros(0)
    names = GLONASS_NAMES
    return NavRecords(
        empty.astype("U1"),
        empty.astype(np.int16),
        empty,
        dict.fromkeys(names, empty),
        empty.astype(np.int64),
    )


SATELLITES = [("G", 9), ("J", 1), ("E", 11), ("E", 26), ("C", 21), ("C", 38)]


def _positions_match(nav: Navigation, source: Navigation, limit_m: float) -> None:
    t = T0 + np.array([-3600.0, 0.0, 1800.0, 3600.0])
    for system, prn in SATELLITES:
        ours = satellite_states(nav, system, prn, t)
        theirs = satellite_states(source, system, prn, t)
        assert ours.valid.all() and theirs.valid.all(), (system, prn)
        error = np.linalg.norm(ours.position - theirs.position, axis=1)
        assert error.max() <= limit_m, (system, prn, error)
        np.testing.assert_allclose(ours.clock_bias_s, theirs.clock_bias_s, rtol=0, atol=1e-15)


def test_a_ubx_log_gives_every_systems_ephemerides_at_the_source_positions(tmp_path):
    data, where = _log()
    path = tmp_path / "log.ubx"
    path.write_bytes(data)
    recording = read_ubx(path)
    kepler = recording.navigation.kepler
    found = sorted(zip(kepler.system.tolist(), kepler.prn.tolist(), strict=True))
    assert found == sorted(SATELLITES)
    _positions_match(recording.navigation, _source(), 1e-3)
    c21 = np.flatnonzero((kepler.system == "C") & (kepler.prn == 21))[0]
    assert kepler.toc[c21] == WEEK * W + 345_600.0 + 14.0
    assert kepler["toe_sow"][c21] == 345_600.0 and kepler["week"][c21] == BDT_WN
    e11 = np.flatnonzero((kepler.system == "E") & (kepler.prn == 11))[0]
    assert kepler["week"][e11] == WEEK and kepler["codes"][e11] == 513.0
    problems = recording.problems
    assert (
        f"log.ubx, byte {where['bad page']}: 1 Galileo pages or ephemerides refused (the first: "
        "E11, page fails the CRC-24Q check)" in " ".join(problems)
    )
    assert any(
        "byte 0: navigation data not decoded (1 BeiDou GEO (D2) subframes)" in p for p in problems
    )


def test_a_ros_bag_of_the_same_messages_gives_the_same_records(tmp_path):
    data, _ = _log(bad_page=False)
    ubx_path = tmp_path / "log.ubx"
    ubx_path.write_bytes(data)
    from_ubx = read_ubx(ubx_path).navigation.kepler
    path = bag_path(tmp_path, "ros1", "sfrbx")
    meas = {"prMes": 21e6, "cpMes": 0.0, "doMes": 0.0, "gnssId": 0, "svId": 9, "sigId": 0}
    meas |= {"freqId": 0, "locktime": 1000, "cno": 40, "prStdev": 3, "cpStdev": 0}
    meas |= {"doStdev": 4, "trkStat": 1, "reserved3": 0}
    with SmallBag(path, "ros1") as bag:
        ublox_rawx(bag, T0, [meas])
        t = T0 + 1.0
        for w in lnav.encode_ephemeris(lnav.EXAMPLE, 57_502):
            ublox_sfrbx(bag, t, 0, 9, 0, lnav.with_parity(w))
        for w in lnav.encode_ephemeris(QZSS, 57_502):
            ublox_sfrbx(bag, t, 5, 1, 0, lnav.with_parity(w))
        for svid, words in _galileo_pages():
            ublox_sfrbx(bag, t, 2, svid, 0, words)
        for prn, words in _beidou_subframes():
            ublox_sfrbx(bag, t, 3, prn, 0, words)
        ublox_sfrbx(bag, t, 3, 3, 0, bds.encode_subframes(BEIDOU[21], BDT_WN, BDT_SOW)[0])
    with Bag(path) as bag:
        gnss = read_ublox(bag, "/ublox/rxmraw", "/ublox/rxmsfrb")
    records = {(r.system, r.prn): r for r in gnss.ephemerides}
    assert sorted(records) == sorted(SATELLITES)
    for k in range(len(from_ubx)):
        record = records[(str(from_ubx.system[k]), int(from_ubx.prn[k]))]
        bdt = -14.0 if record.system == "C" else 0.0  # RINEX writes BeiDou epochs on BDT
        assert record.toc == from_ubx.toc[k] + bdt
        for name, value in record.params.items():
            assert value == from_ubx[name][k], (record.system, record.prn, name)
    assert (
        "/ublox/rxmsfrb: navigation data not decoded (1 BeiDou GEO (D2) subframes): those "
        "satellites have no ephemeris in the sequence" in " ".join(gnss.problems)
    )


HK = "hk_tst_static_f9p"


def _real_records(nav: Navigation, system: str) -> list[int]:
    """One record per satellite of the system: the first of each."""
    kepler = nav.kepler
    first: dict[int, int] = {}
    for k in np.flatnonzero(kepler.system == system):
        first.setdefault(int(kepler.prn[k]), int(k))
    return sorted(first.values())


@pytest.mark.skipif(
    not (shared_data_dir() / HK / "hksc155c.20l").is_file(),
    reason=f"shared data {HK} (Galileo and BeiDou RINEX navigation files) not present",
)
def test_real_broadcast_records_come_back_through_pages_and_subframes(tmp_path):
    """Each Galileo and BeiDou satellite's first record of the day's RINEX files (real broadcast
    values) encoded as the satellite sent it, decoded from a UBX log: the satellite positions
    over ±1 h of toe are within 1 mm of the RINEX record's, the clocks within 1 ps."""
    source = read_nav([shared_data_dir() / HK / f"hksc155c.20{x}" for x in "lb"])
    kepler = source.kepler
    out = b""
    chosen = []
    for k in _real_records(source, "E"):
        eph = {name: float(kepler[name][k]) for name in kepler.params}
        gst = kepler["toe"][k] - 600.0
        eph |= {"toc_sow": float(kepler.toc[k] % W)}
        health = int(eph["health"])
        if health or eph["accuracy"] < 0:
            continue
        out += b"".join(
            gal.ubx_sfrbx(int(kepler.prn[k]), gal.sfrbx_words(w))
            for w in gal.encode_ephemeris(int(kepler.prn[k]), eph, gst)
        )
        chosen.append(k)
    for k in _real_records(source, "C"):
        prn = int(kepler.prn[k])
        if prn <= 5 or prn >= 59 or kepler["health"][k]:
            continue
        eph = {name: float(kepler[name][k]) for name in kepler.params}
        eph |= {"toc_sow": float((kepler.toc[k] - 14.0) % W)}
        sent = kepler["toe"][k] - 14.0 - 600.0
        wn, sow = int(sent // W) - 1356, int(sent % W) // 6 * 6
        out += b"".join(bds.ubx_sfrbx(prn, w) for w in bds.encode_subframes(eph, wn, sow))
        chosen.append(k)
    path = tmp_path / "real.ubx"
    path.write_bytes(out)
    nav = read_ubx(path).navigation
    assert len(nav.kepler) == len(chosen) >= 40  # 22 Galileo, 22 BeiDou MEO/IGSO
    for k in chosen:
        system, prn = str(kepler.system[k]), int(kepler.prn[k])
        t = kepler["toe"][k] + np.array([-3600.0, 0.0, 3600.0])
        ours = satellite_states(nav, system, prn, t)
        theirs = satellite_states(Navigation(kepler.subset([k]), source.glonass), system, prn, t)
        error = np.linalg.norm(ours.position - theirs.position, axis=1)
        assert error.max() <= 1e-3, (system, prn, error)
        np.testing.assert_allclose(ours.clock_bias_s, theirs.clock_bias_s, rtol=0, atol=1e-12)


def test_what_is_not_decoded_is_counted_by_kind():
    """A GPS L2C message and a 9-word BeiDou one are another signal or length of a decoded
    system; SBAS and NavIC have no decoder here and their satellites no ephemeris, which the
    problem says; BeiDou subframes 4–5 are almanac."""
    almanac = bds.almanac_subframe(4, BDT_SOW + 18)
    messages = [
        SfrbxMessage(10, 0, 5, 4, 0, tuple(range(10))),
        SfrbxMessage(11, 3, 21, 0, 0, tuple(range(9))),
        SfrbxMessage(12, 1, 131, 0, 0, tuple(range(8))),
        SfrbxMessage(13, 7, 2, 0, 0, tuple(range(10))),
        SfrbxMessage(14, 3, 21, 0, 0, tuple(almanac)),
    ]
    decoded = decode_sfrbx(messages, WEEK, T0)
    assert len(decoded.kepler) == len(decoded.glonass) == 0
    assert decoded.problems == (
        (
            None,
            "not decoded: 1 BeiDou almanac subframes 4-5, 1 BeiDou messages of other signals or "
            "lengths, 1 GPS messages of other signals or lengths",
        ),
        (
            None,
            "navigation data not decoded (1 NavIC messages, 1 SBAS messages): those satellites "
            "have no ephemeris in the sequence, so their measurements are not used; add a RINEX "
            "navigation file of the day for them",
        ),
    )
