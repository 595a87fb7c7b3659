"""BeiDou D1 subframes (vo_doppler.io.beidou_d1d2): subframes encoded from known values
(tests/helpers, fields at their bit positions in the 300-bit subframe with its check bits,
written out again) decode back exactly at their quantisation, also as a hypothesis property over
valid ephemerides; every single flipped bit the BCH code covers is refused and counted;
subframes of different frames are never combined; times are BDT, kept in GPS seconds."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.helpers.beidou_d1 import (
    EXAMPLE,
    KEPLER_SCALED,
    SCALES,
    almanac_subframe,
    encode_subframes,
    quantised,
)
from tests.helpers.nav_grid import grid, kepler_strategy
from vo_doppler.io.beidou_d1d2 import (
    D1Assembler,
    bch_error,
    decode_subframe,
    is_geo,
    subframe_id,
)

SECONDS_PER_WEEK = 604800.0
WN, SOW = 1001, 446_100
"""BDT week and second of subframe 1 (300 s before toe)."""


def _assemble(subframes, prn: int = 21) -> D1Assembler:
    assembler = D1Assembler()
    for k, words in enumerate(subframes):
        assembler.add(prn, words, 200 + k)
    return assembler


def test_encoded_subframes_pass_the_bch_check_and_name_themselves():
    subframes = encode_subframes(EXAMPLE, WN, SOW)
    assert [bch_error(s) for s in subframes] == [None, None, None]
    assert [subframe_id(s) for s in subframes] == [1, 2, 3]
    assert [decode_subframe(s)["sow"] for s in subframes] == [SOW, SOW + 6, SOW + 12]


def test_each_field_decodes_within_half_an_lsb():
    one, two, three = (decode_subframe(s) for s in encode_subframes(EXAMPLE, WN, SOW))
    fields = one | two | three
    renamed = {"tgd1": "tgd", "tgd2": "iodc"}
    expected = quantised(EXAMPLE)
    checked = 0
    for name, value in fields.items():
        source = renamed.get(name, name)
        if source in KEPLER_SCALED:
            assert value == expected[source], name
            assert abs(value - EXAMPLE[source]) <= SCALES[source] / 2, name
            checked += 1
    assert checked == len(KEPLER_SCALED)
    assert (int(two["toe_msb"]) << 15 | int(three["toe_lsb"])) * 8.0 == EXAMPLE["toe_sow"]
    assert (one["wn"], one["aode"], one["aodc"]) == (WN, 1.0, 1.0)


def test_subframes_1_to_3_make_one_record_on_gps_time():
    assembler = _assemble(encode_subframes(EXAMPLE, WN, SOW))
    assert assembler.rejected == [] and len(assembler.records) == 1
    record = assembler.records[0]
    for name, value in quantised(EXAMPLE).items():
        if name in KEPLER_SCALED and name != "toc_sow":
            assert record[name] == value, name
    gps_week = (WN + 1356) * SECONDS_PER_WEEK
    assert record["toe"] == gps_week + 446_400.0 + 14.0
    assert record["toc"] == gps_week + 446_400.0 + 14.0
    assert record["toe_sow"] == 446_400.0 and record["week"] == WN
    assert record["transmission_sow"] == SOW and record["where"] == 202.0
    assert (record["iode"], record["fit_interval"], record["health"]) == (1.0, 1.0, 0.0)
    assert record["accuracy"] == 2.4  # URAI 0
    records = assembler.navrecords()
    assert records.system.tolist() == ["C"] and records.prn.tolist() == [21]


@settings(max_examples=120, deadline=None)
@given(bit=st.integers(0, 299).filter(lambda b: not 11 <= b <= 14), which=st.integers(0, 2))
def test_a_flipped_bit_is_refused_and_counted(bit, which):
    """Any one bit but the 4 reserved bits of word 1 (no code covers them): the subframe is
    refused (a BCH codeword that is not one, or the preamble lost) and named; the record waits
    for a good copy of its frame."""
    subframes = encode_subframes(EXAMPLE, WN, SOW)
    broken = [list(s) for s in subframes]
    broken[which][bit // 30] ^= 1 << (29 - bit % 30)
    assembler = _assemble(broken)
    assert assembler.records == []
    assert len(assembler.rejected) == 1 and assembler.rejected[0][:2] == (200 + which, 21)
    why = assembler.rejected[0][2]
    assert why == "no preamble" if bit < 11 else why == f"word {bit // 30 + 1} fails the BCH check"
    assembler.add(21, subframes[which], 9)
    assert len(assembler.records) == 1 and assembler.records[0]["where"] == 9


def test_subframes_of_different_frames_are_not_combined():
    """Subframe 1 of one frame, 2 and 3 of the next (another AODE): no record until the next
    frame's subframe 1 arrives."""
    old = encode_subframes(EXAMPLE, WN, SOW)
    new = encode_subframes(EXAMPLE | {"iode": 2.0, "m0": 1.0}, WN, SOW + 30)
    assembler = _assemble([old[0], new[1], new[2]])
    assert assembler.records == []
    assembler.add(21, new[0], 7)
    assembler.add(21, new[1], 8)
    (record,) = assembler.records
    assert record["iode"] == 2.0 and record["m0"] == quantised({"m0": 1.0})["m0"]


