"""BeiDou B1I D1 navigation message subframes 1–3 (MEO and IGSO satellites) → broadcast ephemeris
records; the D2 message of the GEO satellites is recognised and not decoded.

BDS-SIS-ICD-B1I (version 3.0, 2019), D1 message: a subframe is ten 30-bit words. Word 1 is the
preamble 11100010010, 4 reserved bits, then 11 information bits (the subframe ID FraID and the 8
most significant bits of the seconds of week SOW) with 4 BCH(15,11,1) check bits; words 2–10
each carry 22 information bits in two BCH(15,11,1) codewords. u-blox RXM-SFRBX delivers the ten
words de-interleaved in bits 29…0 of its words (interface description, "BeiDou"): the 22
information bits, then the 4 check bits of the first 11 and the 4 of the second (:func:`bch_error`).

Check: each 15-bit codeword (11 information bits, the first sent the highest power, then its 4
check bits) must be a multiple of the code's generator g(x) = x⁴ + x + 1; a subframe with a
codeword that is not, or without the preamble, is refused.

The information bits (26 of word 1, 22 of each other word) hold the fields one after another
(:data:`SUBFRAMES`, the D1 subframe figures less the check bits): after Pre, Rev, FraID and
SOW, subframe 1 the health SatH1, AODC, URAI, the BDT week WN (13 bits), toc (2³ s), TGD1 and
TGD2 (0.1 ns), the Klobuchar α/β (not kept), a2 (2⁻⁶⁶ s/s²), a0 (2⁻³³ s), a1 (2⁻⁵⁰ s/s), AODE;
subframe 2 Δn (2⁻⁴³ semicircles/s), C_uc (2⁻³¹ rad), M0 (2⁻³¹ semicircles), e (2⁻³³), C_us, C_rc
and C_rs (2⁻⁶ m), √A (2⁻¹⁹ √m) and the 2 most significant bits of toe; subframe 3 the 15 least
significant bits of toe (toe in 2³ s), i0, C_ic, Ω-dot, C_is, IDOT, Ω0 and ω.

A record is made from subframes 1, 2 and 3 of one frame of a satellite (their SOW s, s + 6,
s + 12: the ephemeris only changes between frames) whose orbit is a BeiDou orbit
(:mod:`vo_doppler.bounds`) and whose toe falls in the years RINEX holds (a 13-bit week reaches
2163); a repeated (PRN, AODE, toe) is made once. D1 is sent by PRN 6–58;
PRN 1–5 and 59–63 (GEO) send D2, whose ephemeris is spread over ten pages of subframe 1 at
0.6 s: not decoded (counted by the caller).

Time: BDT counts weeks from 2006-01-01 00:00:00 UTC, when GPS time was week 1356 and 14 s
(BDT = GPST − 14 s); toe and toc are the BDT times with their seconds of week nearest subframe
1's WN and SOW, kept in GPS seconds (``toe``, the record's ``toc``) and as BDT seconds of week
(``toe_sow``) and BDT week (``week``), as RINEX writes them. RINEX 3.05 BeiDou record names:
``iode`` AODE, ``health`` SatH1, ``accuracy`` the URA of URAI (the GPS table), ``tgd`` TGD1,
``iodc`` (RINEX's TGD2 slot) TGD2, ``transmission_sow`` subframe 1's SOW, ``fit_interval``
(RINEX's AODC slot) AODC.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from vo_doppler.bounds import BEIDOU_ECCENTRICITY, BEIDOU_INCLINATION, BEIDOU_SQRT_A
from vo_doppler.io.gps_lnav import (
    KEPLER_NAMES,
    URA_METERS,
    kepler_records,
    off_orbit,
    time_of_week_near,
)
from vo_doppler.io.nav_fields import ICD_PI, Field, read_fields
from vo_doppler.io.rinex_common import LAST_YEAR
from vo_doppler.model.gpstime import BDT_MINUS_GPST_S, SECONDS_PER_WEEK, calendar_to_gps_seconds
from vo_doppler.model.navigation import NavRecords

PREAMBLE = 0b11100010010
BDT_WEEK_OFFSET = 1356
"""GPS week of BDT week 0 (2006-01-01)."""
BCH_GENERATOR = 0b10011
INFO_BITS = 26 + 9 * 22
SUBFRAME_S = 6.0
LATEST_GPS_S = float(calendar_to_gps_seconds(LAST_YEAR + 1, 1, 1, 0, 0, 0))
"""The end of the years a RINEX file holds: a 13-bit BDT week reaches 2163."""
BEIDOU_ORBIT = (
    ("sqrt_a", BEIDOU_SQRT_A),
    ("e", BEIDOU_ECCENTRICITY),
    ("i0", BEIDOU_INCLINATION),
)
SC = ICD_PI  # semicircles → radians

_HEADER: tuple[Field, ...] = (
    ("pre", 11, False, 1.0),
    (None, 4, False, 1.0),
    ("fraid", 3, False, 1.0),
    ("sow", 20, False, 1.0),
)
SUBFRAMES: dict[int, tuple[Field, ...]] = {
    1: (
        *_HEADER,
        ("sath1", 1, False, 1.0),
        ("aodc", 5, False, 1.0),
        ("urai", 4, False, 1.0),
        ("wn", 13, False, 1.0),
        ("toc_sow", 17, False, 8.0),
        ("tgd1", 10, True, 1.0e-10),
        ("tgd2", 10, True, 1.0e-10),
        (None, 64, False, 1.0),  # Klobuchar α0–α3, β0–β3
        ("af2", 11, True, 2.0**-66),
        ("af0", 24, True, 2.0**-33),
        ("af1", 22, True, 2.0**-50),
        ("aode", 5, False, 1.0),
    ),
    2: (
        *_HEADER,
        ("delta_n", 16, True, 2.0**-43 * SC),
        ("cuc", 18, True, 2.0**-31),
        ("m0", 32, True, 2.0**-31 * SC),
        ("e", 32, False, 2.0**-33),
        ("cus", 18, True, 2.0**-31),
        ("crc", 18, True, 2.0**-6),
        ("crs", 18, True, 2.0**-6),
        ("sqrt_a", 32, False, 2.0**-19),
        ("toe_msb", 2, False, 1.0),
    ),
    3: (
        *_HEADER,
        ("toe_lsb", 15, False, 1.0),
        ("i0", 32, True, 2.0**-31 * SC),
        ("cic", 18, True, 2.0**-31),
        ("omega_dot", 24, True, 2.0**-43 * SC),
        ("cis", 18, True, 2.0**-31),
        ("idot", 14, True, 2.0**-43 * SC),
        ("omega0", 32, True, 2.0**-31 * SC),
        ("omega", 32, True, 2.0**-31 * SC),
        (None, 1, False, 1.0),
    ),
}
"""Fields of the information bits of D1 subframes 1–3 (name, bits, signed, scale)."""


def is_geo(prn: int) -> bool:
    """Whether a BeiDou PRN is a GEO satellite's, which sends D2."""
    return prn <= 5 or prn >= 59


