"""What a road vehicle's motion sensors can report, and how far its GNSS antenna can sit from
its reference point.

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
"""Specific force along the vehicle's forward axis."""

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
