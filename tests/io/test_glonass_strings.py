"""GLONASS navigation strings (vo_doppler.io.glonass_strings): a receiver's strings decode to
the ephemeris that receiver reported; strings encoded from known values (tests/helpers, the
ICD's layout written out again) decode back exactly, also as a hypothesis property; the
Hamming check corrects every single data-bit error and refuses every double one; records that
cannot be one satellite's are refused with the reason."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from tests.helpers.glonass_strings import (
    EXAMPLE,
    SCALES,
    encode_strings,
    example_at,
    quantised,
    sfrbx_words,
    tb_quarter_hour,
)
from vo_doppler.io.glonass_strings import (
    GLONASS_NAMES,
    GlonassAssembler,
    check_string,
    decode_string,
    sfrbx_string,
    string_number,
)
from vo_doppler.model.gpstime import SECONDS_PER_WEEK

RECEIVER_STRINGS = (
    # strings 1–5 of slot 18 on 13 April 2016 as a NovAtel receiver logged them (GLORAWFRAME,
    # GPS week 1892, 300827 s; 3 padding bits first), published with libswiftnav's tests
    0x01074396999B05C3A850B5,
    0x021760A5256204D9C15F66,
    0x0380269D60899A6D0E3123,
    0x04865D1CC0000000344918,
    0x050D100000000340000895,
)
RECEIVER_EPHEMERIS = {  # the same receiver's GLOEPHEMERIS of them (m, m/s, m/s², s)
    "x": -1.4453039062500000e07,
    "y": -6.9681713867187500e06,
    "z": 1.9873773925781250e07,
    "vx": -1.4125013351440430e03,
    "vy": -2.3216266632080078e03,
    "vz": -1.8360681533813477e03,
    "ax": 0.0,
    "ay": 0.0,
    "az": -2.79396772384643555e-06,
    "minus_tau_n": 9.71024855971336365e-05,
    "gamma_n": 1.81898940354585648e-12,
}
WEEK = 2300
TOC = tb_quarter_hour(WEEK * SECONDS_PER_WEEK + 3 * 86400.0 + 10 * 3600.0)


def _assemble(strings, slot=5, channel=-3, reference=TOC, signal=0):
    assembler = GlonassAssembler(reference)
    for where, string in enumerate(strings):
        assembler.add(slot, channel, string, where, signal)
    return assembler


def test_a_receivers_strings_give_its_ephemeris():
    for number, string in enumerate(RECEIVER_STRINGS, start=1):
        assert check_string(string) == string and string_number(string) == number
    assert decode_string(RECEIVER_STRINGS[3])["nt"] == 31 + 29 + 31 + 13  # 13 April, leap year
    assembler = _assemble(RECEIVER_STRINGS, slot=18, channel=1, reference=1892 * SECONDS_PER_WEEK)
    assert assembler.rejected == []
    ((slot, toc, params, where),) = assembler.records
    assert slot == 18 and where == 3  # emitted at string 4
    assert toc == 1892 * SECONDS_PER_WEEK + 301517.0  # the receiver's toe: tb 59, 11:45 UTC
    assert params["frame_time"] == 300827.0 - 17.0  # the log's GPS time less the 17 leap seconds
    for name, value in RECEIVER_EPHEMERIS.items():
        assert params[name] == value, name
    assert params["health"] == 0.0 and params["channel"] == 1.0 and params["age"] == 0.0


def test_exact_round_trip_of_encoded_strings():
    params = example_at(TOC) | {"channel": -3.0}
    strings = encode_strings(5, TOC, params)
    assembler = _assemble(strings)
    ((slot, toc, back, _),) = assembler.records
    assert (slot, toc) == (5, TOC)
    assert back == quantised(params)
    assert back["minus_tau_n"] != params["minus_tau_n"]  # quantised: 2^-30 s
    records = assembler.navrecords()
    assert set(records.params) == set(GLONASS_NAMES) and records.system.tolist() == ["R"]
    assert math.isnan(records["status_flags"][0]) and records["urai"][0] == EXAMPLE["urai"]


@pytest.mark.parametrize(
    ("bn", "ln", "health"), [(0, 0, 0.0), (4, 0, 1.0), (3, 0, 0.0), (0, 1, 1.0), (7, 1, 1.0)]
)
def test_health_from_the_msb_of_bn_or_ln(bn, ln, health):
    params = example_at(TOC) | {"bn": bn, "ln": ln}
    assert _assemble(encode_strings(5, TOC, params)).records[0][2]["health"] == health


def test_sign_magnitude_numbers():
    params = example_at(TOC) | {"x": -1.0 * 2.0**-11 * 1000, "y": 20_000e3, "z": -17_000e3}
    strings = encode_strings(5, TOC, params)
    assert (strings[0] >> 34) & 1 == 1 and (strings[0] >> 8) & ((1 << 26) - 1) == 1
    assert decode_string(strings[0])["x"] == -0.48828125  # one LSB below zero, not −2^26 LSB


def test_single_errors_corrected_double_errors_refused():
    for string in encode_strings(5, TOC, example_at(TOC)) + list(RECEIVER_STRINGS):
        for bit in range(9, 86):
            assert check_string(string ^ (1 << (bit - 1))) == string, bit
        for bit in range(1, 8):  # a check bit hit: the data are right
            assert check_string(string ^ (1 << (bit - 1))) >> 8 == string >> 8
        assert check_string(string ^ (1 << 7)) is None  # cΣ alone: refused
        for a in range(85):
            for b in range(a + 1, 85, 7):
                assert check_string(string ^ (1 << a) ^ (1 << b)) is None, (a, b)


def test_sfrbx_words_hold_the_string():
    string = encode_strings(5, TOC, example_at(TOC))[1]
    words = sfrbx_words(string, superframe=3, frame=4)
    assert words[0] >> 31 == 0 and (words[0] >> 27) & 0xF == 2  # idle chip, string number
    assert words[2] & 0x7FF == 0 and sfrbx_string(words) == string


def test_the_day_from_nt_nearest_the_reference():
    """NT names a day of a four-year interval: any reference within two years finds it."""
    strings = encode_strings(5, TOC, example_at(TOC))
    for days in (-700, -1, 0, 3, 700):
        record = _assemble(strings, reference=TOC + days * 86400.0).records[0]
        assert record[1] == TOC, days
    wrong = _assemble(strings, reference=TOC + 800 * 86400.0).records[0]
    assert wrong[1] == TOC + 1461 * 86400.0


def test_frame_after_moscow_midnight_keeps_the_day_of_tb():
    """tb 23:45 Moscow, the frame at 00:05 the next day (whose date NT holds): tb is the day
    before the frame's."""
    toc = tb_quarter_hour(WEEK * SECONDS_PER_WEEK + 2 * 86400.0 + 20 * 3600.0 + 44 * 60.0)
    assert (toc - 18.0 + 3 * 3600.0) % 86400.0 == 23.75 * 3600.0
    params = example_at(toc, frame_before_s=-20 * 60.0)
    record = _assemble(encode_strings(5, toc, params), reference=toc).records[0]
    assert record[1] == toc and record[2]["frame_time"] == params["frame_time"]


