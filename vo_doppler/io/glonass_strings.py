"""GLONASS L1/L2 C/A navigation strings 1–4 (the immediate data) → broadcast ephemeris records.

ICD GLONASS (edition 5.1, 2008): a string is 85 bits, bit 85 (sent first) the idle chip, bits
84–81 the string number m, bits 8–1 the Hamming check bits β8…β1 (sec. 4.3.1); the layout and
scale factors of the immediate data are Tables 4.5 and 4.9. A number with a sign is sent as
sign and magnitude: its most significant bit 1 means negative. Strings here are integers whose
bit n − 1 is ICD bit n.

Check (sec. 4.7, Table 4.13): the checksums c1…c7 (each β_k and the data bits b9…b85 that a
Hamming code of positions 3, 5, 6, 7, 9, … gives it: data bit b_i sits at the (i − 8)-th
position that is not a power of two, and enters c_k when that position has bit k − 1 set) and
cΣ (every bit of the string). All zero, or one c_k = 1 with cΣ = 1 (a check bit hit): the data
are right. Two or more c_k = 1 with cΣ = 1: bit icor = c7…c1 + 8 − K is inverted, K the number
of the highest c_k = 1, if icor ≤ 85. Any other case (some c_k = 1 with cΣ = 0, or cΣ = 1 alone)
is a multiple error: the string is refused.

Fields (SI units): string 1: tk (hours 76–72, minutes 71–66, 30-s flag 65), ẋ (64–41, 2⁻²⁰
km/s), ẍ (40–36, 2⁻³⁰ km/s²), x (35–9, 2⁻¹¹ km); string 2: Bn (80–78), tb (76–70, 15 min), y;
string 3: γn (79–69, 2⁻⁴⁰), ln (65), z; string 4: τn (80–59, 2⁻³⁰ s), Δτn (58–54, 2⁻³⁰ s), En
(53–49, days), FT (33–30), NT (26–16, day), n (15–11, the slot).

A record is made when strings 1, 2, 3 and 4 of a satellite arrive one after another (the
immediate data of one 30-s frame, sent within 8 s; a string missing or refused starts the
satellite over), in RINEX 3 terms (:class:`~vo_doppler.io.rinex_write.GlonassRecord`):
``minus_tau_n`` = −τn, ``gamma_n`` = γn, ``frame_time`` = tk in seconds of the UTC week,
``x``…``az``, ``health`` = 1 when the most significant bit of Bn (RINEX 3.05: the health) or ln
(the GLONASS-M's own unhealthy flag) is set, ``channel`` = the frequency number the receiver
tracked, ``age`` = En; ``delta_tau_n`` and ``urai`` (FT) for the RINEX 3.05 fifth line.

Time: tk and tb count in Moscow time (UTC(SU) + 3 h) from the start of the day NT, which counts
the days of a four-year interval from 1 January of a leap year. The interval is the one putting
NT nearest the recording's GPS time (``reference``), so string 5 (N4, τc, τGPS) is not needed;
tb is taken within 12 h of tk, and the record's epoch is tb in GPS time (leap seconds added).

A record is refused (and named) when its slot n is not the receiver's, NT, tb or tk are not
times of a day, tb lies more than :data:`MAX_TB_FROM_FRAME_S` from the frame time (tb is the
middle of the interval in which the frame is sent), or the orbit is not a GLONASS orbit (the
RINEX navigation reader's bounds). A repeated (slot, tb) is emitted once: every frame repeats it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from vo_doppler.io.rinex_nav import GLONASS_FIELDS, GLONASS_MAX_SPEED_KM_S, GLONASS_RADIUS_KM
from vo_doppler.model.gpstime import (
    SECONDS_PER_DAY,
    SECONDS_PER_WEEK,
    calendar_to_gps_seconds,
    utc_to_gps_seconds,
)
from vo_doppler.model.navigation import NavRecords

STRING_BITS = 85
MOSCOW_MINUS_UTC_S = 3 * 3600.0
FOUR_YEARS_DAYS = 1461
MAX_TB_FROM_FRAME_S = 3600.0
"""Largest |tk − tb| accepted: tb is the middle of a 30, 45 or 60-min interval (P1) that holds
the frame, so a frame is at most 30 min from its tb; an hour allows an interval's overlap."""
KM = 1000.0
GLONASS_NAMES = tuple(name for group in GLONASS_FIELDS for name in group)


def _state(axis: str) -> tuple[tuple[str, int, int, bool, float], ...]:
    """The velocity, acceleration and position of one axis (strings 1–3, the same bits)."""
    return (
        (f"v{axis}", 64, 24, True, 2.0**-20 * KM),
        (f"a{axis}", 40, 5, True, 2.0**-30 * KM),
        (axis, 35, 27, True, 2.0**-11 * KM),
    )


