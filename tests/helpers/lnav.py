"""GPS LNAV subframe encoder for tests: the inverse of vo_doppler.io.gps_lnav's layout.

Independent of the decoder's field table: the ICD bit positions are written out again here
(IS-GPS-200 Figure 20-1) so a mistake in one is caught by the other and by RTKLIB.
"""

from __future__ import annotations

import numpy as np
from pyubx2 import UBXMessage

GPS_PI = 3.1415926535898
SC = GPS_PI  # semicircles → rad


def _put(bits: list[int], icd_bit: int, n_bits: int, value: int) -> None:
    value &= (1 << n_bits) - 1
    for k in range(n_bits):
        n = icd_bit + k - 1
        word, position = divmod(n, 30)
        assert position < 24, "parity bit"
        bits[24 * word + position] = (value >> (n_bits - 1 - k)) & 1


def _q(value: float, scale: float) -> int:
    return round(value / scale)


def _words(bits: list[int]) -> tuple[int, ...]:
    return tuple(int("".join(str(b) for b in bits[24 * w : 24 * w + 24]), 2) for w in range(10))


def _new(subframe: int, tow_count: int) -> list[int]:
    bits = [0] * 240
    _put(bits, 1, 8, 0x8B)
    _put(bits, 31, 17, tow_count)
    _put(bits, 50, 3, subframe)
    return bits


def encode_ephemeris(eph: dict[str, float], tow_count: int) -> list[tuple[int, ...]]:
    """Subframes 1, 2, 3 (24-bit data words) of one ephemeris; angles in radians."""
    one = _new(1, tow_count)
    _put(one, 61, 10, int(eph["week"]) % 1024)
    _put(one, 71, 2, int(eph["codes"]))
    _put(one, 73, 4, int(eph["ura_index"]))
    _put(one, 77, 6, int(eph["health"]))
    iodc = int(eph["iodc"])
    _put(one, 83, 2, iodc >> 8)
    _put(one, 211, 8, iodc & 0xFF)
    _put(one, 91, 1, int(eph["l2p_flag"]))
    _put(one, 197, 8, _q(eph["tgd"], 2.0**-31))
    _put(one, 219, 16, _q(eph["toc_sow"], 16.0))
    _put(one, 241, 8, _q(eph["af2"], 2.0**-55))
    _put(one, 249, 16, _q(eph["af1"], 2.0**-43))
    _put(one, 271, 22, _q(eph["af0"], 2.0**-31))
    two = _new(2, tow_count + 1)
    _put(two, 61, 8, iodc & 0xFF)
    _put(two, 69, 16, _q(eph["crs"], 2.0**-5))
    _put(two, 91, 16, _q(eph["delta_n"], 2.0**-43 * SC))
    m0 = _q(eph["m0"], 2.0**-31 * SC)
    _put(two, 107, 8, m0 >> 24)
    _put(two, 121, 24, m0)
    _put(two, 151, 16, _q(eph["cuc"], 2.0**-29))
    e = _q(eph["e"], 2.0**-33)
    _put(two, 167, 8, e >> 24)
    _put(two, 181, 24, e)
    _put(two, 211, 16, _q(eph["cus"], 2.0**-29))
    sqrt_a = _q(eph["sqrt_a"], 2.0**-19)
    _put(two, 227, 8, sqrt_a >> 24)
    _put(two, 241, 24, sqrt_a)
    _put(two, 271, 16, _q(eph["toe_sow"], 16.0))
    three = _new(3, tow_count + 2)
    _put(three, 61, 16, _q(eph["cic"], 2.0**-29))
    omega0 = _q(eph["omega0"], 2.0**-31 * SC)
    _put(three, 77, 8, omega0 >> 24)
    _put(three, 91, 24, omega0)
    _put(three, 121, 16, _q(eph["cis"], 2.0**-29))
    i0 = _q(eph["i0"], 2.0**-31 * SC)
    _put(three, 137, 8, i0 >> 24)
    _put(three, 151, 24, i0)
    _put(three, 181, 16, _q(eph["crc"], 2.0**-5))
    omega = _q(eph["omega"], 2.0**-31 * SC)
    _put(three, 197, 8, omega >> 24)
    _put(three, 211, 24, omega)
    _put(three, 241, 24, _q(eph["omega_dot"], 2.0**-43 * SC))
    _put(three, 271, 8, iodc & 0xFF)
    _put(three, 279, 14, _q(eph["idot"], 2.0**-43 * SC))
    return [_words(one), _words(two), _words(three)]


