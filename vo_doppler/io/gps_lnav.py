"""GPS L1 C/A navigation message (LNAV) subframes 1–3 → broadcast ephemeris records.

Bit layout and scale factors: IS-GPS-200 sec. 20.3.3.3 (subframe 1, Table 20-I) and 20.3.3.4
(subframes 2 and 3, Table 20-III), Figure 20-1. A subframe is given here as its ten 24-bit data
words (parity stripped); ICD bit n (1…300, parity included) is data bit
24·⌊(n−1)/30⌋ + (n−1) mod 30 of the 240. Angles in semicircles are multiplied by the ICD's
π = 3.1415926535898.

Parity (sec. 20.3.5.2, Table 20-XIV): each 30-bit word's six parity bits D25…D30 are the
Hamming code of its 24 source data bits d1…d24 and the last two parity bits D29*, D30* of the
word before it (for word 1, those of the previous subframe's word 10, which its two
non-information bits make zero); :func:`parity_error` finds the first word whose parity does
not match, as any one flipped bit makes it.

An ephemeris is emitted when subframes 1, 2 and 3 of one satellite agree on their issue of data
(IODE of 2 and 3 = the 8 LSBs of IODC, sec. 20.3.4.4) and describe an orbit of the system
(:func:`off_orbit`: semi-major axis, eccentricity and inclination of the constellation,
:mod:`vo_doppler.bounds`); a repeated (PRN, IODC, toe) is emitted once. Not
decoded: subframes 4 and 5 (almanac, ionosphere and UTC parameters, pages of sec. 20.3.3.5).
The 10-bit week number is resolved with a full GPS week from the same recording.

QZSS L1 C/A (IS-QZSS-PNT) sends the same subframes 1–3 with the same layout and scales on GPS
time: an assembler made with ``system="J"`` decodes them (PRN 193–202 as J01–J10), checks QZSS
orbits, and keeps the fit interval flag itself, as the RINEX 3.05 QZSS record holds it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.bounds import (
    GPS_ECCENTRICITY,
    GPS_INCLINATION,
    GPS_SQRT_A,
    QZSS_ECCENTRICITY,
    QZSS_INCLINATION,
    QZSS_SQRT_A,
    SignalBounds,
)
from vo_doppler.io.nav_fields import ICD_PI
from vo_doppler.io.rinex_nav import KEPLER_FIELDS
from vo_doppler.model.gpstime import SECONDS_PER_WEEK
from vo_doppler.model.navigation import NavRecords

GPS_PI = ICD_PI
PREAMBLE = 0x8B
URA_METERS = (2.4, 3.4, 4.85, 6.85, 9.65, 13.65, 24.0, 48.0, 96.0, 192.0, 384.0, 768.0)
URA_METERS += (1536.0, 3072.0, 6144.0, np.nan)
KEPLER_NAMES = (*(name for group in KEPLER_FIELDS for name in group), "toe")

# (name, first ICD bit, [(first bit, n bits) …] most significant part first, signed, scale)
_SUBFRAME_FIELDS: dict[int, tuple[tuple[str, tuple[tuple[int, int], ...], bool, float], ...]] = {
    1: (
        ("week10", ((61, 10),), False, 1.0),
        ("codes", ((71, 2),), False, 1.0),
        ("ura_index", ((73, 4),), False, 1.0),
        ("health", ((77, 6),), False, 1.0),
        ("iodc", ((83, 2), (211, 8)), False, 1.0),
        ("l2p_flag", ((91, 1),), False, 1.0),
        ("tgd", ((197, 8),), True, 2.0**-31),
        ("toc_sow", ((219, 16),), False, 2.0**4),
        ("af2", ((241, 8),), True, 2.0**-55),
        ("af1", ((249, 16),), True, 2.0**-43),
        ("af0", ((271, 22),), True, 2.0**-31),
    ),
    2: (
        ("iode", ((61, 8),), False, 1.0),
        ("crs", ((69, 16),), True, 2.0**-5),
        ("delta_n", ((91, 16),), True, 2.0**-43 * GPS_PI),
        ("m0", ((107, 8), (121, 24)), True, 2.0**-31 * GPS_PI),
        ("cuc", ((151, 16),), True, 2.0**-29),
        ("e", ((167, 8), (181, 24)), False, 2.0**-33),
        ("cus", ((211, 16),), True, 2.0**-29),
        ("sqrt_a", ((227, 8), (241, 24)), False, 2.0**-19),
        ("toe_sow", ((271, 16),), False, 2.0**4),
        ("fit_flag", ((287, 1),), False, 1.0),
    ),
    3: (
        ("cic", ((61, 16),), True, 2.0**-29),
        ("omega0", ((77, 8), (91, 24)), True, 2.0**-31 * GPS_PI),
        ("cis", ((121, 16),), True, 2.0**-29),
        ("i0", ((137, 8), (151, 24)), True, 2.0**-31 * GPS_PI),
        ("crc", ((181, 16),), True, 2.0**-5),
        ("omega", ((197, 8), (211, 24)), True, 2.0**-31 * GPS_PI),
        ("omega_dot", ((241, 24),), True, 2.0**-43 * GPS_PI),
        ("iode", ((271, 8),), False, 1.0),
        ("idot", ((279, 14),), True, 2.0**-43 * GPS_PI),
    ),
}


_PARITY_TERMS = (
    # (D29* or D30*, source data bits d1…d24): IS-GPS-200 Table 20-XIV, D25 first
    (29, (1, 2, 3, 5, 6, 10, 11, 12, 13, 14, 17, 18, 20, 23)),
    (30, (2, 3, 4, 6, 7, 11, 12, 13, 14, 15, 18, 19, 21, 24)),
    (29, (1, 3, 4, 5, 7, 8, 12, 13, 14, 15, 16, 19, 20, 22)),
    (30, (2, 4, 5, 6, 8, 9, 13, 14, 15, 16, 17, 20, 21, 23)),
    (30, (1, 3, 5, 6, 7, 9, 10, 14, 15, 16, 17, 18, 21, 22, 24)),
    (29, (3, 5, 6, 8, 9, 10, 11, 13, 15, 19, 22, 23, 24)),
)


def lnav_parity(data: int, d29: int, d30: int) -> int:
    """The six parity bits (D25 as the most significant) of the 24 source data bits ``data``
    (d1 the most significant) after a word ending in the bits ``d29``, ``d30``."""
    parity = 0
    for previous, terms in _PARITY_TERMS:
        bit = d29 if previous == 29 else d30
        for n in terms:
            bit ^= (data >> (24 - n)) & 1
        parity = (parity << 1) | bit
    return parity


def parity_error(words30: tuple[int, ...]) -> int | None:
    """The number (1…10) of the first 30-bit word (24 data bits, then 6 parity bits) whose
    parity is wrong, or None when all ten match (module docstring)."""
    d29 = d30 = 0
    for number, word in enumerate(words30, start=1):
        if lnav_parity((word >> 6) & 0xFFFFFF, d29, d30) != word & 0x3F:
            return number
        d29, d30 = (word >> 1) & 1, word & 1
    return None


GPS_ORBIT = (("sqrt_a", GPS_SQRT_A), ("e", GPS_ECCENTRICITY), ("i0", GPS_INCLINATION))
QZSS_ORBIT = (("sqrt_a", QZSS_SQRT_A), ("e", QZSS_ECCENTRICITY), ("i0", QZSS_INCLINATION))
ORBITS = {"G": GPS_ORBIT, "J": QZSS_ORBIT}


def off_orbit(fields: dict[str, float], orbit: tuple[tuple[str, SignalBounds], ...]) -> str | None:
    """Why decoded fields cannot be an orbit of the system whose bounds ``orbit`` lists (√a,
    eccentricity, inclination), or None."""
    for name, bounds in orbit:
        if name in fields and bounds.outside(np.array([fields[name]]))[0]:
            return f"{name} = {fields[name]:.6g} is outside {bounds}"
    return None


def data_bit(icd_bit: int) -> int:
    """Index (0…239) among the 240 data bits of ICD bit number ``icd_bit`` (1…300)."""
    word, position = divmod(icd_bit - 1, 30)
    if position >= 24:
        raise ValueError(f"ICD bit {icd_bit} is a parity bit")
    return 24 * word + position


def _bits(words: tuple[int, ...], icd_bit: int, n_bits: int) -> int:
    value = 0
    for k in range(n_bits):
        index = data_bit(icd_bit + k)
        word, position = divmod(index, 24)
        value = (value << 1) | ((words[word] >> (23 - position)) & 1)
    return value


def subframe_id(words: tuple[int, ...]) -> int:
    """Subframe ID of the handover word (ICD bits 50–52), 0 when the preamble is wrong."""
    if (words[0] >> 16) & 0xFF != PREAMBLE:
        return 0
    return _bits(words, 50, 3)


def decode_subframe(words: tuple[int, ...]) -> dict[str, float]:
    """Fields of subframe 1, 2 or 3 (SI units, radians), plus ``tow`` of the handover word (s)."""
    number = subframe_id(words)
    if number not in _SUBFRAME_FIELDS:
        raise ValueError(f"subframe {number} is not an ephemeris subframe")
    out = {"subframe": float(number), "tow": 6.0 * _bits(words, 31, 17)}
    for name, parts, signed, scale in _SUBFRAME_FIELDS[number]:
        value, width = 0, 0
        for first, n_bits in parts:
            value = (value << n_bits) | _bits(words, first, n_bits)
            width += n_bits
        if signed and value >> (width - 1):
            value -= 1 << width
        out[name] = value * scale
    return out


@dataclass
class LnavAssembler:
    """Collects subframes per satellite and emits complete, consistent ephemerides."""

    records: list[dict[str, float]]
    pending: dict[int, dict[int, dict[str, float]]]
    emitted: set[tuple[int, int, float]]
    rejected: list[tuple[int, int, str]]
    """(where, PRN, why) of each subframe set whose orbit is not one of the system's."""
    system: str = "G"
    """'G' GPS, or 'J' QZSS (IS-QZSS-PNT: the same subframes 1–3, PRN 193–202 as J01–J10)."""

    @classmethod
    def new(cls, system: str = "G") -> LnavAssembler:
        return cls([], {}, set(), [], system)

    def add(self, prn: int, words: tuple[int, ...], reference_week: int | None, where: int) -> None:
        """One subframe of satellite ``prn``; ``where`` (e.g. a byte offset) is kept per record."""
        fields = decode_subframe(words)
        frames = self.pending.setdefault(prn, {})
        frames[int(fields["subframe"])] = fields
        if len(frames) < 3 or reference_week is None:
            return
        one, two, three = frames[1], frames[2], frames[3]
        iode = int(one["iodc"]) & 0xFF
        if not int(two["iode"]) == int(three["iode"]) == iode:
            return
        key = (prn, int(one["iodc"]), two["toe_sow"])
        if key in self.emitted:
            return
        why = off_orbit(two | three, ORBITS[self.system])
        if why is not None:
            self.rejected.append((where, prn, why))
            return
        self.emitted.add(key)
        record = _record(prn, one, two, three, reference_week, where)
        if self.system == "J":  # the RINEX 3.05 QZSS record holds the fit interval flag itself
            record["fit_interval"] = two["fit_flag"]
        self.records.append(record)

    def navrecords(self) -> NavRecords:
        """The emitted ephemerides with the parameter names of the RINEX navigation reader."""
        return kepler_records(self.system, self.records)


