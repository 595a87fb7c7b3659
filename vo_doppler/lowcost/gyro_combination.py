"""Two yaw-rate sensors combined into one, and the three ways of choosing the weight k.

[KZ] Eq. (7) : ω = ((2 − k)·ω1 + k·ω2) / 2 with k ∈ [0, 2]
(k = 0 is sensor 1 alone, k = 2 sensor 2 alone, k = 1 their average).
Rates are yaw rates in rad/s, counter-clockwise positive (docs/design.md); the weight does not
depend on the sign convention.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from vo_doppler.errors import InputError

log = logging.getLogger(__name__)

K_MIN = 0.0
K_MAX = 2.0


def combine_rates(omega1: np.ndarray, omega2: np.ndarray, k: float) -> np.ndarray:
    """[KZ] Eq. (7): the weighted combination ((2 − k)·ω1 + k·ω2) / 2 of two aligned rate series."""
    if not K_MIN <= k <= K_MAX:
        raise ValueError(f"k must lie in [0, 2], got {k}")
    omega1 = np.asarray(omega1, dtype=float)
    omega2 = np.asarray(omega2, dtype=float)
    if omega1.shape != omega2.shape:
        raise ValueError(f"rate series differ in shape: {omega1.shape} and {omega2.shape}")
    return ((2.0 - k) * omega1 + k * omega2) / 2.0


@dataclass(frozen=True)
class KChoice:
    """One choice of k: how it was found, its value, and whether it had to be clipped."""

    method: str
    k: float
    clipped: bool = False
    note: str = ""


@dataclass(frozen=True)
class KChoices:
    """The three choices of k over one standstill record."""

    sweep: KChoice
    closed_form: KChoice
    inverse_variance: KChoice

    def as_list(self) -> list[KChoice]:
        return [self.sweep, self.closed_form, self.inverse_variance]


def _standstill_integrals(t: np.ndarray, omega1: np.ndarray, omega2: np.ndarray):
    t = np.asarray(t, dtype=float)
    if len(t) < 2:
        raise InputError(f"a standstill record needs at least 2 samples, got {len(t)}")
    dt = np.diff(t)
    integral1 = float(np.sum(dt * (omega1[1:] + omega1[:-1]) / 2.0))
    integral2 = float(np.sum(dt * (omega2[1:] + omega2[:-1]) / 2.0))
    return integral1, integral2


def k_by_sweep(
    t: np.ndarray, omega1: np.ndarray, omega2: np.ndarray, step: float = 0.01
) -> tuple[KChoice, np.ndarray, np.ndarray]:
    """[KZ]'s sweep: k over 0..2 in ``step`` increments, keeping the k whose combined rate,
    integrated over the standstill record, ends with the smallest heading drift.

    Returns the choice and the swept grid with its final heading drift (rad) for each k.
    """
    integral1, integral2 = _standstill_integrals(t, omega1, omega2)
    grid = np.round(np.arange(K_MIN, K_MAX + step / 2.0, step), 10)
    # The final heading of the combined rate is [KZ] Eq. (7) applied to the two heading integrals.
    final_heading = ((2.0 - grid) * integral1 + grid * integral2) / 2.0
    best = int(np.argmin(np.abs(final_heading)))
    return KChoice("sweep", float(grid[best])), grid, final_heading


def k_closed_form(omega1: np.ndarray, omega2: np.ndarray) -> KChoice:
    """The k that zeroes the combined mean bias: (2 − k)·b1 + k·b2 = 0 → k = 2·b1 / (b1 − b2),
    with b1, b2 the mean standstill rates. Clipped to [0, 2] when the biases share a sign."""
    b1 = float(np.mean(omega1))
    b2 = float(np.mean(omega2))
    if b1 == b2:
        return KChoice("closed form", 1.0, True, "equal mean biases: any k gives the same bias")
    k = 2.0 * b1 / (b1 - b2)
    if K_MIN <= k <= K_MAX:
        return KChoice("closed form", k)
    clipped = float(np.clip(k, K_MIN, K_MAX))
    note = f"biases share a sign (b1={b1:.3g}, b2={b2:.3g} rad/s): k={k:.3g} clipped"
    log.warning("closed-form k: %s to %.2f", note, clipped)
    return KChoice("closed form", clipped, True, note)


def k_inverse_variance(omega1: np.ndarray, omega2: np.ndarray) -> KChoice:
    """Inverse-variance weighting: (2 − k)/2 = σ2²/(σ1² + σ2²) → k = 2·σ1²/(σ1² + σ2²)."""
    var1 = float(np.var(omega1))
    var2 = float(np.var(omega2))
    if var1 + var2 == 0.0:
        return KChoice("inverse variance", 1.0, True, "both sensors have zero variance")
    return KChoice("inverse variance", 2.0 * var1 / (var1 + var2))


def choose_k(t: np.ndarray, omega1: np.ndarray, omega2: np.ndarray) -> KChoices:
    """All three choices of k over one standstill record (aligned samples at times ``t``)."""
    sweep, _, _ = k_by_sweep(t, omega1, omega2)
    return KChoices(sweep, k_closed_form(omega1, omega2), k_inverse_variance(omega1, omega2))