def _bch_remainder(codeword: int) -> int:
    """The remainder of a 15-bit codeword (the first bit the x¹⁴ term) divided by g(x)."""
    for power in range(14, 3, -1):
        if codeword >> power & 1:
            codeword ^= BCH_GENERATOR << (power - 4)
    return codeword


def bch_error(words: list[int]) -> int | None:
    """The number (1…10) of the first word with a BCH codeword that is not one, or None."""
    for number, word in enumerate(words[:10], start=1):
        word &= 0x3FFFFFFF
        if number == 1:
            codewords = [word & 0x7FFF]
        else:
            first, second = word >> 19, word >> 8 & 0x7FF
            codewords = [first << 4 | (word >> 4) & 0xF, second << 4 | word & 0xF]
        if any(_bch_remainder(c) for c in codewords):
            return number
    return None


def information_bits(words: list[int]) -> int:
    """The 224 information bits of a subframe: word 1's first 26, then 22 of each other word."""
    bits = (words[0] & 0x3FFFFFFF) >> 4
    for word in words[1:10]:
        bits = (bits << 22) | ((word & 0x3FFFFFFF) >> 8)
    return bits


def subframe_id(words: list[int]) -> int:
    """FraID of a subframe, 0 without the preamble."""
    header = read_fields(information_bits(words), INFO_BITS, _HEADER)
    return int(header["fraid"]) if int(header["pre"]) == PREAMBLE else 0


