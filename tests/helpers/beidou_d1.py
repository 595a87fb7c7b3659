"""BeiDou D1 subframe encoder for tests: the inverse of vo_doppler.io.beidou_d1d2.

Independent of the decoder: each field's bits are placed at their positions in the 300-bit
subframe with the check bits in place (the ICD's D1 figures: word n spans bits 30(n − 1) …
30n − 1, 22 information bits then 8 check bits, word 1 26 and 4), where the decoder lays the
fields one after another over the information bits alone; the BCH check bits come from a
polynomial division written out again here.
"""

from __future__ import annotations

from pyubx2 import UBXMessage

from tests.helpers.nav_grid import on_grid

SC = 3.1415926535898
SECONDS_PER_WEEK = 604800.0
PREAMBLE = 0b11100010010

# subframe → (name, [(first bit of the 300, bits) …] most significant part first, signed, scale)
FIELDS = {
    1: (("sath1", ((42, 1),), False, 1.0), ("aodc", ((43, 5),), False, 1.0),
        ("urai", ((48, 4),), False, 1.0), ("wn", ((60, 13),), False, 1.0),
        ("toc_sow", ((73, 9), (90, 8)), False, 8.0), ("tgd", ((98, 10),), True, 1e-10),
        ("iodc", ((108, 4), (120, 6)), True, 1e-10), ("af2", ((214, 11),), True, 2.0**-66),
        ("af0", ((225, 7), (240, 17)), True, 2.0**-33),
        ("af1", ((257, 5), (270, 17)), True, 2.0**-50), ("iode", ((287, 5),), False, 1.0)),
    2: (("delta_n", ((42, 10), (60, 6)), True, 2.0**-43 * SC),
        ("cuc", ((66, 16), (90, 2)), True, 2.0**-31),
        ("m0", ((92, 20), (120, 12)), True, 2.0**-31 * SC),
        ("e", ((132, 10), (150, 22)), False, 2.0**-33), ("cus", ((180, 18),), True, 2.0**-31),
        ("crc", ((198, 4), (210, 14)), True, 2.0**-6),
        ("crs", ((224, 8), (240, 10)), True, 2.0**-6),
        ("sqrt_a", ((250, 12), (270, 20)), False, 2.0**-19), ("toe_msb", ((290, 2),), False, 1.0)),
    3: (("toe_lsb", ((42, 10), (60, 5)), False, 1.0),
        ("i0", ((65, 17), (90, 15)), True, 2.0**-31 * SC),
        ("cic", ((105, 7), (120, 11)), True, 2.0**-31),
        ("omega_dot", ((131, 11), (150, 13)), True, 2.0**-43 * SC),
        ("cis", ((163, 9), (180, 9)), True, 2.0**-31),
        ("idot", ((189, 13), (210, 1)), True, 2.0**-43 * SC),
        ("omega0", ((211, 21), (240, 11)), True, 2.0**-31 * SC),
        ("omega", ((251, 11), (270, 21)), True, 2.0**-31 * SC)),
}  # fmt: skip
SCALES = {name: scale for fields in FIELDS.values() for name, _, _, scale in fields}
KEPLER_SCALED = ("toc_sow", "tgd", "iodc", "af2", "af0", "af1", "delta_n", "cuc", "m0", "e",
                 "cus", "crc", "crs", "sqrt_a", "i0", "cic", "omega_dot", "cis", "idot",
                 "omega0", "omega")  # fmt: skip


def _put(bits: list[int], parts, value: int, signed: bool) -> None:
    width = sum(n for _, n in parts)
    if signed:
        assert -(1 << (width - 1)) <= value < 1 << (width - 1), (value, width)
        value &= (1 << width) - 1
    assert 0 <= value < 1 << width, (value, width)
    k = width
    for first, n in parts:
        for j in range(n):
            k -= 1
            assert bits[first + j] == 0, first + j
            bits[first + j] = (value >> k) & 1


def _check_bits(info: list[int]) -> list[int]:
    """The 4 BCH(15,11,1) check bits of 11 information bits: the remainder of info · x⁴ by
    x⁴ + x + 1."""
    register = [*info, 0, 0, 0, 0]
    for k in range(11):
        if register[k]:
            for j, g in enumerate((1, 0, 0, 1, 1)):
                register[k + j] ^= g
    return register[11:]


