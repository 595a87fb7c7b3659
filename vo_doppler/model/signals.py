"""Carrier frequencies of GNSS signals by RINEX band (RINEX 3.05 sec. 5.1 / Table 4): interface
facts that the readers (a Doppler in Hz → m/s) and the GNSS stage (:mod:`vo_doppler.gnss.signals`)
share, like GPS time's constants in :mod:`vo_doppler.model.gpstime`.

The band is the second character of an observable code ('D1C' → band 1, RINEX 2 'D2' → band 2).
GLONASS FDMA bands depend on the frequency channel k: G1 = 1602 + 0.5625·k MHz,
G2 = 1246 + 0.4375·k MHz (ICD-GLONASS 5.1 sec. 3.3.1.4).

BeiDou's band digits changed between RINEX versions (:func:`beidou_band`, :func:`beidou_signal`):
B1I (1561.098 MHz) is band 2 in RINEX 3.01 (C2I), band 1 in 3.02 (C1I, sec. 5.1), band 2 again
from 3.03 on ("BeiDou B1 observation codes changed back to the RINEX 3.01 convention", 3.03
release notes); RINEX 3.04 (Table 9) gives band 1 to B1C (1575.42 MHz, attributes D P X), band
5 to B2a, band 7 to B2I (I Q X) and B2b (D P Z), band 8 to B2a+b and band 6 to B3I (I Q X);
RINEX 3.05 (Table 19) adds the authorised B1A (band 1: S L Z) and B3A (band 6: D P Z).
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


BEIDOU_B1I_BAND_1_BEFORE = 3.03
"""RINEX versions below this one (3.02; 3.01 never wrote band 1) label BeiDou B1I band 1."""


def beidou_band(code: str, rinex_version: float) -> str:
    """The band digit of a BeiDou observable ``code`` ('C1I', 'D7I', RINEX-2-like 'C2') in a
    RINEX file of ``rinex_version``, as RINEX 3.03 on numbers the bands: B1I's band 1 of
    RINEX 3.02 is band 2 (module docstring)."""
    band = code[1:2]
    return "2" if band == "1" and rinex_version < BEIDOU_B1I_BAND_1_BEFORE else band


def beidou_signal(code: str, rinex_version: float) -> str | None:
    """The BeiDou signal ('B1I', 'B1C', 'B1A', 'B2a', 'B2I', 'B2b', 'B2a+b', 'B3I', 'B3A') of an
    observable ``code`` in a RINEX file of ``rinex_version`` (module docstring), None for a
    band BeiDou does not use. The version rule is :func:`beidou_band`'s, as the carrier
    frequencies' (:func:`carrier_frequency`)."""
    band, attribute = beidou_band(code, rinex_version), code[2:3]
    data_pilot = attribute in ("D", "P", "Z")
    signals = {
        "2": "B1I",
        "1": "B1A" if attribute in ("S", "L", "Z") else "B1C",
        "5": "B2a",
        "7": "B2b" if data_pilot else "B2I",
        "8": "B2a+b",
        "6": "B3A" if data_pilot else "B3I",
    }
    return signals.get(band)


def carrier_frequency(
    system: str, code: str, glonass_channel: int | None = None, rinex_version: float = 3.04
) -> float | None:
    """Carrier frequency (Hz) of an observable, or None when it cannot be known."""
    band = beidou_band(code, rinex_version) if system == "C" else code[1:2]
    if system == "R" and band in GLONASS_FDMA:
        if glonass_channel is None:
            return None
        base, step = GLONASS_FDMA[band]
        return base + step * glonass_channel
    return FREQUENCIES_HZ.get(system, {}).get(band)
