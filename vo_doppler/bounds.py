"""The physical bounds of the project, in one place (a base-layer module): what a road
vehicle's motion sensors can report, how far its GNSS antenna can sit from its reference point,
where on Earth and when a recording can be, and what a GNSS receiver can measure of the
satellites it tracks (the second half of this module). Every reader checks its values against
them; the GNSS stage and the checks take :data:`RECEIVER_RADIUS` for "a position on Earth" (a
receiver position given or solved, the RINEX header's approximate position).

A value beyond these bounds is not a measurement: it is a corrupt row, a wrong unit or a wrong
DBC factor, and integrating it moves a dead-reckoned track by kilometres (one wheel-speed row of
1e9 m/s did). The bounds are wide on purpose, so that no real drive (a spin, a reversing
manoeuvre, the fastest production car) is refused:

* speed in [−10, 150] m/s: the fastest production cars reach about 136 m/s (490 km/h);
  reverse gears are geared for, and reversing driven at, well under 10 m/s (36 km/h);
* yaw rate within ±5 rad/s (286 °/s): tyre grip limits a car to about 1.5 rad/s (lateral
  acceleration ≈ 1 g at the smallest turning radius, ≈ 5 m), a spinning car reaches 2–3 rad/s,
  and the automotive yaw-rate sensors' full scale is ±100 to ±300 °/s;
* forward acceleration (an accelerometer's specific force) within ±50 m/s² (5 g): tyres allow
  about 1.5 g, the rest is margin for vibration and potholes;
* antenna lever arm at most 20 m long: the longest road vehicles (articulated buses, 18.75 m;
  EU lorries, 16.5 m) are shorter.

Readers skip and count isolated out-of-range samples, as they skip non-finite ones; when more
than :data:`MAX_OUT_OF_RANGE_FRACTION` of a signal is out of range the signal itself is wrong
(its unit or scale factor) and the reader raises an error instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.geo import SPEED_OF_LIGHT


@dataclass(frozen=True)
class SignalBounds:
    """The closed range ``[low, high]`` (SI ``unit``) a vehicle signal can take."""

    low: float
    high: float
    unit: str

    def outside(self, values: np.ndarray) -> np.ndarray:
        """Mask of the values outside the range (NaN counts as outside)."""
        values = np.asarray(values, dtype=float)
        return ~((values >= self.low) & (values <= self.high))

    def __str__(self) -> str:
        return f"[{self.low:g}, {self.high:g}] {self.unit}"


SPEED = SignalBounds(-10.0, 150.0, "m/s")
"""Vehicle (wheel, odometer, GNSS ground) speed, forward positive."""
GROUND_SPEED = SignalBounds(0.0, SPEED.high, "m/s")
"""Speed over ground as NMEA reports it: a magnitude, never negative; bounded like SPEED."""
YAW_RATE = SignalBounds(-5.0, 5.0, "rad/s")
"""Yaw rate, either sign."""
FORWARD_ACCELERATION = SignalBounds(-50.0, 50.0, "m/s²")
"""Specific force along the vehicle's forward axis (the same bound holds on every axis)."""
VELOCITY_COMPONENT = SignalBounds(-SPEED.high, SPEED.high, "m/s")
"""One component (north, east, up, left …) of a vehicle's velocity."""
ANGULAR_RATE = YAW_RATE
"""Roll and pitch rates: bounded as the yaw rate (the same gyro's full scale)."""

MAX_OUT_OF_RANGE_FRACTION = 0.01
"""Largest share of a signal's samples that may be out of range and skipped as isolated bad
samples; beyond it the whole signal is suspect (a wrong unit or factor) and is refused."""

MAX_LEVER_ARM_M = 20.0
"""Longest antenna lever arm (m): no road vehicle is longer."""


def too_many_out_of_range(n_out: int, n_total: int) -> bool:
    """Whether ``n_out`` of ``n_total`` samples out of range is more than isolated bad samples."""
    return n_out > MAX_OUT_OF_RANGE_FRACTION * n_total


