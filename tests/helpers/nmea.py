"""Hand-built NMEA 0183 sentences with valid checksums, for the NMEA reader's tests."""

from __future__ import annotations

import datetime as dt
import functools
import operator


def sentence(body: str) -> str:
    """``$BODY*hh``: the checksum is the XOR of the body's bytes."""
    checksum = functools.reduce(operator.xor, body.encode(), 0)
    return f"${body}*{checksum:02X}"


def _ddmm(value: float, positive: str, negative: str, width: int) -> tuple[str, str]:
    hemisphere = positive if value >= 0 else negative
    value = abs(value)
    degrees = int(value)
    minutes = (value - degrees) * 60.0
    return f"{degrees:0{width}d}{minutes:010.7f}", hemisphere


def gga(time: dt.time, lat: float, lon: float, quality: int = 1) -> str:
    """A GGA fix (quality 0: no fix)."""
    la, ns = _ddmm(lat, "N", "S", 2)
    lo, ew = _ddmm(lon, "E", "W", 3)
    stamp = time.strftime("%H%M%S.%f")[:9]
    return sentence(f"GPGGA,{stamp},{la},{ns},{lo},{ew},{quality},08,0.9,10.0,M,30.0,M,,")


def rmc(moment: dt.datetime, lat: float, lon: float, knots: float, status="A") -> str:
    """An RMC fix with its date and speed over ground (status V: no fix)."""
    la, ns = _ddmm(lat, "N", "S", 2)
    lo, ew = _ddmm(lon, "E", "W", 3)
    stamp = moment.strftime("%H%M%S.%f")[:9]
    day = moment.strftime("%d%m%y")
    return sentence(f"GPRMC,{stamp},{status},{la},{ns},{lo},{ew},{knots:.2f},45.0,{day},,,A")


def vtg(kmh: float | None, knots: float | None = None, mode: str | None = "A") -> str:
    """A VTG (course 45 deg) with its speed over ground in km/h and knots (None: empty field;
    knots default to the km/h converted) and mode indicator (None: the NMEA 2.2 form without)."""
    if knots is None and kmh is not None:
        knots = kmh / 1.852
    speeds = ["" if v is None else f"{v:.6f}" for v in (knots, kmh)]
    fields = ["GPVTG", "45.0", "T", "", "M", speeds[0], "N", speeds[1], "K"]
    return sentence(",".join(fields + ([] if mode is None else [mode])))
