"""Galileo I/NAV pages (E1-B and E5b-I) → broadcast ephemeris records.

Galileo OS SIS ICD (Issue 2.0, 2021), I/NAV page layout: a page is an even part (even/odd flag
0, page type, 112 data bits, 6 tail bits) and an odd part (even/odd flag 1, page type, 16 data
bits, 40 bits OSNMA/reserved, 22 SAR, 2 spare, CRC 24, 8 SSP/reserved, 6 tail bits), 120 bits
each. u-blox RXM-SFRBX delivers a page as eight 32-bit words (interface description, "Galileo
E1 C/B" and "Galileo E5b"): the even part in the first four, the odd part in the last four, each
followed by 8 padding bits (:func:`sfrbx_page`).

Check: the CRC-24Q (generator polynomial 0x1864CFB, no initial value) of the even part's 114
bits before its tail and the odd part's first 82 bits must equal the odd part's CRC; a page
failing it, or whose parts are not flagged even then odd, is refused.
Alert pages (page type 1) hold no word and are skipped.

A word is the even part's 112 data bits then the odd part's 16, its type the first 6 bits
(:data:`WORDS`, the ICD's I/NAV word tables): 1–4 the ephemeris and clock, each with the issue of
data IODnav; 5 the ionosphere, the broadcast group delays BGD(E1,E5a) and BGD(E1,E5b), the
signal health (HS) and data validity (DVS) of E5b and E1-B, and the GST week WN and time of week
TOW; 0 (with its time field 2) the GST week and time of week too. Scales: t0e and t0c 60 s, M0,
Ω0, i0, ω 2⁻³¹ semicircles, Δn, i-dot 2⁻⁴³ semicircles/s, Ω-dot 2⁻⁴³ semicircles/s, e 2⁻³³, √A
2⁻¹⁹ √m, C_uc…C_is 2⁻²⁹ rad, C_rc, C_rs 2⁻⁵ m, af0 2⁻³⁴ s, af1 2⁻⁴⁶ s/s, af2 2⁻⁵⁹ s/s², BGD
2⁻³² s.

A record is made from words 1–4 of one satellite with one IODnav (words of another IODnav are
never combined with them) and the satellite's latest word 5; word 4's SVID must be the
satellite's, t0e and t0c must be seconds of a week, and the orbit a Galileo orbit
(:mod:`vo_doppler.bounds`). A repeated (SVID, IODnav, t0e) is made once.

Time: GST counts weeks from GPS week 1024 and runs on GPS time (its offset, nanoseconds, is
neglected), so the GST of the latest word 5 or 0 is GPS week WN + 1024 and TOW; toe and toc are
the times with their seconds of week nearest it. The 12-bit WN wraps in 2078.

RINEX 3.05 Galileo record names: ``iode`` IODnav, ``codes`` the data sources (bit 0 E1-B, bit 2 E5b
of the pages of words 1–4, bit 9: the clock is for E5b/E1), ``week`` the GAL week of toe (GPS
week numbering), ``accuracy`` the SISA in metres (−1 for none, NAPA), ``health`` (bit 0 E1-B
DVS, bits 1–2 E1-B HS, bit 6 E5b DVS, bits 7–8 E5b HS), ``tgd`` BGD(E1,E5a), ``iodc`` (RINEX's
slot) BGD(E1,E5b), ``transmission_sow`` the second of week of the GST used.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from vo_doppler.bounds import GALILEO_ECCENTRICITY, GALILEO_INCLINATION, GALILEO_SQRT_A
from vo_doppler.io.gps_lnav import KEPLER_NAMES, kepler_records, off_orbit, time_of_week_near
from vo_doppler.io.nav_fields import ICD_PI, Field, read_fields
from vo_doppler.model.gpstime import SECONDS_PER_WEEK
from vo_doppler.model.navigation import NavRecords

GST_WEEK_OFFSET = 1024
"""GPS week of GST week 0 (1999-08-22)."""
PART_BITS = 120
WORD_BITS = 128
CRC24Q = 0x1864CFB
E1B, E5B = 0, 1
"""Index of the signal a page came from (its data-source bit is 1 << 2 · index)."""
SIGNALS = {0: E1B, 1: E1B, 5: E5B}
"""u-blox sigId of the pages decoded: 0 (an M8's E1, reported without a signal), 1 E1-B, 5 E5b-I."""
GALILEO_ORBIT = (
    ("sqrt_a", GALILEO_SQRT_A),
    ("e", GALILEO_ECCENTRICITY),
    ("i0", GALILEO_INCLINATION),
)
SC = ICD_PI  # semicircles → radians

WORDS: dict[int, tuple[Field, ...]] = {
    1: (
        ("iodnav", 10, False, 1.0),
        ("toe_sow", 14, False, 60.0),
        ("m0", 32, True, 2.0**-31 * SC),
        ("e", 32, False, 2.0**-33),
        ("sqrt_a", 32, False, 2.0**-19),
        (None, 2, False, 1.0),
    ),
    2: (
        ("iodnav", 10, False, 1.0),
        ("omega0", 32, True, 2.0**-31 * SC),
        ("i0", 32, True, 2.0**-31 * SC),
        ("omega", 32, True, 2.0**-31 * SC),
        ("idot", 14, True, 2.0**-43 * SC),
        (None, 2, False, 1.0),
    ),
    3: (
        ("iodnav", 10, False, 1.0),
        ("omega_dot", 24, True, 2.0**-43 * SC),
        ("delta_n", 16, True, 2.0**-43 * SC),
        ("cuc", 16, True, 2.0**-29),
        ("cus", 16, True, 2.0**-29),
        ("crc", 16, True, 2.0**-5),
        ("crs", 16, True, 2.0**-5),
        ("sisa", 8, False, 1.0),
    ),
    4: (
        ("iodnav", 10, False, 1.0),
        ("svid", 6, False, 1.0),
        ("cic", 16, True, 2.0**-29),
        ("cis", 16, True, 2.0**-29),
        ("toc_sow", 14, False, 60.0),
        ("af0", 31, True, 2.0**-34),
        ("af1", 21, True, 2.0**-46),
        ("af2", 6, True, 2.0**-59),
        (None, 2, False, 1.0),
    ),
    5: (
        (None, 11 + 11 + 14 + 5, False, 1.0),  # NeQuick ai0, ai1, ai2 and the region flags
        ("bgd_e5a", 10, True, 2.0**-32),
        ("bgd_e5b", 10, True, 2.0**-32),
        ("e5b_hs", 2, False, 1.0),
        ("e1b_hs", 2, False, 1.0),
        ("e5b_dvs", 1, False, 1.0),
        ("e1b_dvs", 1, False, 1.0),
        ("wn", 12, False, 1.0),
        ("tow", 20, False, 1.0),
        (None, 23, False, 1.0),
    ),
    0: (
        ("time", 2, False, 1.0),
        (None, 88, False, 1.0),
        ("wn", 12, False, 1.0),
        ("tow", 20, False, 1.0),
    ),
}
"""Fields of each word type after its 6-bit type (name, bits, signed, scale)."""


def _crc_table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        remainder = byte << 16
        for _ in range(8):
            remainder <<= 1
            if remainder & 1 << 24:
                remainder ^= CRC24Q
        table.append(remainder & 0xFFFFFF)
    return tuple(table)


_CRC_TABLE = _crc_table()


def crc24q(bits: int, n_bits: int) -> int:
    """CRC-24Q of ``n_bits`` bits (the first the most significant), zeros in front of them
    making whole bytes (they leave the remainder unchanged)."""
    crc = 0
    for byte in bits.to_bytes((n_bits + 7) // 8, "big"):
        crc = ((crc << 8) & 0xFFFFFF) ^ _CRC_TABLE[(crc >> 16) ^ byte]
    return crc


def sfrbx_page(words: list[int]) -> tuple[int, int]:
    """(even part, odd part) of an RXM-SFRBX Galileo page: 120 bits each, from the eight
    32-bit words (each part's last 8 bits of padding dropped)."""
    value = 0
    for word in words[:8]:
        value = (value << 32) | (word & 0xFFFFFFFF)
    return value >> (128 + 8), (value >> 8) & ((1 << PART_BITS) - 1)


def _part(bits: int, first: int, n_bits: int) -> int:
    """``n_bits`` bits of a 120-bit page part from its bit ``first`` (0 the first sent)."""
    return (bits >> (PART_BITS - first - n_bits)) & ((1 << n_bits) - 1)


def page_problem(even: int, odd: int) -> str | None:
    """Why the page parts cannot be a nominal I/NAV page, or None."""
    if _part(even, 0, 1) != 0 or _part(odd, 0, 1) != 1:
        return "page parts not even then odd"
    covered = (_part(even, 0, 114) << 82) | _part(odd, 0, 82)
    if crc24q(covered, 196) != _part(odd, 82, 24):
        return "page fails the CRC-24Q check"
    return None


def is_alert(even: int, odd: int) -> bool:
    """Whether a page is an alert page (page type 1)."""
    return bool(_part(even, 1, 1) or _part(odd, 1, 1))


def page_word(even: int, odd: int) -> int:
    """The 128-bit word of a page: the even part's 112 data bits, then the odd part's 16."""
    return (_part(even, 2, 112) << 16) | _part(odd, 2, 16)


def decode_word(word: int) -> dict[str, float]:
    """The fields of word type 0–5 (module docstring), plus ``type``."""
    number = word >> (WORD_BITS - 6)
    if number not in WORDS:
        raise ValueError(f"word type {number} holds no ephemeris")
    return {"type": float(number)} | read_fields(word, WORD_BITS - 6, WORDS[number])


def sisa_metres(index: int) -> float:
    """SISA (m) of its 8-bit index (the ICD's SISA table: 1 cm steps to 0.49 m, 2 cm to 0.98 m,
    4 cm to 1.96 m, 16 cm to 6 m); −1 for the spare indices and NAPA (no accuracy prediction)."""
    if index < 50:
        return index * 0.01
    if index < 75:
        return 0.5 + (index - 50) * 0.02
    if index < 100:
        return 1.0 + (index - 75) * 0.04
    if index < 126:
        return 2.0 + (index - 100) * 0.16
    return -1.0


@dataclass
class InavAssembler:
    """Pages per satellite → records (module docstring)."""

    records: list[dict[str, float]] = field(default_factory=list)
    rejected: list[tuple[int, int, str]] = field(default_factory=list)
    """(where, SVID, why) of each refused page or word set."""
    n_alert: int = 0
    sets: dict[int, dict[int, dict[int, dict[str, float]]]] = field(default_factory=dict)
    """Words 1–4 per SVID and IODnav, each with the signals of its pages, until they make a
    record (or are refused)."""
    status: dict[int, dict[str, float]] = field(default_factory=dict)
    """Per SVID: the latest word 5 and the latest GST (from word 5 or 0)."""
    emitted: set[tuple[int, int, float]] = field(default_factory=set)

    def add(self, svid: int, signal: int, words: list[int], where: int) -> None:
        """One RXM-SFRBX page of satellite ``svid`` from signal ``signal`` (:data:`E1B` or
        :data:`E5B`); ``where`` (a byte offset or message index) names it in :attr:`rejected`
        and in the record it completes."""
        even, odd = sfrbx_page(words)
        why = page_problem(even, odd)
        if why:
            self.rejected.append((where, svid, why))
            return
        if is_alert(even, odd):
            self.n_alert += 1
            return
        word = page_word(even, odd)
        number = word >> (WORD_BITS - 6)
        if number not in WORDS:
            return
        fields = decode_word(word)
        status = self.status.setdefault(svid, {})
        if number == 5:
            status |= fields
        if number in (0, 5) and (number == 5 or fields["time"] == 2):
            status["gst"] = (fields["wn"] + GST_WEEK_OFFSET) * SECONDS_PER_WEEK + fields["tow"]
        sets = self.sets.setdefault(svid, {})
        if number in (1, 2, 3, 4):
            words_of = sets.setdefault(int(fields["iodnav"]), {})
            words_of.setdefault(number, fields)
            words_of[number]["sources"] = int(words_of[number].get("sources", 0)) | 1 << 2 * signal
        if "bgd_e5b" not in status or "gst" not in status:
            return
        for iodnav in [k for k, words_of in sets.items() if len(words_of) == 4]:
            self._record(svid, iodnav, sets.pop(iodnav), status, where)

    def navrecords(self) -> NavRecords:
        """The records with the parameter names of the RINEX navigation reader."""
        return kepler_records("E", self.records)

    def _record(self, svid, iodnav, words_of, status, where: int) -> None:
        one, two, three, four = (words_of[k] for k in (1, 2, 3, 4))
        key = (svid, iodnav, one["toe_sow"])
        if key in self.emitted:
            return
        self.emitted.add(key)
        why = off_orbit(one | two, GALILEO_ORBIT)
        if int(four["svid"]) != svid:
            why = f"word 4 is of E{int(four['svid']):02d}"
        elif max(one["toe_sow"], four["toc_sow"]) >= SECONDS_PER_WEEK:
            why = f"t0e {one['toe_sow']:g} s or t0c {four['toc_sow']:g} s is no time of week"
        if why:
            self.rejected.append((where, svid, why))
            return
        gst = status["gst"]
        toe = time_of_week_near(gst, one["toe_sow"])
        sources = 1 << 9
        for fields in (one, two, three, four):
            sources |= int(fields["sources"])
        health = int(status["e1b_dvs"]) | int(status["e1b_hs"]) << 1
        health |= int(status["e5b_dvs"]) << 6 | int(status["e5b_hs"]) << 7
        merged = one | two | three | four
        self.records.append(
            {name: merged[name] for name in KEPLER_NAMES if name in merged}
            | {
                "iode": float(iodnav),
                "codes": float(sources),
                "week": float(toe // SECONDS_PER_WEEK),
                "l2p_flag": 0.0,
                "accuracy": sisa_metres(int(three["sisa"])),
                "health": float(health),
                "tgd": status["bgd_e5a"],
                "iodc": status["bgd_e5b"],
                "transmission_sow": gst % SECONDS_PER_WEEK,
                "fit_interval": 0.0,
                "toe": toe,
                "toc": time_of_week_near(gst, four["toc_sow"]),
                "prn": float(svid),
                "where": float(where),
            }
        )