def lever_arm_problem(arm) -> str | None:
    """Why an antenna lever arm (m, 2 or 3 components) cannot be a vehicle's, or None."""
    length = float(np.linalg.norm(np.asarray(arm, dtype=float)))
    if length > MAX_LEVER_ARM_M:
        return (
            f"the lever arm is {length:.4g} m long, beyond any road vehicle "
            f"({MAX_LEVER_ARM_M:g} m): give it in metres, from the vehicle's reference point"
        )
    return None


# Where and when: a road vehicle on the Earth, a recording of the GNSS era.

HEIGHT = SignalBounds(-1.0e3, 1.0e4, "m")
"""Ellipsoidal height of a road vehicle: the lowest road (Dead Sea shore, −430 m) and the
highest (about 5,800 m) with the geoid's ±110 m and a wide margin."""
LATITUDE_DEG = SignalBounds(-90.0, 90.0, "°")
LONGITUDE_DEG = SignalBounds(-180.0, 180.0, "°")
GPS_TIME = SignalBounds(0.0, 3.8e9, "s")
"""GPS seconds (since 1980-01-06) from the start of GPS time to 2100 (3.79e9 s)."""
TIME_OFFSET = SignalBounds(-GPS_TIME.high, GPS_TIME.high, "s")
"""A sensor clock's offset to GPS time: larger than every GPS time up to 2100, it would put the
sensor's data outside the GNSS era whatever its own clock reads (a Unix clock is −3.2e8 s away,
a monotonic log clock up to +3.8e9 s)."""

# GNSS measurements of a receiver on the ground.

