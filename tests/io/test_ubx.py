"""UBX reader: messages built with pyubx2's own constructors, values round-tripped exactly;
corrupted streams give the project's error or skipped-frame messages with byte offsets."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pyubx2 import UBXMessage

from tests.helpers import glonass_strings as glo
from tests.helpers.lnav import EXAMPLE, encode_ephemeris, quantised, sfrbx
from vo_doppler.errors import InputError
from vo_doppler.gnss.ephemeris import satellite_states
from vo_doppler.io.ubx import read_ubx

WEEK = 2200
TOW = 345612.25


def rawx(tow: float, locktime: int = 5000, half_cycle: int = 1) -> bytes:
    """Three signals: GPS 5 L1 C/A (all valid), Galileo 11 E5a Q (no carrier), GLONASS 3 L1."""
    return UBXMessage(
        "RXM", "RXM-RAWX", 0, rcvTow=tow, week=WEEK, leapS=18, numMeas=3, version=1,
        prMes_01=21_234_567.891, cpMes_01=111_590_123.4567, doMes_01=-1234.5,
        gnssId_01=0, svId_01=5, sigId_01=0, locktime_01=locktime, cno_01=45,
        prStd_01=3, cpStd_01=2, doStd_01=4, prValid_01=1, cpValid_01=1, halfCyc_01=half_cycle,
        prMes_02=23_456_789.125, doMes_02=250.75, gnssId_02=2, svId_02=11, sigId_02=4,
        cno_02=38, prStd_02=5, doStd_02=6, prValid_02=1,
        prMes_03=20_111_222.5, cpMes_03=107_500_000.25, doMes_03=-3000.0, gnssId_03=6,
        svId_03=3, sigId_03=0, freqId_03=2, cno_03=41, prValid_03=1, cpValid_03=1, halfCyc_03=1,
        locktime_03=64500,
    ).serialize()  # fmt: skip


def pvt() -> bytes:
    return UBXMessage(
        "NAV", "NAV-PVT", 0, iTOW=int(TOW * 1000), year=2022, month=3, day=9, hour=23,
        min=59, second=54, nano=250_000_000, validDate=1, validTime=1, fullyResolved=1,
        fixType=3, gnssFixOk=1, numSV=12, lon=11.5820513, lat=48.1351253, height=519_321,
        hMSL=471_000, hAcc=1520, vAcc=2250, velN=12_340, velE=-5_670, velD=120, gSpeed=13_580,
        headMot=335.75, sAcc=85, headAcc=0.75,
    ).serialize()  # fmt: skip


def write(tmp_path: Path, data: bytes) -> Path:
    path = tmp_path / "log.ubx"
    path.write_bytes(data)
    return path


def test_rawx_values_round_trip_exactly(tmp_path):
    data = b"$GPGGA,not ubx*00\r\n" + rawx(TOW) + rawx(TOW + 1.0, locktime=300, half_cycle=0)
    recording = read_ubx(write(tmp_path, data))
    obs = recording.observations
    t0 = WEEK * 604800.0 + TOW
    np.testing.assert_array_equal(obs.epoch_time, [t0, t0 + 1.0])
    first = obs.subset(obs.time == t0)

    def value(system, prn, code):
        rows = (first.system == system) & (first.prn == prn) & first.mask(code=code)
        assert rows.sum() == 1, (system, prn, code)
        return first.value[rows][0]

    assert value("G", 5, "C1C") == 21_234_567.891
    assert value("G", 5, "L1C") == 111_590_123.4567
    assert value("G", 5, "D1C") == -1234.5
    assert value("G", 5, "S1C") == 45.0
    assert value("E", 11, "C5Q") == 23_456_789.125
    assert value("E", 11, "D5Q") == 250.75
    assert value("R", 3, "L1C") == 107_500_000.25
    assert "L5Q" not in obs.codes_of("E")
    assert obs.header.glonass_channels == {3: -5}
    assert recording.problems and "19 bytes outside UBX frames" in recording.problems[-1]
    sigma = recording.sigma.at([t0, t0, t0], ["G", "G", "G"], [5, 5, 5], ["C1C", "L1C", "D1C"])
    np.testing.assert_allclose(sigma, [0.01 * 2**3, 0.004 * 2, 0.002 * 2**4], rtol=1e-15)


def test_lli_from_lock_time_and_half_cycle(tmp_path):
    recording = read_ubx(write(tmp_path, rawx(TOW) + rawx(TOW + 1.0, locktime=300, half_cycle=0)))
    obs = recording.observations.select("G", "L1C")
    np.testing.assert_array_equal(obs.lli, [0, 1 | 2])
    glonass = recording.observations.select("R", "L1C")
    np.testing.assert_array_equal(glonass.lli, [0, 0])


def test_nav_pvt_becomes_the_receiver_solution(tmp_path):
    solution = read_ubx(write(tmp_path, pvt())).solution
    assert len(solution) == 1
    # 2022-03-09 23:59:54.25 UTC + 18 s = Thursday 2022-03-10 00:00:12.25 GPST, week 2200
    assert solution.t[0] == WEEK * 604800.0 + TOW
    assert solution.lat[0] == pytest.approx(np.radians(48.1351253), abs=1e-15)
    assert solution.lon[0] == pytest.approx(np.radians(11.5820513), abs=1e-15)
    assert solution.height[0] == 519.321
    np.testing.assert_array_equal(solution.velocity_ned[0], [12.34, -5.67, 0.12])
    assert solution.speed[0] == 13.58
    assert solution.course[0] == pytest.approx(np.radians(335.75), abs=1e-12)
    assert solution.speed_accuracy[0] == 0.085
    assert solution.course_accuracy[0] == pytest.approx(np.radians(0.75), abs=1e-12)
    assert (solution.horizontal_accuracy[0], solution.vertical_accuracy[0]) == (1.52, 2.25)
    assert solution.fix_ok[0] and solution.n_sat[0] == 12


def test_sfrbx_subframes_give_the_ephemeris_and_its_orbit(tmp_path):
    subframes = encode_ephemeris(EXAMPLE, 57599)
    data = rawx(TOW) + b"".join(sfrbx(9, words) for words in subframes)
    nav = read_ubx(write(tmp_path, data)).navigation
    assert len(nav.kepler) == 1 and nav.kepler.prn[0] == 9
    expected = quantised(EXAMPLE)
    for name in ("m0", "sqrt_a", "e", "omega0", "i0", "omega", "af0", "af1", "idot"):
        assert nav.kepler[name][0] == expected[name], name
    t = WEEK * 604800.0 + 345600.0 + np.array([-3600.0, 0.0, 5400.0])
    states = satellite_states(nav, "G", 9, t)
    assert states.valid.all()
    radius = np.linalg.norm(states.position, axis=1)
    assert np.all(np.abs(radius - expected["sqrt_a"] ** 2) < 0.02 * expected["sqrt_a"] ** 2)
    speed = np.linalg.norm(states.velocity, axis=1)
    assert np.all((speed > 2500.0) & (speed < 4000.0))


def test_glonass_strings_give_the_ephemeris_and_its_orbit(tmp_path):
    """Strings 1–4 of R03 (channel −5, as RXM-RAWX tracks it) in RXM-SFRBX messages: one record
    at the values the strings carry, tb on its GPS time; a string whose check fails is named
    by its byte offset and the satellite is taken from its next frame."""
    toc = glo.tb_quarter_hour(WEEK * 604800.0 + TOW)
    params = glo.example_at(toc) | {"channel": -5.0}
    strings = glo.encode_strings(3, toc, params)
    broken = glo.ubx_sfrbx(3, -5, strings[1] ^ 0b11 << 30)
    frames = [glo.ubx_sfrbx(3, -5, s) for s in strings]
    data = rawx(TOW) + frames[0] + broken + b"".join(frames[2:]) + b"".join(frames)
    recording = read_ubx(write(tmp_path, data))
    glonass = recording.navigation.glonass
    assert glonass.prn.tolist() == [3] and glonass.toc.tolist() == [toc]
    assert glonass.line[0] == len(rawx(TOW)) + 2 * len(frames[0]) + 5 * len(frames[0])
    for name, value in glo.quantised(params).items():
        assert glonass[name][0] == value, name
    offset = len(rawx(TOW)) + len(frames[0])
    assert any(
        f"byte {offset}: 1 GLONASS strings or ephemerides refused (the first: R03, string "
        "fails the Hamming check)" in p
        for p in recording.problems
    )
    t = toc + np.array([-900.0, 0.0, 900.0])
    states = satellite_states(recording.navigation, "R", 3, t)
    assert states.valid.all()
    radius = np.linalg.norm(states.position, axis=1)
    np.testing.assert_allclose(radius, np.linalg.norm([params[a] for a in "xyz"]), rtol=2e-3)


def test_glonass_strings_without_a_gps_time_are_named(tmp_path):
    toc = glo.tb_quarter_hour(WEEK * 604800.0 + TOW)
    strings = glo.encode_strings(3, toc, glo.example_at(toc))
    recording = read_ubx(write(tmp_path, b"".join(glo.ubx_sfrbx(3, -5, s) for s in strings)))
    assert len(recording.navigation.glonass) == 0
    assert "byte 0: GLONASS strings without a GPS time: not decoded" in recording.problems[0]


def test_nav_pvt_whose_utc_disagrees_with_itow_is_skipped(tmp_path):
    message = UBXMessage(
        "NAV",
        "NAV-PVT",
        0,
        iTOW=int(TOW * 1000),
        year=2022,
        month=3,
        day=10,
        hour=23,
        min=59,
        second=54,
        nano=250_000_000,
        validDate=1,
        validTime=1,
    )
    recording = read_ubx(write(tmp_path, rawx(TOW) + message.serialize()))
    assert len(recording.solution) == 0
    assert any(f"log.ubx, byte {len(rawx(TOW))}: NAV-PVT iTOW" in p for p in recording.problems)


def test_file_without_wanted_messages_is_an_input_error(tmp_path):
    other = UBXMessage("NAV", "NAV-CLOCK", 0, iTOW=1000, clkB=5).serialize()
    with pytest.raises(InputError, match="no UBX RXM-RAWX"):
        read_ubx(write(tmp_path, other))
    with pytest.raises(InputError, match="no UBX RXM-RAWX"):
        read_ubx(write(tmp_path, b"\x00" * 64))


def test_epochs_going_back_are_an_error_naming_the_offset(tmp_path):
    first = rawx(TOW)
    with pytest.raises(InputError) as info:
        read_ubx(write(tmp_path, first + rawx(TOW - 1.0)))
    assert f"log.ubx, byte {len(first)}: " in str(info.value)


def test_bad_checksum_frame_is_skipped_and_named(tmp_path):
    good, bad = rawx(TOW), bytearray(rawx(TOW + 1.0))
    bad[20] ^= 0x40
    recording = read_ubx(write(tmp_path, good + bytes(bad) + rawx(TOW + 2.0)))
    assert recording.observations.epoch_time.size == 2
    assert any(f"log.ubx, byte {len(good)}: UBX checksum mismatch" in p for p in recording.problems)


STREAM = rawx(TOW) + pvt() + b"".join(sfrbx(9, w) for w in encode_ephemeris(EXAMPLE, 57599))


@settings(
    max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    cuts=st.lists(st.integers(0, len(STREAM) - 1), min_size=1, max_size=6),
    flips=st.lists(st.tuples(st.integers(0, len(STREAM) - 1), st.integers(1, 255)), max_size=6),
    truncate=st.integers(0, len(STREAM)),
)
def test_corrupted_streams_fail_only_with_input_errors(tmp_path, cuts, flips, truncate):
    data = bytearray(STREAM)
    for position, mask in flips:
        data[position] ^= mask
    for position in sorted(set(cuts), reverse=True):
        del data[position : position + 3]
    data = bytes(data[:truncate])
    try:
        recording = read_ubx(write(tmp_path, data))
    except InputError as exc:
        assert "log.ubx" in str(exc)
        return
    for problem in recording.problems:
        assert "log.ubx, byte " in problem
    if recording.observations is not None:
        assert np.all(np.isfinite(recording.observations.value))


def test_out_of_range_values_are_dropped_and_counted(tmp_path):
    message = UBXMessage(
        "RXM", "RXM-RAWX", 0, rcvTow=TOW, week=WEEK, numMeas=1, version=1, prMes_01=float("nan"),
        doMes_01=2.0e6, gnssId_01=0, svId_01=5, cno_01=45, prValid_01=1,
    ).serialize()  # fmt: skip
    recording = read_ubx(write(tmp_path, message))
    assert recording.observations.codes == ("S1C",)
    assert any("2 RXM-RAWX values out of range" in p for p in recording.problems)
