"""Cleaning of one sampled time series: bad samples dropped, time order restored, gaps counted.

Used for the gyro rates and the GPS fixes alike; every dropped sample is counted in the report.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from vo_doppler.errors import InputError

log = logging.getLogger(__name__)

GAP_FACTOR = 10.0


@dataclass(frozen=True)
class SeriesReport:
    """What was found in one rate series: samples, dropped samples, rate and gaps."""

    name: str
    n_samples: int
    n_non_finite: int
    n_duplicate_times: int
    n_unordered: int
    rate_hz: float
    n_gaps: int
    longest_gap_s: float


def clean_series(
    t: np.ndarray, values: np.ndarray, name: str
) -> tuple[np.ndarray, np.ndarray, SeriesReport]:
    """Drop non-finite samples, sort by time and keep the first of duplicated times.

    Gaps longer than ``GAP_FACTOR`` times the median interval are counted and logged.
    """
    t = np.asarray(t, dtype=float).reshape(-1)
    values = np.asarray(values, dtype=float)
    if len(values) != len(t):
        raise InputError(f"{name}: {len(t)} times but {len(values)} values")
    finite = np.isfinite(t) & np.all(np.isfinite(values), axis=tuple(range(1, values.ndim)))
    n_non_finite = int(np.sum(~finite))
    t, values = t[finite], values[finite]
    n_unordered = int(np.sum(np.diff(t) < 0))
    order = np.argsort(t, kind="stable")
    t, values = t[order], values[order]
    keep = np.concatenate([[True], np.diff(t) > 0]) if len(t) else np.zeros(0, bool)
    n_duplicates = int(np.sum(~keep))
    t, values = t[keep], values[keep]
    if len(t) < 2:
        raise InputError(f"{name}: fewer than 2 usable samples ({len(t)})")
    dt = np.diff(t)
    median_dt = float(np.median(dt))
    gaps = dt > GAP_FACTOR * median_dt
    report = SeriesReport(
        name=name,
        n_samples=len(t),
        n_non_finite=n_non_finite,
        n_duplicate_times=n_duplicates,
        n_unordered=n_unordered,
        rate_hz=1.0 / median_dt,
        n_gaps=int(np.sum(gaps)),
        longest_gap_s=float(dt.max()),
    )
    if n_non_finite or n_duplicates or n_unordered:
        log.warning(
            "%s: dropped %d non-finite and %d duplicate-time samples; %d out of time order",
            name,
            n_non_finite,
            n_duplicates,
            n_unordered,
        )
    if report.n_gaps:
        log.warning(
            "%s: %d gaps longer than %.3g s (longest %.3g s) are bridged linearly",
            name,
            report.n_gaps,
            GAP_FACTOR * median_dt,
            report.longest_gap_s,
        )
    return t, values, report