def test_strings_must_follow_one_another():
    one, two, three, four = encode_strings(5, TOC, example_at(TOC))
    assert _assemble([one, two, four]).records == []
    assert _assemble([one, two, three, three, four]).records == []
    assert len(_assemble([two, one, two, three, four]).records) == 1
    broken = three ^ (1 << 40) ^ (1 << 41)
    refused = _assemble([one, two, broken, four])
    assert refused.records == [] and refused.rejected == [(2, 5, "string fails the Hamming check")]


def test_a_repeated_ephemeris_is_emitted_once_and_signals_kept_apart():
    l1 = encode_strings(5, TOC, example_at(TOC))
    assembler = GlonassAssembler(TOC)
    for where, string in enumerate(l1 * 3):  # three frames
        assembler.add(5, -3, string, where)
    assert len(assembler.records) == 1
    interleaved = GlonassAssembler(TOC)
    for where, (a, b) in enumerate(zip(l1, l1, strict=True)):
        interleaved.add(5, -3, a, where, signal=0)
        interleaved.add(5, -3, b, where, signal=2)
    assert len(interleaved.records) == 1 and interleaved.rejected == []
    later = tb_quarter_hour(TOC + 1)
    assembler.add(5, -3, 0, 99)  # a string of zeros passes the check: number 0, ignored
    for string in encode_strings(5, later, example_at(later)):
        assembler.add(5, -3, string, 100)
    assert [r[1] for r in assembler.records] == [TOC, later]


