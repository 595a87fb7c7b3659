"""GLONASS navigation string encoder for tests: the inverse of vo_doppler.io.glonass_strings.

Independent of the decoder: the field positions (ICD GLONASS 5.1 Table 4.5) and the bits each
check bit covers (sec. 4.7, listed as the ICD lists them) are written out again here, so a
mistake in one is caught by the other (and the decoder is also checked on a receiver's strings).
"""

from __future__ import annotations

import numpy as np
from pyubx2 import UBXMessage

from vo_doppler.model.gpstime import (
    SECONDS_PER_DAY,
    days_from_civil,
    gps_minus_utc,
    utc_to_gps_seconds,
)

KM = 1000.0
SCALES = {  # RINEX name (SI) → LSB
    **{axis: 2.0**-11 * KM for axis in ("x", "y", "z")},
    **{f"v{axis}": 2.0**-20 * KM for axis in "xyz"},
    **{f"a{axis}": 2.0**-30 * KM for axis in "xyz"},
    "minus_tau_n": 2.0**-30,
    "gamma_n": 2.0**-40,
    "delta_tau_n": 2.0**-30,
}


def _ranges(*spans: tuple[int, int]) -> tuple[int, ...]:
    return tuple(i for low, high in spans for i in range(low, high + 1))


CHECK_BITS = (  # β1…β7: the data bits b9…b85 each covers (ICD sec. 4.7)
    (9, 10, 12, 13, 15, 17, 19, 20, 22, 24, 26, 28, 30, 32, 34, 35, 37, 39, 41, 43, 45, 47, 49,
     51, 53, 55, 57, 59, 61, 63, 65, 66, 68, 70, 72, 74, 76, 78, 80, 82, 84),
    (9, 11, 12, 14, 15, 18, 19, 21, 22, 25, 26, 29, 30, 33, 34, 36, 37, 40, 41, 44, 45, 48, 49,
     52, 53, 56, 57, 60, 61, 64, 65, 67, 68, 71, 72, 75, 76, 79, 80, 83, 84),
    _ranges((10, 12), (16, 19), (23, 26), (31, 34), (38, 41), (46, 49), (54, 57), (62, 65),
            (69, 72), (77, 80), (85, 85)),
    _ranges((13, 19), (27, 34), (42, 49), (58, 65), (73, 80)),
    _ranges((20, 34), (50, 65), (81, 85)),
    _ranges((35, 65)),
    _ranges((66, 85)),
)  # fmt: skip


def _put(string: int, lowest_bit: int, width: int, value: int, signed: bool = False) -> int:
    """``string`` with ``value`` in ICD bits lowest_bit … lowest_bit + width − 1."""
    if signed:
        assert abs(value) < 1 << (width - 1), (value, width)
        value = (1 << (width - 1)) | -value if value < 0 else value
    assert 0 <= value < 1 << width, (value, width)
    return string | (value << (lowest_bit - 1))


def with_check_bits(string: int) -> int:
    """The string (bits 9–85 set, 1–8 zero) with its check bits β1…β8."""
    bit = [0] + [(string >> (n - 1)) & 1 for n in range(1, 86)]
    for k, covered in enumerate(CHECK_BITS, start=1):
        string |= (sum(bit[i] for i in covered) & 1) << (k - 1)
    return string | ((string.bit_count() & 1) << 7)  # β8: the whole string of even parity


def quantised(params: dict[str, float]) -> dict[str, float]:
    """The values the strings can carry (each parameter rounded to its LSB)."""
    return {k: (round(v / SCALES[k]) * SCALES[k] if k in SCALES else v) for k, v in params.items()}


def _moscow(utc: float) -> tuple[int, float]:
    """(day NT of the four-year interval, seconds of the day) in Moscow time of a UTC time
    (counted as GPS seconds are)."""
    day, seconds = divmod(utc + 3 * 3600.0, SECONDS_PER_DAY)
    first = int(days_from_civil(1996, 1, 1) - days_from_civil(1980, 1, 6))
    return (int(day) - first) % 1461 + 1, seconds