def _with_check_bits(bits: list[int]) -> list[int]:
    out = list(bits)
    out[26:30] = _check_bits(bits[15:26])
    for word in range(1, 10):
        base = 30 * word
        out[base + 22 : base + 26] = _check_bits(bits[base : base + 11])
        out[base + 26 : base + 30] = _check_bits(bits[base + 11 : base + 22])
    return out


def encode_subframes(eph: dict[str, float], wn: int, sow: int) -> list[list[int]]:
    """Subframes 1, 2, 3 (ten 30-bit words each, check bits included) of a record (RINEX names:
    ``iode`` AODE, ``fit_interval`` AODC, ``tgd``/``iodc`` TGD1/TGD2, ``health`` SatH1,
    ``urai`` the URA index), subframe 1 sent at BDT week ``wn``, second ``sow``."""
    toe = round(eph["toe_sow"] / 8.0)
    values = dict(eph) | {"aodc": eph.get("fit_interval", 0), "sath1": eph.get("health", 0)}
    values |= {"urai": eph.get("urai", 0), "wn": wn, "toe_msb": toe >> 15}
    values |= {"toe_lsb": toe & 0x7FFF}
    out = []
    for number in (1, 2, 3):
        bits = [0] * 300
        _put(bits, ((0, 11),), PREAMBLE, False)
        _put(bits, ((15, 3),), number, False)
        _put(bits, ((18, 8), (30, 12)), sow + 6 * (number - 1), False)
        for name, parts, signed, scale in FIELDS[number]:
            _put(bits, parts, round(values[name] / scale), signed)
        bits = _with_check_bits(bits)
        out.append([int("".join(map(str, bits[30 * w : 30 * w + 30])), 2) for w in range(10)])
    return out


def almanac_subframe(number: int, sow: int) -> list[int]:
    """Subframe ``number`` (4 or 5: almanac pages, their data all zero) sent at second ``sow``."""
    bits = [0] * 300
    _put(bits, ((0, 11),), PREAMBLE, False)
    _put(bits, ((15, 3),), number, False)
    _put(bits, ((18, 8), (30, 12)), sow, False)
    bits = _with_check_bits(bits)
    return [int("".join(map(str, bits[30 * w : 30 * w + 30])), 2) for w in range(10)]


def ubx_sfrbx(prn: int, words: list[int], sig_id: int = 0) -> bytes:
    """A UBX RXM-SFRBX frame carrying one BeiDou subframe (2 padding bits above each word)."""
    dwrd = {f"dwrd_{k + 1:02d}": w for k, w in enumerate(words)}
    return UBXMessage(
        "RXM", "RXM-SFRBX", 0, gnssId=3, svId=prn, sigId=sig_id, numWords=10, chn=5, version=2,
        **dwrd,
    ).serialize()  # fmt: skip


def quantised(eph: dict[str, float]) -> dict[str, float]:
    """The values the message carries (each scaled parameter rounded to its LSB)."""
    return on_grid(eph, SCALES, KEPLER_SCALED)


EXAMPLE = {
    # a BeiDou MEO record (C21-like) of the usual magnitudes (radians, seconds, metres)
    "toe_sow": 446400.0,
    "toc_sow": 446400.0,
    "iode": 1.0,
    "fit_interval": 1.0,
    "m0": -1.5294733434,
    "e": 7.3567312211e-04,
    "sqrt_a": 5282.6223049164,
    "omega0": -2.9135271163,
    "i0": 0.9626544623,
    "omega": -0.6634589391,
    "idot": 1.9286517653e-10,
    "omega_dot": -6.7753108003e-09,
    "delta_n": 3.7316040637e-09,
    "cuc": 4.0512531996e-06,
    "cus": 1.0244222358e-05,
    "crc": 153.28125,
    "crs": 87.125,
    "cic": -1.3969838619e-08,
    "cis": 2.3283064365e-08,
    "af0": -5.1860255189e-04,
    "af1": 6.9188298750e-12,
    "af2": 0.0,
    "tgd": 1.4e-08,
    "iodc": -3.4e-09,
    "health": 0.0,
}