def quantised(eph: dict[str, float]) -> dict[str, float]:
    """The values the subframes can carry (each parameter rounded to its LSB)."""
    scales = {
        "tgd": 2.0**-31,
        "toc_sow": 16.0,
        "af2": 2.0**-55,
        "af1": 2.0**-43,
        "af0": 2.0**-31,
        "crs": 2.0**-5,
        "delta_n": 2.0**-43 * SC,
        "m0": 2.0**-31 * SC,
        "cuc": 2.0**-29,
        "e": 2.0**-33,
        "cus": 2.0**-29,
        "sqrt_a": 2.0**-19,
        "toe_sow": 16.0,
        "cic": 2.0**-29,
        "omega0": 2.0**-31 * SC,
        "cis": 2.0**-29,
        "i0": 2.0**-31 * SC,
        "crc": 2.0**-5,
        "omega": 2.0**-31 * SC,
        "omega_dot": 2.0**-43 * SC,
        "idot": 2.0**-43 * SC,
    }
    return {k: (np.round(v / scales[k]) * scales[k] if k in scales else v) for k, v in eph.items()}


EXAMPLE = {
    # a GPS ephemeris with values of the usual magnitudes (radians, seconds, metres)
    "week": 2200,
    "codes": 1,
    "ura_index": 0,
    "health": 0,
    "iodc": 301,
    "l2p_flag": 0,
    "tgd": -1.1175870895385742e-08,
    "toc_sow": 345600.0,
    "af2": 0.0,
    "af1": -1.4779288903810084e-12,
    "af0": -2.3657130077481270e-04,
    "crs": -1.0465625e02,
    "delta_n": 4.2337763591e-09,
    "m0": 2.8914823472,
    "cuc": -5.3681433200836182e-06,
    "e": 1.2187458411790431e-02,
    "cus": 2.7529895305633545e-06,
    "sqrt_a": 5153.6589355468750,
    "toe_sow": 345600.0,
    "cic": 1.1175870895385742e-08,
    "omega0": -1.7451372018,
    "cis": -6.5192580223083496e-08,
    "i0": 0.9782457389,
    "crc": 3.2821875e02,
    "omega": -1.9230114325,
    "omega_dot": -8.1739833499e-09,
    "idot": -2.3572413267e-10,
}


_PARITY = (
    # IS-GPS-200 Table 20-XIV, written out again: (previous word's D29* or D30*, data bits)
    (29, (1, 2, 3, 5, 6, 10, 11, 12, 13, 14, 17, 18, 20, 23)),
    (30, (2, 3, 4, 6, 7, 11, 12, 13, 14, 15, 18, 19, 21, 24)),
    (29, (1, 3, 4, 5, 7, 8, 12, 13, 14, 15, 16, 19, 20, 22)),
    (30, (2, 4, 5, 6, 8, 9, 13, 14, 15, 16, 17, 20, 21, 23)),
    (30, (1, 3, 5, 6, 7, 9, 10, 14, 15, 16, 17, 18, 21, 22, 24)),
    (29, (3, 5, 6, 8, 9, 10, 11, 13, 15, 19, 22, 23, 24)),
)


def with_parity(words: tuple[int, ...]) -> tuple[int, ...]:
    """The ten 24-bit data words as 30-bit words, each followed by its six parity bits (the
    word before the first taken as ending in D29* = D30* = 0, as a word 10 does)."""
    out, previous = [], (0, 0)
    for word in words:
        bits = [(word >> (23 - k)) & 1 for k in range(24)]
        parity = 0
        for which, terms in _PARITY:
            bit = previous[0] if which == 29 else previous[1]
            for n in terms:
                bit ^= bits[n - 1]
            parity = (parity << 1) | bit
        out.append((word << 6) | parity)
        previous = ((parity >> 1) & 1, parity & 1)
    return tuple(out)


def sfrbx(prn: int, words: tuple[int, ...], flip: int | None = None, gnss_id: int = 0) -> bytes:
    """A UBX RXM-SFRBX frame carrying one GPS (``gnss_id`` 5: QZSS) L1 C/A subframe (24-bit data
    words, each in bits 29…6 of its ``dwrd`` followed by its parity bits); ``flip``: one bit
    (0…299, bit 0 the first word's most significant) inverted after the parity was computed."""
    full = list(with_parity(tuple(words)))
    if flip is not None:
        full[flip // 30] ^= 1 << (29 - flip % 30)
    dwrd = {f"dwrd_{k + 1:02d}": word for k, word in enumerate(full)}
    return UBXMessage(
        "RXM",
        "RXM-SFRBX",
        0,
        gnssId=gnss_id,
        svId=prn,
        sigId=0,
        numWords=10,
        chn=4,
        version=2,
        **dwrd,
    ).serialize()