def encode_strings(slot: int, toc: float, params: dict[str, float]) -> list[int]:
    """Strings 1–4 of a GLONASS record (RINEX names in SI units, ``toc`` tb in GPS time,
    ``frame_time`` the frame's seconds of the UTC week; optional ``bn`` and ``ln``, else the
    health's bit as Bn's most significant one)."""
    p = {k: round(v / SCALES[k]) if k in SCALES else v for k, v in params.items()}
    tb_utc = toc - float(gps_minus_utc(toc))
    tb, rest = divmod(_moscow(tb_utc)[1], 900.0)
    assert rest == 0, "tb on a quarter hour"
    week = 7 * SECONDS_PER_DAY
    frame_utc = tb_utc + (params["frame_time"] - tb_utc + week / 2) % week - week / 2
    nt, tk = _moscow(frame_utc)  # NT: the frame's day
    assert tk % 30 == 0, "frame time on 30 s"
    hours, minutes = divmod(int(tk // 60), 60)
    bn = int(params.get("bn", 4 * int(params["health"])))
    one = _put(_put(_put(1 << 80, 72, 5, hours), 66, 6, minutes), 65, 1, int(tk % 60 // 30))
    two = _put(_put(2 << 80, 78, 3, bn), 70, 7, int(tb))
    three = _put(_put(3 << 80, 69, 11, p["gamma_n"], True), 65, 1, int(params.get("ln", 0)))
    strings = [one, two, three]
    for k, axis in enumerate("xyz"):
        strings[k] = _put(strings[k], 41, 24, p[f"v{axis}"], True)
        strings[k] = _put(strings[k], 36, 5, p[f"a{axis}"], True)
        strings[k] = _put(strings[k], 9, 27, p[axis], True)
    four = _put(4 << 80, 59, 22, -p["minus_tau_n"], True)
    four = _put(four, 54, 5, p.get("delta_tau_n", 0), True)
    four = _put(four, 49, 5, int(params["age"]))
    four = _put(four, 30, 4, int(params.get("urai", 0)))
    four = _put(four, 16, 11, nt)
    four = _put(four, 11, 5, slot)
    return [with_check_bits(s) for s in (*strings, four)]


def sfrbx_words(string: int, superframe: int = 0, frame: int = 0) -> list[int]:
    """The four RXM-SFRBX words of a string: bits 85–54, 53–22, 21–1 (then 11 zero bits), and
    the receiver's superframe and frame numbers."""
    return [
        (string >> 53) & 0xFFFFFFFF,
        (string >> 21) & 0xFFFFFFFF,
        (string & 0x1FFFFF) << 11,
        (superframe << 16) | frame,
    ]


def ubx_sfrbx(slot: int, channel: int, string: int, sig_id: int = 0) -> bytes:
    """A UBX RXM-SFRBX frame carrying one GLONASS string."""
    dwrd = {f"dwrd_{k + 1:02d}": w for k, w in enumerate(sfrbx_words(string))}
    return UBXMessage(
        "RXM",
        "RXM-SFRBX",
        0,
        gnssId=6,
        svId=slot,
        sigId=sig_id,
        freqId=channel + 7,
        numWords=4,
        chn=9,
        version=2,
        **dwrd,
    ).serialize()


EXAMPLE = {
    # a GLONASS-M record (m, m/s, m/s², s): a circular prograde orbit of 64.8° inclination
    "x": 12_345_678.125,
    "y": -15_432_109.875,
    "z": 16_001_234.5,
    "vx": 1870.4286,
    "vy": -1172.8019,
    "vz": -2574.2088,
    "ax": 1.8626451e-06,
    "ay": -9.3132257e-07,
    "az": 2.7939677e-06,
    "minus_tau_n": -1.2345678e-05,
    "gamma_n": 9.094947e-13,
    "delta_tau_n": 2.7939677e-09,
    "health": 0.0,
    "age": 2.0,
    "urai": 3.0,
}


def example_at(toc: float, frame_before_s: float = 900.0) -> dict[str, float]:
    """:data:`EXAMPLE` with the frame time ``frame_before_s`` before tb (``toc``, GPS)."""
    utc = toc - float(gps_minus_utc(toc)) - frame_before_s
    return EXAMPLE | {"frame_time": utc % (7 * SECONDS_PER_DAY)}


def tb_quarter_hour(gps: float) -> float:
    """The GPS time of the tb (a quarter hour of UTC) at or after ``gps``, with the leap seconds
    in force at that quarter hour (a leap second between ``gps`` and it counts)."""
    quarter = np.ceil((gps - float(gps_minus_utc(gps))) / 900.0) * 900.0
    return float(utc_to_gps_seconds(quarter))
