"""Galileo I/NAV page encoder for tests: the inverse of vo_doppler.io.galileo_inav.

Independent of the decoder: every field's first bit in its 128-bit word is written out here from
the ICD's word tables (the decoder lays its fields one after another), the CRC-24Q is a bitwise
polynomial division (the decoder's is table-driven), and pages are built part by part.
"""

from __future__ import annotations

from pyubx2 import UBXMessage

from tests.helpers.nav_grid import on_grid

SC = 3.1415926535898  # semicircles → rad, the ICD's π
SECONDS_PER_WEEK = 604800.0

# word type → (name, first bit in the 128-bit word, bits, scale); signed ones are marked in SIGNED
WORD_FIELDS = {
    1: (("iode", 6, 10, 1.0), ("toe_sow", 16, 14, 60.0), ("m0", 30, 32, 2.0**-31 * SC),
        ("e", 62, 32, 2.0**-33), ("sqrt_a", 94, 32, 2.0**-19)),
    2: (("iode", 6, 10, 1.0), ("omega0", 16, 32, 2.0**-31 * SC), ("i0", 48, 32, 2.0**-31 * SC),
        ("omega", 80, 32, 2.0**-31 * SC), ("idot", 112, 14, 2.0**-43 * SC)),
    3: (("iode", 6, 10, 1.0), ("omega_dot", 16, 24, 2.0**-43 * SC),
        ("delta_n", 40, 16, 2.0**-43 * SC), ("cuc", 56, 16, 2.0**-29), ("cus", 72, 16, 2.0**-29),
        ("crc", 88, 16, 2.0**-5), ("crs", 104, 16, 2.0**-5), ("sisa", 120, 8, 1.0)),
    4: (("iode", 6, 10, 1.0), ("svid", 16, 6, 1.0), ("cic", 22, 16, 2.0**-29),
        ("cis", 38, 16, 2.0**-29), ("toc_sow", 54, 14, 60.0), ("af0", 68, 31, 2.0**-34),
        ("af1", 99, 21, 2.0**-46), ("af2", 120, 6, 2.0**-59)),
    5: (("tgd", 47, 10, 2.0**-32), ("iodc", 57, 10, 2.0**-32), ("e5b_hs", 67, 2, 1.0),
        ("e1b_hs", 69, 2, 1.0), ("e5b_dvs", 71, 1, 1.0), ("e1b_dvs", 72, 1, 1.0),
        ("wn", 73, 12, 1.0), ("tow", 85, 20, 1.0)),
    0: (("time", 6, 2, 1.0), ("wn", 96, 12, 1.0), ("tow", 108, 20, 1.0)),
}  # fmt: skip
SIGNED = {"m0", "omega0", "i0", "omega", "idot", "omega_dot", "delta_n", "cuc", "cus", "crc",
          "crs", "cic", "cis", "af0", "af1", "af2", "tgd", "iodc"}  # fmt: skip
SCALES = {name: scale for fields in WORD_FIELDS.values() for name, _, _, scale in fields}
KEPLER_SCALED = ("toe_sow", "m0", "e", "sqrt_a", "omega0", "i0", "omega", "idot", "omega_dot",
                 "delta_n", "cuc", "cus", "crc", "crs", "cic", "cis", "af0", "af1", "af2", "tgd",
                 "iodc")  # fmt: skip
"""RINEX parameters the words carry at their LSB (``tgd``/``iodc``: the two BGDs)."""


def _put(word: int, first: int, width: int, value: int, signed: bool) -> int:
    if signed:
        assert -(1 << (width - 1)) <= value < 1 << (width - 1), (value, width)
        value &= (1 << width) - 1
    assert 0 <= value < 1 << width, (value, width)
    return word | value << (128 - first - width)


def encode_word(number: int, values: dict[str, float]) -> int:
    """A 128-bit word of type ``number`` holding ``values`` (RINEX names, SI units; integers
    for the counts and flags)."""
    word = number << 122
    for name, first, width, scale in WORD_FIELDS[number]:
        word = _put(word, first, width, round(values[name] / scale), name in SIGNED)
    return word


def crc24q(bits: list[int]) -> int:
    """CRC-24Q by polynomial division: the remainder of bits · x²⁴ by 0x1864CFB."""
    register = [*bits, *[0] * 24]
    generator = [int(b) for b in f"{0x1864CFB:025b}"]
    for k in range(len(bits)):
        if register[k]:
            for j, g in enumerate(generator):
                register[k + j] ^= g
    return int("".join(str(b) for b in register[-24:]), 2)