def kepler_records(system: str, rows: list[dict[str, float]]) -> NavRecords:
    """Records of one system from rows holding :data:`KEPLER_NAMES` (``toc`` and ``toe`` in GPS
    seconds), ``prn`` and ``where`` (a byte offset or message index, kept as the record's line)."""
    params = {name: np.array([r[name] for r in rows], dtype=float) for name in KEPLER_NAMES}
    return NavRecords(
        np.full(len(rows), system, dtype="U1"),
        np.array([r["prn"] for r in rows], dtype=np.int16),
        np.array([r["toc"] for r in rows], dtype=float),
        params,
        np.array([r["where"] for r in rows], dtype=np.int64),
    )


def _record(prn, one, two, three, reference_week, where) -> dict[str, float]:
    """RINEX-named parameters; weeks resolved near ``reference_week`` (sec. 20.3.3.3.1.1)."""
    week = reference_week - ((reference_week - int(one["week10"])) % 1024)
    if reference_week - week > 512:
        week += 1024
    transmission_sow = one["tow"] - 6.0
    t_tx = week * SECONDS_PER_WEEK + transmission_sow
    toc = time_of_week_near(t_tx, one["toc_sow"])
    toe = time_of_week_near(toc, two["toe_sow"])
    return {
        **{k: v for k, v in (one | two | three).items() if k in KEPLER_NAMES},
        "iode": two["iode"],
        "week": float(week),
        "accuracy": URA_METERS[int(one["ura_index"])],
        "transmission_sow": transmission_sow,
        "fit_interval": 6.0 if two["fit_flag"] else 4.0,
        "toe": toe,
        "toc": toc,
        "prn": prn,
        "where": where,
    }


def time_of_week_near(reference: float, seconds_of_week: float) -> float:
    """The time with the given second of week nearest to ``reference`` (any system's time
    counted in weeks from its own origin)."""
    delta = seconds_of_week - np.mod(reference, SECONDS_PER_WEEK)
    delta -= SECONDS_PER_WEEK * np.round(delta / SECONDS_PER_WEEK)
    return float(reference + delta)