_FIELDS: dict[int, tuple[tuple[str, int, int, bool, float], ...]] = {
    # string m → (name, highest ICD bit, bits, sign-magnitude, scale to SI)
    1: (
        ("tk_hours", 76, 5, False, 1.0),
        ("tk_minutes", 71, 6, False, 1.0),
        ("tk_half", 65, 1, False, 1.0),
        *_state("x"),
    ),
    2: (
        ("bn", 80, 3, False, 1.0),
        ("tb", 76, 7, False, 1.0),
        *_state("y"),
    ),
    3: (
        ("gamma_n", 79, 11, True, 2.0**-40),
        ("ln", 65, 1, False, 1.0),
        *_state("z"),
    ),
    4: (
        ("tau_n", 80, 22, True, 2.0**-30),
        ("delta_tau_n", 58, 5, True, 2.0**-30),
        ("age", 53, 5, False, 1.0),
        ("urai", 33, 4, False, 1.0),
        ("nt", 26, 11, False, 1.0),
        ("slot", 15, 5, False, 1.0),
    ),
}


def _hamming_position(data_bit: int) -> int:
    """Position in the Hamming code of data bit b9…b85: the (i − 8)-th that is no power of 2."""
    position, count = 2, 0
    while count < data_bit - 8:
        position += 1
        count += position & (position - 1) != 0
    return position


_CHECK_MASKS = tuple(
    (1 << (k - 1))
    | sum(1 << (i - 1) for i in range(9, STRING_BITS + 1) if _hamming_position(i) >> (k - 1) & 1)
    for k in range(1, 8)
)
"""Per checksum c_k (k = 1…7): the bits of β_k and of the data bits it covers."""


def check_string(bits: int) -> int | None:
    """The string with a single data-bit error corrected (a check bit hit is left as it is: the
    data are right), or None when the check finds more (module docstring, ICD sec. 4.7)."""
    bits &= (1 << STRING_BITS) - 1
    syndrome = sum(((bits & mask).bit_count() & 1) << k for k, mask in enumerate(_CHECK_MASKS))
    total = bits.bit_count() & 1
    if total == 0 or syndrome == 0:
        return bits if total == syndrome == 0 else None
    if syndrome & (syndrome - 1) == 0:
        return bits  # one checksum: a check bit was hit, the data are right
    icor = syndrome + 8 - syndrome.bit_length()
    return bits ^ (1 << (icor - 1)) if icor <= STRING_BITS else None


def string_number(bits: int) -> int:
    """The string number m (ICD bits 84–81)."""
    return (bits >> 80) & 0xF


def decode_string(bits: int) -> dict[str, float]:
    """The immediate-data fields of string 1, 2, 3 or 4 (module docstring), in SI units."""
    number = string_number(bits)
    if number not in _FIELDS:
        raise ValueError(f"string {number} holds no immediate data")
    out = {"string": float(number)}
    for name, high, width, signed, scale in _FIELDS[number]:
        value = (bits >> (high - width)) & ((1 << width) - 1)
        if signed and value >> (width - 1):
            value = -(value & ((1 << (width - 1)) - 1))
        out[name] = value * scale
    return out


def sfrbx_string(words: list[int]) -> int:
    """The 85-bit string of a u-blox RXM-SFRBX GLONASS message: ICD bits 85–54 in the first
    32-bit word, 53–22 in the second, 21–1 in bits 31–11 of the third (u-blox interface
    description, "GLONASS navigation data"); the fourth holds frame numbers, not used."""
    return (
        ((words[0] & 0xFFFFFFFF) << 53)
        | ((words[1] & 0xFFFFFFFF) << 21)
        | ((words[2] & 0xFFFFFFFF) >> 11)
    )