def test_a_repeated_frame_is_one_record_and_almanac_subframes_are_counted():
    subframes = encode_subframes(EXAMPLE, WN, SOW)
    assembler = _assemble(subframes + encode_subframes(EXAMPLE, WN, SOW + 30))
    assert len(assembler.records) == 1
    for number in (4, 5):
        assembler.add(21, almanac_subframe(number, SOW + 18 + 6 * number), 50)
    assert assembler.n_almanac == 2 and assembler.rejected == []


@pytest.mark.parametrize("change", [{"sqrt_a": 5153.7}, {"e": 0.2}, {"i0": 1.3}])
def test_an_orbit_no_beidou_satellite_flies_is_refused(change):
    assembler = _assemble(encode_subframes(EXAMPLE | change, WN, SOW))
    assert assembler.records == []
    assert assembler.rejected[0][2].startswith(f"{next(iter(change))} = ")


def test_a_week_past_the_years_rinex_holds_is_refused():
    """BDT week 4905 (GPS week 6261, January 2100) and later: refused; week 4903 is read."""
    assert len(_assemble(encode_subframes(EXAMPLE, 4903, SOW)).records) == 1
    assembler = _assemble(encode_subframes(EXAMPLE, 4905, SOW))
    assert assembler.records == [] and assembler.rejected == [
        (202, 21, "BDT week 4905 is after 2099")
    ]


def test_geo_satellites_are_the_d2_ones():
    assert [p for p in range(1, 64) if is_geo(p)] == [1, 2, 3, 4, 5, 59, 60, 61, 62, 63]


EPHEMERIS = kepler_strategy(
    SCALES,
    toe_sow=st.integers(0, 75_599).map(lambda n: n * 8.0),
    toc_sow=st.integers(0, 75_599).map(lambda n: n * 8.0),
    iode=st.integers(0, 31).map(float),
    fit_interval=st.integers(0, 31).map(float),
    e=grid(SCALES["e"], 0.0, 0.049),
    sqrt_a=st.sampled_from([5282.6, 6493.4]).flatmap(
        lambda a: grid(SCALES["sqrt_a"], a - 20.0, a + 20.0)
    ),
    i0=grid(SCALES["i0"], 0.0, 1.04),
    af0=grid(SCALES["af0"], -9e-4, 9e-4),
    health=st.sampled_from([0.0, 1.0]),
)


@settings(max_examples=150, deadline=None)
@given(eph=EPHEMERIS, prn=st.integers(6, 58), wn=st.integers(0, 4800), sow=st.integers(0, 100_790))
def test_any_valid_ephemeris_comes_back_exactly(eph, prn, wn, sow):
    sow *= 6
    assembler = _assemble(encode_subframes(eph, wn, sow), prn=prn)
    assert assembler.rejected == []
    (record,) = assembler.records
    for name in KEPLER_SCALED:
        if name != "toc_sow":
            assert record[name] == eph[name], name
    assert record["toe_sow"] == eph["toe_sow"] and record["iode"] == eph["iode"]
    assert record["fit_interval"] == eph["fit_interval"] and record["health"] == eph["health"]
    sent = (wn + 1356) * SECONDS_PER_WEEK + sow + 14.0
    assert abs(record["toe"] - sent) <= SECONDS_PER_WEEK / 2
    assert (record["toe"] - 14.0) % SECONDS_PER_WEEK == eph["toe_sow"]
    assert (record["toc"] - 14.0) % SECONDS_PER_WEEK == eph["toc_sow"]
    assert record["week"] == (record["toe"] - 14.0) // SECONDS_PER_WEEK - 1356
