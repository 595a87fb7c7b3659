"""Where a recording's yaw rate and wheel speed came from, in the words the library's checks
(:mod:`vo_doppler.checks`) need to name what to fix: a CAN signal and its DBC, a CSV file, a
command-line option."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class VehicleSignalSource:
    """Names for the messages of the vehicle-signal checks; the defaults fit signals built in
    code (no file behind them)."""

    sensor: str = "vehicle signals"
    """What the clock messages call the sensor, e.g. ``CAN``."""
    offset_s: float = 0.0
    """The clock offset (s) that put the signals on GPS time."""
    offset_name: str = "the vehicle signals' clock offset"
    """The setting that holds ``offset_s``, e.g. ``the manifest's time_offset_s``."""
    yaw_rate_offset_name: str | None = None
    """The setting that puts the yaw rate on GPS time where it is not ``offset_name`` (a yaw-rate
    CSV with its own offset option)."""
    yaw_rate: str = "the yaw rate"
    """The yaw rate's origin, e.g. a CSV file or a CAN signal with its DBC."""
    yaw_rate_unit: str = "rad/s"
    """The unit the origin declares (a DBC's; a CSV's column name says rad/s)."""
    yaw_rate_unit_fix: str = "convert it to rad/s"
    """What to do when the values look like deg/s."""
    yaw_rate_sign_fix: str = "negate it: it must be counter-clockwise positive (a left turn > 0)"
    """What to do when the yaw rate turns against the GNSS course."""
