"""Static bias of a yaw-rate sensor and its removal, with τ proposed by the Allan deviation.

[KZ] Eq. (5): ε0 = (1/N)·Σ ω_i over the N samples of τ seconds of standstill.
[KZ] Eq. (6): ω' = ω − ε0.
τ is proposed at the minimum of the overlapping Allan deviation of the standstill rates: shorter
averages are dominated by white noise, longer ones by the wandering bias. The rule of
:func:`choose_tau`: τ never exceeds the window, and a window of straight driving (a moving record)
averages over its whole length — its Allan minimum measures the driving (road, steering
corrections), not the sensor, and a short τ there turns that motion into bias.
"""

from __future__ import annotations

from dataclasses import dataclass

import allantools
import numpy as np

from vo_doppler.errors import InputError


@dataclass(frozen=True)
class StaticBias:
    """ε0 (rad/s) averaged over ``n`` samples in [t0, t1]."""

    eps0: float
    t0: float
    t1: float
    n: int


def static_bias(t: np.ndarray, rate: np.ndarray, t0: float, t1: float) -> StaticBias:
    """[KZ] Eq. (5): the mean rate over the samples with t0 ≤ t ≤ t1."""
    t = np.asarray(t, dtype=float)
    inside = (t >= t0) & (t <= t1)
    n = int(np.sum(inside))
    if n == 0:
        raise InputError(f"no rate samples in the bias interval {t0:.3f}–{t1:.3f} s")
    return StaticBias(float(np.mean(np.asarray(rate, dtype=float)[inside])), t0, t1, n)


def remove_bias(rate: np.ndarray, eps0: float) -> np.ndarray:
    """[KZ] Eq. (6): ω − ε0."""
    return np.asarray(rate, dtype=float) - eps0


@dataclass(frozen=True)
class AllanDeviation:
    """Overlapping Allan deviation (rad/s) at averaging times ``taus`` (s)."""

    taus: np.ndarray
    adev: np.ndarray

    @property
    def tau_at_minimum(self) -> float:
        return float(self.taus[int(np.argmin(self.adev))])


def allan_deviation(rate: np.ndarray, sample_rate_hz: float, n_taus: int = 60) -> AllanDeviation:
    """Overlapping Allan deviation of rate samples at log-spaced τ up to a third of the record."""
    rate = np.asarray(rate, dtype=float)
    duration = len(rate) / sample_rate_hz
    if len(rate) < 9:
        raise InputError(f"the Allan deviation needs at least 9 samples, got {len(rate)}")
    taus = np.logspace(np.log10(1.0 / sample_rate_hz), np.log10(duration / 3.0), n_taus)
    taus_out, adev, _, _ = allantools.oadev(rate, rate=sample_rate_hz, data_type="freq", taus=taus)
    good = np.isfinite(adev) & (adev > 0)
    return AllanDeviation(np.asarray(taus_out)[good], np.asarray(adev)[good])


def detect_standstill(
    t: np.ndarray, speed: np.ndarray, max_speed: float = 0.2, min_duration: float = 5.0
) -> list[tuple[float, float]]:
    """Intervals where the speed (wheel or GPS, m/s) stays at or below ``max_speed`` for at
    least ``min_duration`` seconds, in time order."""
    t = np.asarray(t, dtype=float)
    still = np.asarray(speed, dtype=float) <= max_speed
    edges = np.diff(np.concatenate([[0], still.astype(int), [0]]))
    starts = np.flatnonzero(edges == 1)
    ends = np.flatnonzero(edges == -1) - 1
    return [
        (float(t[a]), float(t[b]))
        for a, b in zip(starts, ends, strict=True)
        if t[b] - t[a] >= min_duration
    ]


@dataclass(frozen=True)
class TauChoice:
    """τ (s) and the sentence that says why."""

    tau: float
    reason: str


def choose_tau(
    requested: float | None, allan: AllanDeviation, window_s: float, window_is_standstill: bool
) -> TauChoice:
    """τ for Eq. (5): the requested value or, for ``auto`` (None), the Allan minimum over a
    standstill and the whole window over a straight stretch; never longer than the window."""
    window = "standstill" if window_is_standstill else "straight stretch"
    if requested is None and not window_is_standstill:
        return TauChoice(
            window_s,
            f"τ = the whole straight stretch ({window_s:.3g} s): the Allan minimum of a moving "
            "record measures the driving, not the sensor",
        )
    if requested is None:
        tau, source = allan.tau_at_minimum, "the Allan deviation minimum"
    else:
        tau, source = float(requested), "as given"
    if not tau > 0:
        raise InputError(f"τ must be positive, got {tau:g} s")
    if tau > window_s:
        return TauChoice(
            window_s,
            f"τ = {tau:.3g} s ({source}) is longer than the {window} ({window_s:.3g} s); "
            f"using the whole {window}",
        )
    return TauChoice(tau, f"τ = {tau:.3g} s ({source}) over the {window}")
