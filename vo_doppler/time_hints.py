"""Messages for sensor times that do not overlap the GNSS epochs: the two spans in plain
numbers and a guess at the cause with the option that fixes it."""

from __future__ import annotations

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.model.gpstime import GPS_MINUS_UTC_LATEST_S, UNIX_TIME_AT_GPS_EPOCH_S

UNIX_OFFSET_S = GPS_MINUS_UTC_LATEST_S - UNIX_TIME_AT_GPS_EPOCH_S
"""GPS time − Unix time today, the offset that puts a Unix-time log on GPS time."""


def span(t) -> str:
    """``first..last s`` of a time array (plain numbers, no numpy brackets)."""
    if len(t) == 0:
        return "no samples"
    return f"{float(t[0]):.3f}..{float(t[-1]):.3f} s"


def offset_hint(sensor_t0: float, gnss_t0: float, option: str) -> str:
    """What ``option`` (e.g. ``--time-offset-can``) should probably be, from the first times."""
    gap = gnss_t0 - sensor_t0
    if abs(gap - UNIX_OFFSET_S) < 3600.0:
        return (
            f"the sensor times look like Unix time: pass {option} {UNIX_OFFSET_S:.0f} "
            f"(GPS - Unix = {-UNIX_TIME_AT_GPS_EPOCH_S:.0f} s "
            f"+ {GPS_MINUS_UTC_LATEST_S:.0f} leap seconds)"
        )
    if abs(sensor_t0) < 1.0e5:
        return (
            "the sensor times look like seconds since the start of the log: pass "
            f"{option} with the GPS time of that start (about {gap:.0f} if both start together)"
        )
    return (
        f"pass {option} with GPS time minus sensor time (about {gap:.0f} s if they start together)"
    )


def frame_index_hint(t: np.ndarray) -> str:
    """For a trajectory whose times are 0, 1, 2, …: they are frame numbers, not times."""
    if len(t) > 1 and np.array_equal(t, np.arange(len(t))):
        return (
            "; its times are frame numbers 0, 1, 2, ... (a KITTI poses file has no times): pass "
            "--times with the images' times.txt (then --time-offset to GPS time)"
        )
    return ""


def overlaps(t: np.ndarray, epochs: np.ndarray) -> bool:
    """Whether the span of ``t`` meets the span of ``epochs``."""
    return bool(len(t) and len(epochs) and t[-1] >= epochs[0] and t[0] <= epochs[-1])


def overlap_error(what: str, t: np.ndarray, epochs: np.ndarray, option: str, path=None):
    """The project's error for ``what``'s times (``t``, GPS s after the offsets) missing the
    GNSS epochs, with the likely offset (see :func:`offset_hint`)."""
    hint = offset_hint(float(t[0]), float(epochs[0]), option) if len(t) and len(epochs) else ""
    return InputError(
        f"the {what} times ({span(t)}) do not overlap the GNSS epochs ({span(epochs)}, GPS "
        f"time)" + (f"; {hint}" if hint else ""),
        path,
    )
