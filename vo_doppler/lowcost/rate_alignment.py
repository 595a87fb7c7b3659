"""Two yaw-rate sensors brought onto one time base before they are combined by [KZ] Eq. (7).

The sensors may run at different rates and hold bad samples; the common time base is the
first sensor's sample times inside the interval both sensors cover, and the second sensor is
linearly interpolated onto it. Everything dropped is counted in the report.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.lowcost.series import SeriesReport, clean_series

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class AlignedRates:
    """Both sensors' yaw rates (rad/s) on one time base, with what was done to get there."""

    t: np.ndarray
    omega1: np.ndarray
    omega2: np.ndarray
    report1: SeriesReport
    report2: SeriesReport


def align_rates(
    t1: np.ndarray, omega1: np.ndarray, t2: np.ndarray, omega2: np.ndarray
) -> AlignedRates:
    """Clean both series and interpolate sensor 2 onto sensor 1's times where both exist."""
    t1, omega1, report1 = clean_series(t1, omega1, "gyro 1")
    t2, omega2, report2 = clean_series(t2, omega2, "gyro 2")
    start, end = max(t1[0], t2[0]), min(t1[-1], t2[-1])
    if end <= start:
        raise InputError(
            f"the gyros do not overlap in time: gyro 1 {t1[0]:.3f}–{t1[-1]:.3f} s, "
            f"gyro 2 {t2[0]:.3f}–{t2[-1]:.3f} s"
        )
    inside = (t1 >= start) & (t1 <= end)
    if np.sum(inside) < 2:
        raise InputError("fewer than 2 gyro-1 samples inside the interval both gyros cover")
    if not np.isclose(report1.rate_hz, report2.rate_hz, rtol=0.01):
        log.info(
            "gyro 2 (%.4g Hz) resampled onto gyro 1's times (%.4g Hz)",
            report2.rate_hz,
            report1.rate_hz,
        )
    t = t1[inside]
    return AlignedRates(t, omega1[inside], np.interp(t, t2, omega2), report1, report2)
