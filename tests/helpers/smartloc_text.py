"""Synthetic smartLoc raw CSV text for tests: the format's header (its 34 column names, an
interface fact) and rows made from chosen values."""

from __future__ import annotations

from dataclasses import dataclass, field

HEADER_NAMES = (
    "GPSWeek [weeks]",
    "GPSSecondsOfWeek [s]",
    "Longitude (GT Lon) [deg]",
    "Longitude Cov (GT Lon) [deg]",
    "Latitude (GT Lat) [deg]",
    "Latitude Cov (GT Lat) [deg]",
    "Height above ellipsoid (GT Height) [m]",
    "Height above ellipsoid Cov (GT Height) [m]",
    "Heading (0° = East, counterclockwise) - (GT Heading) [rad]",
    "Heading Cov (0° = East, counterclockwise) - (GT Heading) [rad]",
    "Acceleration (GT Acceleration) [ms^2]",
    "Acceleration Cov (GT Acceleration) [ms^2]",
    "Velocity (GT Velocity) [m/s]",
    "Velocity Cov (GT Velocity) [m/s]",
    "Yaw-Rate (GT Yaw-rate) [rad/s]",
    "Yaw-Rate Cov (GT Yaw-rate) [rad/s]",
    "Measurement time of week (rcvTow) [s]",
    "GPS week number (week) [weeks]",
    "GPS leap seconds (leapS) [s]",
    "Number of measurements to follow (numMeas) []",
    "Receiver tracking status (recStat) []",
    "Pseudorange measurement (prMes) [m]",
    "Carrier phase measurement (cpMes) [cycles]",
    "Doppler measurement (doMes) [Hz]",
    "GNSS identifier (gnssId) []",
    "Satellite identifier (svId) []",
    "Frequency slot - only Glonass (freqId) []",
    "Carrier phase locktime counter (locktime) [ms]",
    "Carrier-to-noise density ratio (cno) [dbHz]",
    "Estimated pseudorange measurement standard deviation (prStdev) [m]",
    "Estimated carrier phase measurement standard deviation (cpStdev) [cycles]",
    "Estimated Doppler measurement standard deviation (doStdev) [Hz]",
    "Tracking status (trkStat) []",
    "NLOS (0 == no, 1 == yes, # == No Information)",
)
HEADER = ";".join(HEADER_NAMES)
WEEK = 1900


@dataclass
class Truth:
    """One epoch's ground-truth state as the file writes it."""

    tow: float
    lon: float = 13.37
    lat: float = 52.5
    height: float = 76.0
    heading: float = 1.25
    acceleration: float = 0.5
    speed: float = 5.7
    yaw_rate: float = 0.01


@dataclass
class Measurement:
    gnss: str = "GPS"
    sv: int = 12
    doppler_hz: float = 222.1658
    doppler_sigma_hz: float = 0.128
    pseudorange_m: float = 2.0e7
    carrier_cycles: float = 1.04e8
    freq_id: int = 0
    cn0: float = 45.0
    tracking: int = 15
    nlos: str = "0"
    extra: dict[str, str] = field(default_factory=dict)


def row(truth: Truth, m: Measurement, week: int = WEEK) -> str:
    """One data row: the epoch's ground truth and one measurement."""
    values = [
        week, repr(truth.tow), truth.lon, 1e-6, truth.lat, 1e-6, truth.height, 1e-6,
        truth.heading, 1e-7, truth.acceleration, 0.03, truth.speed, 2e-4, truth.yaw_rate, 5e-6,
        repr(truth.tow), week, 17, 19, 1, repr(m.pseudorange_m), repr(m.carrier_cycles),
        repr(m.doppler_hz), m.gnss, m.sv, m.freq_id, 64500, m.cn0, 0.32, 0.004,
        repr(m.doppler_sigma_hz), m.tracking, m.nlos,
    ]  # fmt: skip
    fields = [str(v) for v in values]
    for name, text in m.extra.items():
        fields[HEADER_NAMES.index(name)] = text
    return ";".join(fields)


def smartloc_text(epochs: list[tuple[Truth, list[Measurement]]]) -> str:
    lines = [HEADER] + [row(truth, m) for truth, ms in epochs for m in ms]
    return "\n".join(lines) + "\n"
