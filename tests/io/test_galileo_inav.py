"""Galileo I/NAV pages (vo_doppler.io.galileo_inav): words encoded from known values
(tests/helpers, the ICD's bit positions written out again) decode back exactly at the words'
quantisation, also as a hypothesis property over valid ephemerides; a page failing the CRC is
refused and counted; words of different IODnav are never combined; the record holds the RINEX
names, the full toe/toc on GPS time and the health, data-source and SISA conventions."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.helpers.galileo_inav import (
    EXAMPLE,
    KEPLER_SCALED,
    SCALES,
    crc24q,
    encode_ephemeris,
    encode_word,
    quantised,
    sfrbx_words,
)
from tests.helpers.nav_grid import grid, kepler_strategy
from vo_doppler.io import galileo_inav as inav
from vo_doppler.io.galileo_inav import InavAssembler, decode_word, sisa_metres

SECONDS_PER_WEEK = 604800.0
GST = 2357 * SECONDS_PER_WEEK + 439_000.0
"""GPS time of the word 5 sent (GST week 1333, 200 s before toe)."""


def _assemble(words: list[int], svid: int = 11, signal: int = inav.E1B) -> InavAssembler:
    assembler = InavAssembler()
    for k, word in enumerate(words):
        assembler.add(svid, signal, sfrbx_words(word), 100 + k)
    return assembler


def test_the_crc_is_crc24q_on_its_check_vector():
    """CRC-24Q of the ASCII digits 1…9 is 0xCDE703 (the code's published check value), by the
    decoder's table and by the helper's polynomial division."""
    digits = int.from_bytes(b"123456789", "big")
    assert inav.crc24q(digits, 72) == 0xCDE703
    assert crc24q([(digits >> (71 - k)) & 1 for k in range(72)]) == 0xCDE703


def test_a_page_pair_gives_back_its_word():
    word = encode_word(3, quantised(EXAMPLE) | {"iode": 161, "sisa": 107})
    even, odd = inav.sfrbx_page(sfrbx_words(word))
    assert inav.page_problem(even, odd) is None and not inav.is_alert(even, odd)
    assert inav.page_word(even, odd) == word


@pytest.mark.parametrize("number", [1, 2, 3, 4, 5])
def test_each_word_decodes_to_its_values_within_half_an_lsb(number):
    values = EXAMPLE | {"svid": 11, "sisa": 107, "wn": 1333, "tow": 439_000, "e1b_hs": 0}
    values |= {"e5b_hs": 0, "e1b_dvs": 0, "e5b_dvs": 0}
    fields = decode_word(encode_word(number, values))
    assert fields["type"] == number
    expected = quantised(EXAMPLE)
    renamed = {"bgd_e5a": "tgd", "bgd_e5b": "iodc", "iodnav": "iode"}
    for name, value in fields.items():
        source = renamed.get(name, name)
        if source in KEPLER_SCALED:
            assert value == expected[source], name
            assert abs(value - EXAMPLE[source]) <= SCALES[source] / 2, name


def test_words_1_to_5_make_one_record_with_rinex_names_and_gps_times():
    assembler = _assemble(encode_ephemeris(11, EXAMPLE, GST))
    assert assembler.rejected == [] and len(assembler.records) == 1
    record = assembler.records[0]
    for name, value in quantised(EXAMPLE).items():
        if name in KEPLER_SCALED and name != "toe_sow":
            assert record[name] == value, name
    week = 2357 * SECONDS_PER_WEEK
    assert record["toe"] == week + 439_200.0 and record["toc"] == week + 439_200.0
    assert record["toe_sow"] == 439_200.0 and record["week"] == 2357.0
    assert record["iode"] == 161.0 and record["prn"] == 11.0 and record["where"] == 104.0
    assert record["codes"] == 513.0  # E1-B pages, clock for E5b/E1
    assert record["accuracy"] == pytest.approx(3.12, abs=1e-12)  # SISA index 107
    assert record["transmission_sow"] == 439_000.0 and record["health"] == 0.0
    records = assembler.navrecords()
    assert records.system.tolist() == ["E"] and records.toc.tolist() == [week + 439_200.0]


def test_a_record_near_the_week_start_takes_the_week_of_its_toe():
    """toe 1 min into a week, word 5 sent 2 min before it (the previous week): the record's
    week and full toe are those of the next week."""
    gst = 2357 * SECONDS_PER_WEEK - 60.0
    eph = EXAMPLE | {"toe_sow": 60.0, "toc_sow": 60.0}
    record = _assemble(encode_ephemeris(11, eph, gst)).records[0]
    assert record["toe"] == 2357 * SECONDS_PER_WEEK + 60.0 and record["week"] == 2357.0
    assert record["transmission_sow"] == SECONDS_PER_WEEK - 60.0


def test_health_bits_follow_rinex():
    """E1-B DVS bit 0, E1-B HS bits 1–2, E5b DVS bit 6, E5b HS bits 7–8."""
    health = 1 | 2 << 1 | 1 << 6 | 3 << 7
    record = _assemble(encode_ephemeris(11, EXAMPLE | {"health": health}, GST)).records[0]
    assert record["health"] == health


def test_e5b_pages_set_their_data_source_bit():
    words = encode_ephemeris(11, EXAMPLE, GST)
    assembler = InavAssembler()
    for k, word in enumerate(words):
        assembler.add(11, inav.E5B if k % 2 else inav.E1B, sfrbx_words(word), k)
    assert assembler.records[0]["codes"] == 512 + 1 + 4


@settings(max_examples=80, deadline=None)
@given(flip=st.one_of(st.integers(0, 113), st.integers(120, 225)), which=st.integers(0, 4))
def test_a_flipped_bit_the_crc_covers_is_refused_and_counted(flip, which):
    """Any one bit of the 196 the CRC covers or of the CRC itself: the page is refused, named,
    and the record waits for a good copy of it."""
    words = encode_ephemeris(11, EXAMPLE, GST)
    assembler = InavAssembler()
    for k, word in enumerate(words):
        assembler.add(11, inav.E1B, sfrbx_words(word, flip if k == which else None), k)
    assert len(assembler.records) == 0
    assert len(assembler.rejected) == 1 and assembler.rejected[0][:2] == (which, 11)
    assert assembler.rejected[0][2] in (
        "page fails the CRC-24Q check",
        "page parts not even then odd",
    )
    assembler.add(11, inav.E1B, sfrbx_words(words[which]), 9)
    assert len(assembler.records) == 1 and assembler.records[0]["where"] == 9


def test_words_of_different_iodnav_are_not_combined():
    old = encode_ephemeris(11, EXAMPLE, GST, iodnav=160)
    new = encode_ephemeris(11, EXAMPLE | {"m0": 1.0, "af0": 1.0e-4}, GST, iodnav=161)
    assembler = _assemble([old[0], old[1], new[2], new[3], new[4]])
    assert assembler.records == []
    assembler.add(11, inav.E1B, sfrbx_words(new[0]), 7)
    assert assembler.records == []
    assembler.add(11, inav.E1B, sfrbx_words(new[1]), 8)
    (record,) = assembler.records
    assert record["iode"] == 161.0 and record["m0"] == quantised({"m0": 1.0})["m0"]


def test_a_repeated_set_is_one_record_and_no_set_is_kept_once_used():
    """A long recording repeats each set every 30 s: the assembler keeps only the words of the
    sets not yet complete."""
    words = encode_ephemeris(11, EXAMPLE, GST)
    assembler = _assemble(words + words + words)
    assert len(assembler.records) == 1 and assembler.sets == {11: {}}


def test_alert_pages_are_skipped_and_counted():
    assembler = InavAssembler()
    for word in encode_ephemeris(11, EXAMPLE, GST):
        assembler.add(11, inav.E1B, sfrbx_words(word, alert=True), 0)
    assert assembler.records == [] and assembler.rejected == [] and assembler.n_alert == 5


def test_word_4_of_another_satellite_is_refused():
    words = encode_ephemeris(12, EXAMPLE, GST)
    assembler = _assemble(words, svid=11)
    assert assembler.records == [] and assembler.rejected == [(104, 11, "word 4 is of E12")]


@pytest.mark.parametrize("change", [{"sqrt_a": 5153.7}, {"e": 0.3}, {"i0": 0.3}])
def test_an_orbit_no_galileo_satellite_flies_is_refused(change):
    assembler = _assemble(encode_ephemeris(11, EXAMPLE | change, GST))
    assert assembler.records == []
    assert assembler.rejected[0][2].startswith(f"{next(iter(change))} = ")


def test_a_toe_beyond_the_week_is_refused():
    eph = EXAMPLE | {"toe_sow": 16000 * 60.0}
    assembler = _assemble(encode_ephemeris(11, eph, GST))
    assert assembler.records == [] and "is no time of week" in assembler.rejected[0][2]


def test_word_0_gives_the_time_when_it_is_the_latest():
    """Word 0 with its time field 2 after word 5: the GST is word 0's."""
    words = encode_ephemeris(11, EXAMPLE, GST)
    later = GST + 30.0
    word0 = encode_word(0, {"time": 2, "wn": 1333, "tow": later % SECONDS_PER_WEEK})
    record = _assemble([words[4], word0, *words[:4]]).records[0]
    assert record["transmission_sow"] == later % SECONDS_PER_WEEK


def test_sisa_indices_in_metres():
    assert [sisa_metres(k) for k in (0, 49, 50, 74, 75, 99, 100, 125, 126, 255)] == [
        0.0,
        0.49,
        0.5,
        0.98,
        1.0,
        1.96,
        2.0,
        6.0,
        -1.0,
        -1.0,
    ]


EPHEMERIS = kepler_strategy(
    SCALES,
    toe_sow=st.integers(0, 10079).map(lambda n: n * 60.0),
    toc_sow=st.integers(0, 10079).map(lambda n: n * 60.0),
    iode=st.integers(0, 1023).map(float),
    e=grid(SCALES["e"], 0.0, 0.19),
    sqrt_a=grid(SCALES["sqrt_a"], 5260.0, 5490.0),
    i0=grid(SCALES["i0"], 0.83, 1.04),
    af0=grid(SCALES["af0"], -0.06, 0.06),
    health=st.sampled_from([0.0, 1.0, 6.0, 64.0, 384.0]),
)


@settings(max_examples=150, deadline=None)
@given(eph=EPHEMERIS, svid=st.integers(1, 36), tow=st.integers(0, 604_799))
def test_any_valid_ephemeris_comes_back_exactly(eph, svid, tow):
    gst = 2357 * SECONDS_PER_WEEK + tow
    assembler = _assemble(encode_ephemeris(svid, eph, gst), svid=svid)
    assert assembler.rejected == []
    (record,) = assembler.records
    for name in KEPLER_SCALED:
        if name != "toe_sow":
            assert record[name] == eph[name], name
    assert record["toe_sow"] == eph["toe_sow"] and record["iode"] == eph["iode"]
    assert record["health"] == eph["health"]
    assert abs(record["toe"] - gst) <= SECONDS_PER_WEEK / 2
    assert record["toe"] % SECONDS_PER_WEEK == eph["toe_sow"]
    assert abs(record["toc"] - gst) <= SECONDS_PER_WEEK / 2
    assert record["week"] == record["toe"] // SECONDS_PER_WEEK
