"""Sampled signals: sample, hold, integrate, travelled distance — one edge rule for all; and
the one rule for comparing times whatever their origin (:func:`relative_times`,
:data:`TIME_TOLERANCE_S`).

**Edge rule.** A signal is known on ``[t[0], t[-1]]`` only. Every function returns NaN at
query times outside that interval unless the caller names another rule with ``outside``:

* ``"nan"`` (default): NaN outside the record;
* ``"hold"``: the value at the nearer end of the record (for an integral: the integrand is
  taken as zero beyond the record, so the integral stops changing);
* ``"extend"`` (integrals only): the integrand's end value is held beyond the record, so the
  integral keeps growing at the end rate.

Integrals use the trapezoidal rule from ``t[0]`` (so ∫ from t₁ to t₂ is the difference of
two samples of the integral). Times are seconds, sorted non-decreasing.
"""

from __future__ import annotations

from enum import StrEnum

import numpy as np


class Outside(StrEnum):
    """The edge rules (module docstring)."""

    NAN = "nan"
    HOLD = "hold"
    EXTEND = "extend"
    """Integrals only."""


TIME_TOLERANCE_S = 1e-6
"""Two times closer than this are taken as equal when spacings are compared: far above the
rounding of a GPS time near 10⁹ s (2⁻²³ s ≈ 1.2·10⁻⁷ s per value), far below any sampling
interval, so that a measurement exactly one spacing after the last kept one is kept whatever
the time origin (at 10⁹ s, ``t_j >= last + gap`` dropped 5 of 30 samples 0.1 s apart)."""
TIME_DECIMALS = 6
"""Times relative to a start are rounded to the microsecond (:func:`relative_times`)."""


def relative_times(t, origin: float) -> np.ndarray:
    """``t − origin`` rounded to the microsecond: the same numbers whatever the time origin.

    A time near 10⁹ s (GPS seconds) carries up to 1.2·10⁻⁷ s of rounding, so ``t − origin``
    differs from the same time counted from the start of a log by that much, and a comparison
    on the edge (a window of exactly 2 s over 10-Hz poses) could go either way; rounded to the
    microsecond (no clock stamps finer), both give the same numbers."""
    return np.round(np.asarray(t, dtype=float) - origin, TIME_DECIMALS)


def time_grid(begin: float, end: float, step_s: float) -> np.ndarray:
    """``begin, begin + step_s, …`` before ``end``: the times of ``np.arange(begin, end,
    step_s)``, each ``begin + k·step_s``. ``np.arange`` steps by ``(begin + step_s) − begin``,
    which near 10⁹ s carries the rounding of ``begin`` (2.4·10⁻⁷ s at 2·10⁹ s) into every step:
    a 20-Hz grid over 38 s ended 1.8·10⁻⁴ s off at GPS seconds shifted by 10⁹ s (issue 30)."""
    count = max(int(np.ceil((end - begin) / step_s)), 0)
    return begin + step_s * np.arange(count)


def _check(outside: Outside | str, allowed: tuple[Outside, ...]) -> None:
    if outside not in allowed:
        raise ValueError(f"outside={outside!r}: use one of {', '.join(allowed)}")


def sample(
    t: np.ndarray, value: np.ndarray, t_query, outside: Outside | str = Outside.NAN
) -> np.ndarray:
    """Linear interpolation of ``value`` at ``t_query`` (``outside``: "nan" or "hold")."""
    _check(outside, (Outside.NAN, Outside.HOLD))
    t = np.asarray(t, dtype=float)
    t_query = np.asarray(t_query, dtype=float)
    if t.size == 0:
        return np.full(t_query.shape, np.nan)
    out = np.interp(t_query, t, np.asarray(value, dtype=float))
    if outside == Outside.NAN:
        out[(t_query < t[0]) | (t_query > t[-1])] = np.nan
    return out


def hold(
    t: np.ndarray, value: np.ndarray, t_query, outside: Outside | str = Outside.NAN
) -> np.ndarray:
    """Sample-and-hold (zero order): the last sample at or before each query time.

    Before the first sample: NaN, or the first value with ``outside="hold"``; after the last
    sample the last value is held only with ``outside="hold"``.
    """
    _check(outside, (Outside.NAN, Outside.HOLD))
    t = np.asarray(t, dtype=float)
    value = np.asarray(value)
    t_query = np.asarray(t_query, dtype=float)
    if t.size == 0:
        return np.full(t_query.shape, np.nan)
    index = np.searchsorted(t, t_query, side="right") - 1
    out = value[np.clip(index, 0, t.size - 1)].astype(float)
    if outside == Outside.NAN:
        out[(t_query < t[0]) | (t_query > t[-1])] = np.nan
    return out


def cumulative_integral(t: np.ndarray, rate: np.ndarray, initial: float = 0.0) -> np.ndarray:
    """Trapezoidal integral of ``rate`` from ``t[0]`` at every sample time (starts at
    ``initial``)."""
    t = np.asarray(t, dtype=float)
    rate = np.asarray(rate, dtype=float)
    if t.shape != rate.shape:
        raise ValueError(f"{t.size} times but {rate.size} values")
    if t.size == 0:
        return np.zeros(0)
    steps = 0.5 * (rate[1:] + rate[:-1]) * np.diff(t)
    return initial + np.concatenate([[0.0], np.cumsum(steps)])


def integral_at(
    t: np.ndarray, rate: np.ndarray, t_query, outside: Outside | str = Outside.NAN
) -> np.ndarray:
    """The integral of ``rate`` since ``t[0]`` at ``t_query`` (module docstring for ``outside``)."""
    _check(outside, tuple(Outside))
    t = np.asarray(t, dtype=float)
    rate = np.asarray(rate, dtype=float)
    t_query = np.asarray(t_query, dtype=float)
    if t.size == 0:
        return np.full(t_query.shape, np.nan)
    total = cumulative_integral(t, rate)
    if outside != Outside.EXTEND:
        return sample(t, total, t_query, outside)
    out = np.interp(t_query, t, total)
    before, after = t_query < t[0], t_query > t[-1]
    out[before] = (t_query[before] - t[0]) * rate[0]
    out[after] = total[-1] + (t_query[after] - t[-1]) * rate[-1]
    return out


def travelled_distance(
    t: np.ndarray, speed: np.ndarray, t_query, outside: Outside | str = Outside.NAN
) -> np.ndarray:
    """Distance travelled since ``t[0]`` at each query time: the integral of the speed."""
    return integral_at(t, speed, t_query, outside)


def increments(
    t: np.ndarray, rate: np.ndarray, t_query, outside: Outside | str = Outside.NAN
) -> np.ndarray:
    """The integral of ``rate`` between consecutive query times, (N − 1,)."""
    return np.diff(integral_at(t, rate, t_query, outside))