def decode_subframe(words: list[int]) -> dict[str, float]:
    """The fields of D1 subframe 1, 2 or 3 (module docstring)."""
    number = subframe_id(words)
    if number not in SUBFRAMES:
        raise ValueError(f"subframe {number} is not an ephemeris subframe")
    return read_fields(information_bits(words), INFO_BITS, SUBFRAMES[number])


def bdt_to_gps(bdt_seconds: float) -> float:
    """BDT seconds since its origin → GPS seconds."""
    return bdt_seconds + BDT_WEEK_OFFSET * SECONDS_PER_WEEK - BDT_MINUS_GPST_S


@dataclass
class D1Assembler:
    """D1 subframes per satellite → records (module docstring)."""

    records: list[dict[str, float]] = field(default_factory=list)
    rejected: list[tuple[int, int, str]] = field(default_factory=list)
    """(where, PRN, why) of each refused subframe or subframe set."""
    n_almanac: int = 0
    """Subframes 4 and 5 (almanac, not decoded)."""
    frames: dict[int, dict[int, dict[str, float]]] = field(default_factory=dict)
    emitted: set[tuple[int, int, float]] = field(default_factory=set)

    def add(self, prn: int, words: list[int], where: int) -> None:
        """One D1 subframe of satellite ``prn`` (MEO or IGSO); ``where`` (a byte offset or
        message index) names it in :attr:`rejected` and in the record it completes."""
        word = bch_error(words)
        if word is not None:
            self.rejected.append((where, prn, f"word {word} fails the BCH check"))
            return
        number = subframe_id(words)
        if number == 0:
            self.rejected.append((where, prn, "no preamble"))
        if number not in SUBFRAMES:
            self.n_almanac += number != 0
            return
        frames = self.frames.setdefault(prn, {})
        frames[number] = decode_subframe(words)
        if len(frames) == 3:
            one, two, three = frames[1], frames[2], frames[3]
            sow = one["sow"]
            if two["sow"] == sow + SUBFRAME_S and three["sow"] == sow + 2 * SUBFRAME_S:
                self._record(prn, one, two, three, where)

    def navrecords(self) -> NavRecords:
        """The records with the parameter names of the RINEX navigation reader."""
        return kepler_records("C", self.records)

    def _record(self, prn: int, one, two, three, where: int) -> None:
        toe_sow = (int(two["toe_msb"]) << 15 | int(three["toe_lsb"])) * 8.0
        key = (prn, int(one["aode"]), toe_sow)
        if key in self.emitted:
            return
        self.emitted.add(key)
        why = off_orbit(two | three, BEIDOU_ORBIT)
        if max(toe_sow, one["toc_sow"], one["sow"]) >= SECONDS_PER_WEEK:
            why = f"toe {toe_sow:g} s, toc {one['toc_sow']:g} s or SOW is no time of week"
        if why:
            self.rejected.append((where, prn, why))
            return
        sent = one["wn"] * SECONDS_PER_WEEK + one["sow"]
        toe = time_of_week_near(sent, toe_sow)
        if bdt_to_gps(toe) >= LATEST_GPS_S:
            self.rejected.append((where, prn, f"BDT week {int(one['wn'])} is after {LAST_YEAR}"))
            return
        merged = one | two | three
        self.records.append(
            {name: merged[name] for name in KEPLER_NAMES if name in merged}
            | {
                "iode": one["aode"],
                "toe_sow": toe_sow,
                "codes": 0.0,
                "week": float(toe // SECONDS_PER_WEEK),
                "l2p_flag": 0.0,
                "accuracy": URA_METERS[int(one["urai"])],
                "health": one["sath1"],
                "tgd": one["tgd1"],
                "iodc": one["tgd2"],
                "transmission_sow": one["sow"],
                "fit_interval": one["aodc"],
                "toe": bdt_to_gps(toe),
                "toc": bdt_to_gps(time_of_week_near(sent, one["toc_sow"])),
                "prn": float(prn),
                "where": float(where),
            }
        )