def _bits(value: int, width: int) -> list[int]:
    return [(value >> (width - 1 - k)) & 1 for k in range(width)]


def page_parts(word: int, alert: bool = False) -> tuple[list[int], list[int]]:
    """The even and odd page parts (120 bits each) carrying a word, with a valid CRC."""
    data = _bits(word, 128)
    even = [0, int(alert), *data[:112], *[0] * 6]
    odd_head = [1, int(alert), *data[112:], *[0] * 40, *[0] * 22, 0, 0]
    crc = crc24q(even[:114] + odd_head)
    odd = [*odd_head, *_bits(crc, 24), *[0] * 8, *[0] * 6]
    assert len(even) == len(odd) == 120
    return even, odd


def sfrbx_words(word: int, flip: int | None = None, alert: bool = False) -> list[int]:
    """The eight RXM-SFRBX words of the page carrying ``word``: even part and 8 padding bits, odd
    part and 8 padding bits; ``flip``: one bit of the 240 page bits (0 the even part's first)
    inverted after the CRC was computed."""
    even, odd = page_parts(word, alert)
    bits = even + odd
    if flip is not None:
        bits[flip] ^= 1
    stream = bits[:120] + [0] * 8 + bits[120:] + [0] * 8
    return [int("".join(str(b) for b in stream[32 * k : 32 * k + 32]), 2) for k in range(8)]


def ubx_sfrbx(svid: int, words: list[int], sig_id: int = 1) -> bytes:
    """A UBX RXM-SFRBX frame carrying one Galileo page."""
    dwrd = {f"dwrd_{k + 1:02d}": w for k, w in enumerate(words)}
    return UBXMessage(
        "RXM", "RXM-SFRBX", 0, gnssId=2, svId=svid, sigId=sig_id, numWords=8, chn=3, version=2,
        **dwrd,
    ).serialize()  # fmt: skip


def encode_ephemeris(
    svid: int, eph: dict[str, float], gst: float, iodnav: int | None = None
) -> list[int]:
    """Words 1, 2, 3, 4 and 5 of a record (RINEX names: ``tgd`` BGD(E1,E5a), ``iodc``
    BGD(E1,E5b), ``health`` the RINEX bits, ``iode`` IODnav), word 5's GST ``gst`` in GPS
    seconds; ``accuracy`` given as its SISA index ``sisa`` (default 107)."""
    health = int(eph.get("health", 0))
    values = dict(eph) | {
        "iode": eph["iode"] if iodnav is None else iodnav,
        "svid": svid,
        "sisa": eph.get("sisa", 107),
        "e1b_dvs": health & 1,
        "e1b_hs": health >> 1 & 3,
        "e5b_dvs": health >> 6 & 1,
        "e5b_hs": health >> 7 & 3,
        "wn": int(gst // SECONDS_PER_WEEK) - 1024,
        "tow": gst % SECONDS_PER_WEEK,
        "time": 2,
    }
    return [encode_word(number, values) for number in (1, 2, 3, 4, 5)]


def quantised(eph: dict[str, float]) -> dict[str, float]:
    """The values the message carries (each scaled parameter rounded to its LSB)."""
    return on_grid(eph, SCALES, KEPLER_SCALED)


EXAMPLE = {
    # a Galileo record with values of the usual magnitudes (radians, seconds, metres), on the
    # words' quantisation grid after quantised()
    "toe_sow": 439200.0,
    "toc_sow": 439200.0,
    "iode": 161.0,
    "m0": 2.899101364047,
    "e": 2.049941084875e-04,
    "sqrt_a": 5440.569823098,
    "omega0": 0.5247109654316,
    "i0": 0.9797451110818,
    "omega": -1.995348157250,
    "idot": -1.079628114455e-10,
    "omega_dot": -5.613221000438e-09,
    "delta_n": 2.191074629543e-09,
    "cuc": -1.528377952705e-06,
    "cus": -6.408907832736e-06,
    "crc": 322.0,
    "crs": 86.0625,
    "cic": 8.243847774616e-09,
    "cis": 1.170756440209e-07,
    "af0": -2.494706057268e-04,
    "af1": 1.153146169893e-12,
    "af2": 0.0,
    "tgd": 1.811767662060e-09,
    "iodc": 2.013075180067e-09,
    "health": 0.0,
}
