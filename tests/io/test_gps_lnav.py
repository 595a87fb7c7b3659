"""GPS LNAV subframes 1-3: exact decoding of encoded ephemerides, checked against RTKLIB."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.lnav import EXAMPLE, encode_ephemeris, quantised
from vo_doppler.io.gps_lnav import LnavAssembler, data_bit, decode_subframe, subframe_id

TOW_COUNT = 57599  # HOW count of subframe 1: transmission at 6·57599 − 6 s of week


def test_data_bit_numbering_skips_parity():
    assert data_bit(1) == 0
    assert data_bit(24) == 23
    assert data_bit(31) == 24
    assert data_bit(292) == 24 * 9 + 21
    with pytest.raises(ValueError):
        data_bit(25)


def test_decoded_fields_equal_the_encoded_quantised_values():
    expected = quantised(EXAMPLE)
    decoded = {}
    for words in encode_ephemeris(EXAMPLE, TOW_COUNT):
        decoded |= decode_subframe(words)
    for name in (
        "tgd", "af2", "af1", "af0", "crs", "delta_n", "m0", "cuc", "e", "cus", "sqrt_a",
        "toe_sow", "cic", "omega0", "cis", "i0", "crc", "omega", "omega_dot", "idot", "toc_sow",
    ):  # fmt: skip
        assert decoded[name] == expected[name], name
    assert decoded["iodc"] == 301
    assert decoded["iode"] == 301 & 0xFF
    assert decoded["week10"] == 2200 % 1024


def test_decoder_agrees_with_rtklib():
    rtk = pytest.importorskip("pyrtklib")
    subframes = encode_ephemeris(EXAMPLE, TOW_COUNT)
    buffer = getattr(rtk, "Arr1Dunsigned char")(150)
    for s, words in enumerate(subframes):
        for w, word in enumerate(words):
            rtk.setbitu(buffer, 240 * s + 24 * w, 24, word)
    eph = rtk.eph_t()
    rtk.decode_frame(buffer, eph, rtk.alm_t(), rtk.Arr1Ddouble(8), rtk.Arr1Ddouble(8))
    ours = {}
    for words in subframes:
        ours |= decode_subframe(words)
    pairs = {
        "af0": eph.f0, "af1": eph.f1, "af2": eph.f2,
        "crs": eph.crs, "crc": eph.crc, "cus": eph.cus, "cuc": eph.cuc, "cis": eph.cis,
        "cic": eph.cic, "delta_n": eph.deln, "m0": eph.M0, "e": eph.e, "omega0": eph.OMG0,
        "i0": eph.i0, "omega": eph.omg, "omega_dot": eph.OMGd, "idot": eph.idot,
        "toe_sow": eph.toes,
    }  # fmt: skip
    for name, theirs in pairs.items():
        assert ours[name] == pytest.approx(theirs, rel=1e-12, abs=1e-20), name
    assert ours["sqrt_a"] ** 2 == pytest.approx(eph.A, rel=1e-12)
    assert ours["iodc"] == eph.iodc
    assert ours["iode"] == eph.iode


def test_assembler_emits_one_record_with_resolved_week_and_times():
    assembler = LnavAssembler.new()
    subframes = encode_ephemeris(EXAMPLE, TOW_COUNT)
    for offset, words in enumerate(subframes * 2):
        assembler.add(7, words, reference_week=2200 + 1024 * 2 + 3, where=offset)
    records = assembler.navrecords()
    assert len(records) == 1
    week = 2200 + 1024 * 2
    assert records["week"][0] == week
    assert records.toc[0] == week * 604800.0 + 345600.0
    assert records["toe"][0] == records.toc[0]
    assert records["transmission_sow"][0] == 6.0 * TOW_COUNT - 6.0
    assert records.line[0] == 2
    assert records.prn[0] == 7


def test_inconsistent_issue_of_data_is_not_emitted():
    assembler = LnavAssembler.new()
    one, two, _ = encode_ephemeris(EXAMPLE, TOW_COUNT)
    _, _, three = encode_ephemeris({**EXAMPLE, "iodc": 302}, TOW_COUNT)
    for words in (one, two, three):
        assembler.add(7, words, reference_week=2200, where=0)
    assert len(assembler.navrecords()) == 0


def test_wrong_preamble_has_no_subframe_id():
    words = encode_ephemeris(EXAMPLE, TOW_COUNT)[0]
    assert subframe_id(words) == 1
    assert subframe_id((words[0] ^ 0xFF0000, *words[1:])) == 0
    assert np.isfinite(decode_subframe(words)["af0"])