RANGE_RATE = SignalBounds(-1.0e4, 1.0e4, "m/s")
"""Pseudorange rate: a GNSS satellite approaches or recedes from a point on the ground at most
about 1 km/s (GPS ≤ 930 m/s); with the vehicle's speed and a free-running receiver clock's drift
(a few ppm: a few km/s) it stays well within 10 km/s."""
HIGHEST_CARRIER_HZ = 1.61e9
"""The highest GNSS carrier (GLONASS G1, channel +6: 1605.4 MHz), rounded up."""
DOPPLER = SignalBounds(
    -RANGE_RATE.high * HIGHEST_CARRIER_HZ / SPEED_OF_LIGHT,
    RANGE_RATE.high * HIGHEST_CARRIER_HZ / SPEED_OF_LIGHT,
    "Hz",
)
"""Doppler shift of any GNSS carrier at the largest range rate (±53.7 kHz)."""
PSEUDORANGE = SignalBounds(1.0e6, 1.0e8, "m")
"""Pseudorange: 19,100 km (GLONASS at zenith) to 42,000 km (a geostationary satellite at the
horizon), widened for a receiver clock of a few milliseconds."""
SIGNAL_TRAVEL_TIME = SignalBounds(1.0e-3, 0.5, "s")
"""Signal travel time (pseudorange / c), the same bound as PSEUDORANGE widened."""
CN0 = SignalBounds(0.0, 100.0, "dB-Hz")
"""Carrier-to-noise density: real signals lie within 10–60 dB-Hz."""
CARRIER_PHASE = SignalBounds(-1.0e10, 1.0e10, "cycles")
"""Accumulated carrier phase: 1e10 cycles of L1 is 1.9e9 m (months of tracking at the largest
Doppler) and the most a RINEX F14.3 field holds."""
MEASUREMENT_SIGMA = SignalBounds(1.0e-9, 1.0e7, "SI")
"""A reported standard deviation (m, m/s, Hz, cycles): positive and finite; beyond 1e7 it says
nothing about the measurement."""
SATELLITE_ORBIT_RADIUS = SignalBounds(1.0e7, 5.0e7, "m")
"""Geocentric distance of a GNSS satellite (MEO 25,500–29,600 km, GEO/IGSO 42,200 km)."""
RECEIVER_RADIUS = SignalBounds(6.0e6, 7.0e6, "m")
"""Geocentric distance of a receiver on or near the ground (the Earth's radius is 6.357–6.378 Mm;
a position beyond these bounds is zeros, garbage or no receiver's, at most about 600 km up)."""
SATELLITE_SPEED = SignalBounds(0.0, 5.0e3, "m/s")
"""Speed of a GNSS satellite in the Earth-fixed frame (MEO about 3.9 km/s, GEO ≈ 0)."""
SATELLITE_CLOCK_BIAS = SignalBounds(-0.01, 0.01, "s")
"""A GNSS satellite clock stays within about 1 ms of system time."""
SATELLITE_CLOCK_DRIFT = SignalBounds(-1.0e-7, 1.0e-7, "s/s")
"""Satellite clock drift: broadcast af1 values are of order 1e-12–1e-10 s/s."""
GPS_SQRT_A = SignalBounds(5100.0, 5210.0, "√m")
"""√a of a GPS orbit: the constellation's semi-major axis is 26,560 km (√a = 5153.7 √m) within
about ±1 %."""
GPS_ECCENTRICITY = SignalBounds(0.0, 0.05, "")
"""GPS orbits are near circular (the specification allows e ≤ 0.02; the oldest satellites
reached 0.03)."""
GPS_INCLINATION = SignalBounds(0.87, 1.05, "rad")
"""GPS orbital planes are inclined 55° ± a few degrees (50°–60°)."""
GALILEO_SQRT_A = SignalBounds(5250.0, 5500.0, "√m")
"""√a of a Galileo orbit: 29,600 km (√a = 5440.6 √m), the two satellites left in eccentric
orbits 27,977 km (5289 √m)."""
GALILEO_ECCENTRICITY = SignalBounds(0.0, 0.2, "")
"""Galileo orbits are near circular, the two eccentric ones at e = 0.16."""
GALILEO_INCLINATION = SignalBounds(0.82, 1.05, "rad")
"""Galileo orbital planes are inclined 56°, the eccentric orbits 49.8°."""
BEIDOU_SQRT_A = SignalBounds(5200.0, 6550.0, "√m")
"""√a of a BeiDou orbit: MEO 27,906 km (5282.6 √m), IGSO and GEO 42,164 km (6493.4 √m)."""
BEIDOU_ECCENTRICITY = SignalBounds(0.0, 0.05, "")
"""BeiDou orbits are near circular."""
BEIDOU_INCLINATION = SignalBounds(-0.2, 1.05, "rad")
"""BeiDou MEO and IGSO planes are inclined 55°, GEO orbits a few degrees."""
QZSS_SQRT_A = SignalBounds(6400.0, 6600.0, "√m")
"""√a of a QZSS orbit: quasi-zenith and geostationary, 42,164 km (6493.4 √m)."""
QZSS_ECCENTRICITY = SignalBounds(0.0, 0.1, "")
"""QZSS quasi-zenith orbits have e ≈ 0.075, the geostationary one ≈ 0."""
QZSS_INCLINATION = SignalBounds(-0.2, 0.9, "rad")
"""QZSS quasi-zenith orbits are inclined about 41°, the geostationary one a few degrees."""
MAX_SATELLITES = 256
"""More satellites than all GNSS systems together have (about 220 numbers)."""

# Vehicle state estimates written by the toolkit (heading.csv).

HEADING_SIGMA_DEG = SignalBounds(1.0e-9, 180.0, "°")
"""A heading's standard deviation: positive; beyond 180° it says nothing about a direction."""
HEADING_DEG = SignalBounds(-360.0, 360.0, "°")
"""A heading or course in degrees as anyone writes it."""
WHEEL_SCALE = SignalBounds(1.0e-3, 1.0e3, "")
"""Wheel-speed scale as the calibration writes it: tyre radius, load and wear change it by a
few per cent, and a wrong unit (km/h read as m/s gives 0.278, mph 0.447) is absorbed by it
with a warning, the headings still right; from mm/s to km/s read as m/s, not zero or
negative."""
DOP = SignalBounds(1.0e-3, 1.0e4, "")
"""A dilution of precision: positive (0.5 with very many satellites); beyond 1e4 the geometry
says nothing."""
MAX_COUNT = 10_000_000
"""Largest count of observations or rows a heading window can hold (hours of 100 Hz data)."""