@pytest.mark.parametrize(
    ("change", "why"),
    [
        ({"slot": 6}, "string 4 is of slot 6"),
        ({"channel": 7}, "frequency number 7 outside -7…6"),
        ({"frame_before_s": 2 * 3600.0}, "tb 64 is 120 min from the frame time"),
        ({"x": 32_000e3}, "orbit radius 38964 km is no GLONASS orbit"),
        ({"vx": 5000.0}, "speed 5.74 km/s is no GLONASS orbit"),
    ],
)
def test_records_that_are_no_ephemeris_refused(change, why):
    toc = tb_quarter_hour(TOC + 3 * 3600.0)  # tb 64: 16:00 Moscow
    params = example_at(toc, change.get("frame_before_s", 900.0))
    params |= {k: v for k, v in change.items() if k in ("x", "vx")}
    strings = encode_strings(change.get("slot", 5), toc, params)
    assembler = _assemble(strings, slot=5, channel=change.get("channel", -3))
    assert assembler.records == [] and assembler.rejected == [(3, 5, why)]


def test_no_immediate_data_in_string_5():
    with pytest.raises(ValueError, match="string 5 holds no immediate data"):
        decode_string(RECEIVER_STRINGS[4])


_COMPONENT = st.floats(-1.0, 1.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@example(  # the first tb after the leap second of 2005-12-31 (GPS - UTC 13 -> 14 s)
    direction=(1.0, 0.0, 0.0),
    radius_km=25_500.0,
    velocity=(0.0, 0.0, 0.0),
    acceleration=(0.0, 0.0, 0.0),
    clock=(0.0, 0.0),
    days=1092,
    quarter=0,
    frame_before=0,
    slot=1,
    channel=0,
    age=0,
)
@given(
    direction=st.tuples(_COMPONENT, _COMPONENT, _COMPONENT).filter(
        lambda v: np.linalg.norm(v) > 0.1
    ),
    radius_km=st.floats(19_100.0, 31_000.0),
    velocity=st.tuples(*(st.floats(-2800.0, 2800.0),) * 3),
    acceleration=st.tuples(*(st.floats(-1.4e-5, 1.4e-5),) * 3),
    clock=st.tuples(st.floats(-1.9e-3, 1.9e-3), st.floats(-9.3e-10, 9.3e-10)),
    days=st.integers(0, 20 * 365),
    quarter=st.integers(0, 95),
    frame_before=st.integers(-60, 60),
    slot=st.integers(1, 24),
    channel=st.integers(-7, 6),
    age=st.integers(0, 31),
)
def test_round_trip_property(
    direction,
    radius_km,
    velocity,
    acceleration,
    clock,
    days,
    quarter,
    frame_before,
    slot,
    channel,
    age,
):
    """Any record the strings can carry comes back at its quantised values, on its day."""
    start = 1200 * SECONDS_PER_WEEK
    toc = tb_quarter_hour(start + days * 86400.0 + quarter * 900.0)
    unit = np.asarray(direction) / np.linalg.norm(direction)
    position = dict(zip("xyz", unit * radius_km * 1000.0, strict=True))
    params = example_at(toc, frame_before * 30.0) | position | {"age": float(age)}
    params |= dict(zip(("vx", "vy", "vz"), velocity, strict=True))
    params |= dict(zip(("ax", "ay", "az"), acceleration, strict=True))
    params |= {"minus_tau_n": clock[0], "gamma_n": clock[1], "channel": float(channel)}
    strings = encode_strings(slot, toc, params)
    assembler = _assemble(strings, slot=slot, channel=channel, reference=toc + 86400.0)
    assert assembler.rejected == []
    ((back_slot, back_toc, back, _),) = assembler.records
    assert (back_slot, back_toc) == (slot, toc)
    assert back == quantised(params)
    for name, lsb in SCALES.items():  # each within half its LSB of the value sent
        assert abs(back[name] - params[name]) <= 0.5 * lsb * (1 + 1e-9), name
