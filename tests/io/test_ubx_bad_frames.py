"""UBX frames with a valid checksum and an impossible content: an empty RXM-RAWX or NAV-PVT
payload, a NAV-PVT speed of 900 km/s, GPS satellite 254, a subframe with one flipped bit, an
ephemeris off any GPS orbit. Each is skipped with a problem naming the file and the byte offset
(or, when nothing usable is left, an InputError naming the file), never an AttributeError.

The minimal files of ../shared/data/bad_inputs_found are read when present; the synthetic
streams below cover the same classes without them."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pyubx2 import UBXMessage

from tests.conftest import shared_data_dir
from tests.helpers.lnav import EXAMPLE, encode_ephemeris, sfrbx, with_parity
from tests.io.test_ubx import TOW, WEEK, pvt, rawx, write
from vo_doppler.errors import InputError
from vo_doppler.io.gps_lnav import lnav_parity, parity_error
from vo_doppler.io.ubx import checksum, read_ubx

BAD = "bad_inputs_found"


def frame(cls: int, mid: int, payload: bytes) -> bytes:
    """A UBX frame with a valid checksum around any payload."""
    body = bytes((cls, mid)) + len(payload).to_bytes(2, "little") + payload
    return b"\xb5\x62" + body + checksum(body)


EMPTY_RAWX, EMPTY_PVT = frame(0x02, 0x15, b""), frame(0x01, 0x07, b"")


def pvt_fast(north_mm_s: int = 900_000_000) -> bytes:
    return UBXMessage(
        "NAV", "NAV-PVT", 0, iTOW=int((TOW + 1.0) * 1000), year=2022, month=3, day=9, hour=23,
        min=59, second=55, nano=250_000_000, validDate=1, validTime=1, fullyResolved=1,
        fixType=3, gnssFixOk=1, numSV=12, lon=11.58, lat=48.13, height=519_321, hMSL=471_000,
        hAcc=1520, vAcc=2250, velN=north_mm_s, velE=0, velD=0, gSpeed=abs(north_mm_s),
        headMot=0.0, sAcc=85, headAcc=0.75,
    ).serialize()  # fmt: skip


def rawx_with(sv: int) -> bytes:
    """GPS 5 and GPS ``sv`` L1 C/A in one epoch."""
    return UBXMessage(
        "RXM", "RXM-RAWX", 0, rcvTow=TOW, week=WEEK, leapS=18, numMeas=2, version=1,
        prMes_01=21_234_567.891, doMes_01=-1234.5, gnssId_01=0, svId_01=5, sigId_01=0,
        cno_01=45, prValid_01=1,
        prMes_02=22_000_000.0, doMes_02=100.0, gnssId_02=0, svId_02=sv, sigId_02=0, cno_02=40,
        prValid_02=1,
    ).serialize()  # fmt: skip


@pytest.mark.parametrize(
    "name", ["empty_rawx.ubx", "empty_pvt.ubx", "pvt_900km_s.ubx", "rawx_G254.ubx"]
)
def test_the_shared_minimal_files_are_input_errors_naming_the_file(name, caplog):
    """Each holds one bad frame and nothing else: nothing usable is left."""
    path = shared_data_dir() / BAD / name
    if not path.is_file():
        pytest.skip(f"{path} absent")
    with pytest.raises(InputError) as caught:
        read_ubx(path)
    assert str(path) in str(caught.value)
    assert all(str(path) in r.getMessage() for r in caplog.records)


@pytest.mark.parametrize("empty", [EMPTY_RAWX, EMPTY_PVT, frame(0x02, 0x13, b"")])
def test_an_empty_payload_with_a_valid_checksum_is_skipped_at_its_offset(tmp_path, empty):
    good = rawx(TOW) + pvt()
    path = write(tmp_path, good + empty + rawx(TOW + 1.0))
    recording = read_ubx(path)
    assert recording.observations.epoch_time.size == 2
    assert len(recording.solution) == 1
    assert any(
        p.startswith(f"{path}, byte {len(good)}: ") and "payload of 0 bytes" in p
        for p in recording.problems
    )


def test_a_payload_shorter_than_its_count_announces_is_skipped(tmp_path):
    short = frame(0x02, 0x15, rawx(TOW)[6:-2][:-32])  # numMeas 3, two measurements
    path = write(tmp_path, pvt() + short)
    recording = read_ubx(path)
    assert recording.observations is None
    assert any("RXM-RAWX payload of 80 bytes, expected 112" in p for p in recording.problems)


@pytest.mark.parametrize("north_mm_s", [900_000_000, -200_000, 151_000])
def test_a_fix_faster_than_any_vehicle_is_skipped(tmp_path, north_mm_s):
    path = write(tmp_path, pvt() + pvt_fast(north_mm_s))
    recording = read_ubx(path)
    assert len(recording.solution) == 1
    assert np.abs(recording.solution.velocity_ned).max() < 150.0
    assert any(f"byte {len(pvt())}: NAV-PVT velocity" in p for p in recording.problems)


@pytest.mark.parametrize("sv", [0, 33, 254])
def test_a_gps_satellite_number_outside_1_to_32_is_dropped(tmp_path, sv):
    recording = read_ubx(write(tmp_path, rawx_with(sv)))
    obs = recording.observations
    assert set(obs.prn.tolist()) == {5}
    assert any("unknown kind or satellite number" in p for p in recording.problems)


def test_lnav_parity_of_known_words():
    """A word of all-zero data after D29* = D30* = 0 has zero parity; after D30* = 1 the bits
    with D30* in their equation (D26, D28, D29) are set; every single data bit changes at
    least one parity bit (the code's distance is 4)."""
    assert lnav_parity(0, 0, 0) == 0
    assert lnav_parity(0, 0, 1) == 0b010110
    assert lnav_parity(0, 1, 0) == 0b101001
    assert all(lnav_parity(1 << k, 0, 0) for k in range(24))


def _ephemeris_stream(flip_subframe: int | None = None, flip: int | None = None, **eph) -> bytes:
    subframes = encode_ephemeris({**EXAMPLE, **eph}, 57599)
    frames = [
        sfrbx(9, words, flip if k == flip_subframe else None) for k, words in enumerate(subframes)
    ]
    week_source = UBXMessage(
        "RXM", "RXM-RAWX", 0, rcvTow=345_600.0, week=EXAMPLE["week"], leapS=18, numMeas=1,
        version=1, prMes_01=21e6, doMes_01=0.0, gnssId_01=0, svId_01=9, cno_01=40, prValid_01=1,
    ).serialize()  # fmt: skip
    return week_source + b"".join(frames)


def test_the_unflipped_ephemeris_is_decoded(tmp_path):
    recording = read_ubx(write(tmp_path, _ephemeris_stream()))
    assert len(recording.navigation.kepler) == 1


@settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(subframe=st.integers(0, 2), bit=st.integers(0, 299))
def test_one_flipped_bit_fails_the_parity_check_and_no_ephemeris_is_made(tmp_path, subframe, bit):
    data = _ephemeris_stream(subframe, bit)
    recording = read_ubx(write(tmp_path, data))
    assert len(recording.navigation.kepler) == 0
    assert any("fails the LNAV parity check" in p for p in recording.problems)


def test_parity_error_names_the_word():
    words = list(with_parity(encode_ephemeris(EXAMPLE, 57599)[1]))
    assert parity_error(tuple(words)) is None
    words[4] ^= 1 << 12
    assert parity_error(tuple(words)) == 5


@pytest.mark.parametrize(
    "change", [{"sqrt_a": 6000.0}, {"sqrt_a": 4000.0}, {"e": 0.3}, {"i0": 0.2}]
)
def test_an_ephemeris_with_valid_parity_off_any_gps_orbit_is_skipped(tmp_path, change):
    recording = read_ubx(write(tmp_path, _ephemeris_stream(**change)))
    assert len(recording.navigation.kepler) == 0
    name = next(iter(change))
    assert any(f"off any GPS orbit: {name} = " in p for p in recording.problems)
