"""Units in the names of configuration fields (docs/design.md, "Choices and units"): a field
that holds a quantity with a unit ends in the unit's suffix (``window_s``, ``gate_rad``,
``max_yaw_drift_rad_s``), so that a reader, and the report that shows the configuration in
people units, need no list of which field holds what."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Unit:
    """A name suffix, the unit it means, and, for an angle, the suffix and factor of the
    people unit the report shows it in (``people_suffix`` None: shown as it is held)."""

    suffix: str
    symbol: str
    people_suffix: str | None = None
    people_symbol: str = ""
    people_scale: float = 1.0


DEGREES_PER_RADIAN = 180.0 / math.pi

UNITS: tuple[Unit, ...] = (
    Unit("_rad", "rad", "_deg", "deg", DEGREES_PER_RADIAN),
    Unit("_rad_s", "rad/s", "_deg_s", "deg/s", DEGREES_PER_RADIAN),
    Unit("_rad_per_sqrt_m", "rad/√m", "_deg_per_sqrt_m", "deg/√m", DEGREES_PER_RADIAN),
    Unit("_rad_per_sqrt_s", "rad/√s", "_deg_per_sqrt_s", "deg/√s", DEGREES_PER_RADIAN),
    Unit("_rad_per_s_sqrt_s", "rad/s/√s", "_deg_per_s_sqrt_s", "deg/s/√s", DEGREES_PER_RADIAN),
    Unit("_s", "s"),
    Unit("_m", "m"),
    Unit("_mps", "m/s"),
    Unit("_mps2", "m/s²"),
    Unit("_m_per_sqrt_s", "m/√s"),
    Unit("_mps_per_sqrt_s", "m/s/√s"),
    Unit("_hz", "Hz"),
    Unit("_px", "pixels"),
    Unit("_grey", "grey levels (0–255)"),
    Unit("_bytes", "bytes"),
    Unit("_db", "dB"),
    Unit("_dbhz", "dB-Hz"),
    Unit("_per_km", "per km"),
    Unit("_deg", "deg"),
    Unit("_dps", "deg/s"),
    Unit("_dps_per_sqrt_s", "deg/s/√s"),
    Unit("_kmh", "km/h"),
)
"""Every unit suffix, SI and radians first. The last four are people units, for the
simulator's settings of devices that work in them (an elevation mask in degrees, a CAN bus's
yaw rate in deg/s, its bias's random walk and wheel speed in km/h); the library's own settings
use the SI ones."""


def unit_of(name: str) -> Unit | None:
    """The unit a field's name ends in (the longest matching suffix: ``_rad_s`` before
    ``_s``), or None."""
    matches = [unit for unit in UNITS if name.endswith(unit.suffix)]
    return max(matches, key=lambda unit: len(unit.suffix)) if matches else None


def in_people_units(name: str, value: object) -> tuple[str, object, str]:
    """(name, value, unit symbol) with an angle turned into degrees and its name's suffix with
    it (``gate_rad`` 0.1 → ``gate_deg`` 5.73, "deg"); any other field as it is, with the
    symbol of its unit ("" without one). None and non-numbers stay as they are."""
    unit = unit_of(name)
    if unit is None:
        return name, value, ""
    if unit.people_suffix is None:
        return name, value, unit.symbol
    shown = name[: -len(unit.suffix)] + unit.people_suffix
    if isinstance(value, int | float) and not isinstance(value, bool):
        value = value * unit.people_scale
    return shown, value, unit.people_symbol