@dataclass
class GlonassAssembler:
    """Strings per slot → records (module docstring); ``reference`` a GPS time of the recording."""

    reference: float
    records: list[tuple[int, float, dict[str, float], int]] = field(default_factory=list)
    """(slot, tb in GPS seconds, RINEX parameters, where) of each record."""
    rejected: list[tuple[int, int, str]] = field(default_factory=list)
    """(where, slot, why) of each refused string or record."""
    chains: dict[tuple[int, int], list[dict[str, float]]] = field(default_factory=dict)
    emitted: set[tuple[int, float]] = field(default_factory=set)

    def add(self, slot: int, channel: int, bits: int, where: int, signal: int = 0) -> None:
        """One string of the satellite in ``slot`` tracked on frequency number ``channel``
        (``signal``: the receiver's signal, L1 or L2, each a string stream of its own);
        ``where`` (a byte offset or message index) names it in :attr:`rejected`."""
        key = (slot, signal)
        checked = check_string(bits)
        if checked is None:
            self.chains.pop(key, None)
            self.rejected.append((where, slot, "string fails the Hamming check"))
            return
        number = string_number(checked)
        if number not in _FIELDS:
            return
        chain = self.chains.pop(key, [])
        if number == 1:
            chain = [decode_string(checked)]
        elif len(chain) == number - 1:
            chain.append(decode_string(checked))
        else:
            return
        if len(chain) < 4:
            self.chains[key] = chain
        else:
            self._record(slot, channel, chain, where)

    def navrecords(self) -> NavRecords:
        """The records with the GLONASS parameter names of the RINEX navigation reader (the
        RINEX 3.05 status and health flags, which strings 1–4 do not hold, NaN)."""
        rows = self.records
        return NavRecords(
            np.full(len(rows), "R", dtype="U1"),
            np.array([slot for slot, _, _, _ in rows], dtype=np.int16),
            np.array([toc for _, toc, _, _ in rows], dtype=float),
            {
                name: np.array([p.get(name, np.nan) for _, _, p, _ in rows], dtype=float)
                for name in GLONASS_NAMES
            },
            np.array([where for _, _, _, where in rows], dtype=np.int64),
        )

    def _record(self, slot: int, channel: int, chain, where: int) -> None:
        one, two, three, four = chain
        fields = one | two | three | four
        why = _refusal(slot, channel, fields)
        if why:
            self.rejected.append((where, slot, why))
            return
        frame_utc = self._frame_time(fields)
        tb_utc = frame_utc + _tb_from_frame(fields)
        toc = float(utc_to_gps_seconds(tb_utc))
        if (slot, toc) in self.emitted:
            return
        self.emitted.add((slot, toc))
        params = {name: fields[name] for axis in "xyz" for name, *_ in _state(axis)}
        params |= {
            "minus_tau_n": -fields["tau_n"],
            "gamma_n": fields["gamma_n"],
            "frame_time": frame_utc % SECONDS_PER_WEEK,
            "health": float(int(fields["bn"]) >> 2 | int(fields["ln"])),
            "channel": float(channel),
            "age": fields["age"],
            "delta_tau_n": fields["delta_tau_n"],
            "urai": fields["urai"],
        }
        self.records.append((slot, toc, params, where))

    def _frame_time(self, fields: dict[str, float]) -> float:
        """The frame time tk as UTC calendar seconds (counted as GPS seconds are), on the day
        NT of the four-year interval nearest :attr:`reference`."""
        interval = float(calendar_to_gps_seconds(1996, 1, 1, 0, 0, 0))
        day = interval + (fields["nt"] - 1) * SECONDS_PER_DAY - MOSCOW_MINUS_UTC_S
        span = FOUR_YEARS_DAYS * SECONDS_PER_DAY
        day += span * round((self.reference - day) / span)
        return day + _tk(fields)


def _tk(fields: dict[str, float]) -> float:
    """The frame time tk in seconds of its (Moscow) day."""
    return fields["tk_hours"] * 3600.0 + fields["tk_minutes"] * 60.0 + fields["tk_half"] * 30.0


def _tb_from_frame(fields: dict[str, float]) -> float:
    """tb − tk (s), tb taken within 12 h of tk."""
    apart = fields["tb"] * 900.0 - _tk(fields)
    return apart - SECONDS_PER_DAY * round(apart / SECONDS_PER_DAY)


def _refusal(slot: int, channel: int, fields: dict[str, float]) -> str:
    """Why four strings cannot be one satellite's ephemeris ('' when they can)."""
    if int(fields["slot"]) != slot:
        return f"string 4 is of slot {int(fields['slot'])}"
    if not -7 <= channel <= 6:
        return f"frequency number {channel} outside -7…6"
    if not (1 <= fields["nt"] <= FOUR_YEARS_DAYS and fields["tb"] <= 95):
        return f"day NT {int(fields['nt'])} or tb {int(fields['tb'])} is no time"
    if fields["tk_hours"] > 23 or fields["tk_minutes"] > 59:
        return f"frame time {int(fields['tk_hours'])} h {int(fields['tk_minutes'])} min"
    apart = abs(_tb_from_frame(fields))
    if apart > MAX_TB_FROM_FRAME_S:
        return f"tb {int(fields['tb'])} is {apart / 60:.0f} min from the frame time"
    radius = (fields["x"] ** 2 + fields["y"] ** 2 + fields["z"] ** 2) ** 0.5 / KM
    speed = (fields["vx"] ** 2 + fields["vy"] ** 2 + fields["vz"] ** 2) ** 0.5 / KM
    if not GLONASS_RADIUS_KM[0] <= radius <= GLONASS_RADIUS_KM[1]:
        return f"orbit radius {radius:.0f} km is no GLONASS orbit"
    if speed > GLONASS_MAX_SPEED_KM_S:
        return f"speed {speed:.2f} km/s is no GLONASS orbit"
    return ""
