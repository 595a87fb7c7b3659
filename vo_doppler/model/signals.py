"""Carrier frequencies of GNSS signals by RINEX band (RINEX 3.05 sec. 5.1 / Table 4): interface
facts that the readers (a Doppler in Hz → m/s) and the GNSS stage (:mod:`vo_doppler.gnss.signals`)
share, like GPS time's constants in :mod:`vo_doppler.model.gpstime`.

The band is the second character of an observable code ('D1C' → band 1, RINEX 2 'D2' → band 2).
GLONASS FDMA bands depend on the frequency channel k: G1 = 1602 + 0.5625·k MHz,
G2 = 1246 + 0.4375·k MHz (ICD-GLONASS 5.1 sec. 3.3.1.4). In RINEX 3.02 BeiDou B1I was band 1;
from 3.03 on it is band 2 (band 1 is B1C).
"""

from __future__ import annotations

from enum import StrEnum


class SatelliteSystem(StrEnum):
    """The GNSS systems by their RINEX letter (RINEX 3.05 sec. 3.5), in the order the readers
    index them."""

    GPS = "G"
    GLONASS = "R"
    GALILEO = "E"
    BEIDOU = "C"
    QZSS = "J"
    SBAS = "S"
    NAVIC = "I"


DEFAULT_SYSTEMS = "GREJC"
"""The systems a run uses unless told otherwise (``--systems``): those the GNSS stage has
ephemerides and signals for in the recordings met so far."""

MHZ = 1e6
FREQUENCIES_HZ: dict[str, dict[str, float]] = {
    "G": {"1": 1575.42 * MHZ, "2": 1227.60 * MHZ, "5": 1176.45 * MHZ},
    "E": {
        "1": 1575.42 * MHZ,
        "5": 1176.45 * MHZ,
        "7": 1207.14 * MHZ,
        "8": 1191.795 * MHZ,
        "6": 1278.75 * MHZ,
    },
    "C": {
        "1": 1575.42 * MHZ,
        "2": 1561.098 * MHZ,
        "5": 1176.45 * MHZ,
        "7": 1207.14 * MHZ,
        "8": 1191.795 * MHZ,
        "6": 1268.52 * MHZ,
    },
    "J": {"1": 1575.42 * MHZ, "2": 1227.60 * MHZ, "5": 1176.45 * MHZ, "6": 1278.75 * MHZ},
    "S": {"1": 1575.42 * MHZ, "5": 1176.45 * MHZ},
    "I": {"5": 1176.45 * MHZ, "9": 2492.028 * MHZ},
    "R": {"3": 1202.025 * MHZ, "4": 1600.995 * MHZ, "6": 1248.06 * MHZ},
}
GLONASS_FDMA = {"1": (1602.0 * MHZ, 0.5625 * MHZ), "2": (1246.0 * MHZ, 0.4375 * MHZ)}


def carrier_frequency(
    system: str, code: str, glonass_channel: int | None = None, rinex_version: float = 3.04
) -> float | None:
    """Carrier frequency (Hz) of an observable, or None when it cannot be known."""
    band = code[1:2]
    if system == "C" and band == "1" and rinex_version < 3.03:
        band = "2"
    if system == "R" and band in GLONASS_FDMA:
        if glonass_channel is None:
            return None
        base, step = GLONASS_FDMA[band]
        return base + step * glonass_channel
    return FREQUENCIES_HZ.get(system, {}).get(band)
