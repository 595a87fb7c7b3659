"""Synthetic Doppler rows for a land vehicle, exact by construction (for tests and benchmarks).

The truth follows the conventions of :mod:`vo_doppler.model.doppler`: ṙ = G·(v_s − v) + ρ − ρ_s,
yaw counter-clockwise from east, velocity horizontal.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vo_doppler.geo import wrap_angle
from vo_doppler.model.doppler import DopplerRows


@dataclass
class DopplerScenario:
    """Rows plus the per-epoch truth and sensor inputs of a synthetic drive."""

    rows: DopplerRows
    t_epoch: np.ndarray
    speed: np.ndarray
    yaw: np.ndarray
    yaw_angle: np.ndarray
    clock_drift: np.ndarray


def line_of_sight(azimuth_rad: np.ndarray, elevation_rad: np.ndarray) -> np.ndarray:
    """ENU unit vectors to satellites at azimuth (clockwise from north) and elevation."""
    az, el = np.asarray(azimuth_rad, dtype=float), np.asarray(elevation_rad, dtype=float)
    return np.stack([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)], axis=-1)


def simulate_doppler(
    t_epoch: np.ndarray,
    yaw: Callable[[np.ndarray], np.ndarray],
    speed: Callable[[np.ndarray], np.ndarray],
    azimuth_deg: np.ndarray,
    elevation_deg: np.ndarray,
    sats_per_epoch: int | None = None,
    clock_drift0: float = 120.0,
    clock_drift_rate: float = 0.3,
    noise_mps: float = 0.0,
    seed: int = 0,
    rotate: bool = True,
) -> DopplerScenario:
    """Doppler rows for satellites at fixed azimuth/elevation; ``sats_per_epoch`` of them per
    epoch — cycling through the list when ``rotate`` (every satellite appears over a window),
    else always the first ones — or all of them."""
    rng = np.random.default_rng(seed)
    t_epoch = np.asarray(t_epoch, dtype=float)
    los_all = line_of_sight(np.radians(azimuth_deg), np.radians(elevation_deg))
    n_total = len(los_all)
    per_epoch = n_total if sats_per_epoch is None else sats_per_epoch
    sat_velocity_all = rng.normal(0.0, 2000.0, (n_total, 3))
    sat_drift_all = rng.normal(0.0, 0.5, n_total)
    psi, s = yaw(t_epoch), speed(t_epoch)
    velocity = s[:, None] * np.stack([np.cos(psi), np.sin(psi), np.zeros_like(psi)], axis=1)
    rho = clock_drift0 + clock_drift_rate * (t_epoch - t_epoch[0])
    epoch = np.repeat(np.arange(len(t_epoch)), per_epoch)
    sat = (epoch * per_epoch + np.tile(np.arange(per_epoch), len(t_epoch))) % n_total
    if per_epoch == n_total or not rotate:
        sat = np.tile(np.arange(per_epoch), len(t_epoch))
    los = los_all[sat]
    range_rate = (
        np.einsum("ni,ni->n", los, sat_velocity_all[sat] - velocity[epoch])
        + rho[epoch]
        - sat_drift_all[sat]
        + rng.normal(0.0, noise_mps, len(epoch)) * (noise_mps > 0)
    )
    weight = np.full(len(epoch), 1.0 / max(noise_mps, 0.05) ** 2)
    rows = DopplerRows(
        t_epoch[epoch],
        los,
        sat_velocity_all[sat],
        sat_drift_all[sat],
        range_rate,
        weight,
        np.array([f"G{i + 1:02d}" for i in sat]),
    )
    return DopplerScenario(rows, t_epoch, s, psi, psi - psi[0], rho)


def gyro_from_heading(
    t: np.ndarray,
    yaw: np.ndarray,
    valid: np.ndarray,
    bias: float,
    noise_rad_s: float,
    rate_hz: float = 10.0,
    seed: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """Gyro samples (times, counter-clockwise yaw rate) whose rate between consecutive valid
    headings is their difference over the interval (0 where a heading is missing, e.g. at
    standstill), sampled at ``rate_hz`` in the middle of sub-intervals, plus bias and noise."""
    rng = np.random.default_rng(seed)
    t = np.asarray(t, dtype=float)
    ok = np.asarray(valid, dtype=bool) & np.isfinite(yaw)
    steps = wrap_angle(np.diff(np.where(ok, yaw, 0.0)))
    interval_rate = np.where(ok[:-1] & ok[1:], steps / np.diff(t), 0.0)
    t_gyro = np.arange(t[0] + 0.5 / rate_hz, t[-1], 1.0 / rate_hz)
    interval = np.clip(np.searchsorted(t, t_gyro, side="right") - 1, 0, len(t) - 2)
    rate = interval_rate[interval] + bias + rng.normal(0.0, noise_rad_s, len(t_gyro))
    return t_gyro, rate
