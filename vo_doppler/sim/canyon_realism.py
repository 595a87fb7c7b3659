"""A street canyon as a car's GNSS receiver sees it: diffraction, diffuse scattering and a noisy
receiver clock (``simulate --canyon-realism real``).

The geometric canyon of :mod:`vo_doppler.sim.gnss_observations` receives a satellite directly or
by one specular facade reflection. Real canyon Doppler (a u-blox M8T at 1 Hz in Hong Kong,
residuals against ground truth with the per-epoch clock removed) is worse in a specific way:
the weaker the signal the larger the error, the error grows with speed, and several satellites
are biased at once. This module models the physics behind it, per (epoch, satellite) row:

* **Coherent path.** A satellite in line of sight arrives directly at the C/N0 of its
  elevation, C_los = C_h + (C_z − C_h)·sin(el). A blocked one arrives diffracted over the roof
  edge of the first building its ray enters (single knife edge, ITU-R P.526 eq. 31):
  J(ν) = 6.9 + 20·log10(√((ν − 0.1)² + 1) + ν − 0.1) dB for ν > −0.78, with
  ν = δ·√(2·d/λ), δ the angle of the ray below the edge and d the distance to the edge. The
  diffracted ray leaves the edge point in the satellite's vertical plane, δ above the line of
  sight, so its extra range rate is v·(u_d − u_e) = (v·h)·(cos el − cos(el + δ)) (h the
  horizontal unit vector towards the satellite) and its extra path d·(1 − cos δ). A specular
  facade reflection (``nlos`` on) replaces it when stronger.
* **Diffuse scattering.** Facades, signboards and vehicles scatter every satellite's signal
  towards the antenna at C_los − L_s (L_s drawn per scatterer). The dominant scatterer is a point
  P on the facades around the antenna (a ray at a random azimuth and elevation, its first
  building hit), fixed in the city for an episode that ends at a rate 1/τ + speed/L (the
  geometry changes as the car moves). Its extra range rate is exact for a fixed point,
  v·(u_d − u_P) with u_P = (P − r)/|P − r|: proportional to speed and bounded by 2·|v|, its
  extra path |P − r|·(1 − u_d·u_P).
* **Mixing.** The receiver tracks the power-weighted centroid of the Doppler spectrum of the
  coherent (power D) and scattered (power S) components: with w = S/(D + S) the range-rate error
  is (1 − w)·coherent + w·scattered, the C/N0 is 10·log10(D + S) (linear powers) plus
  ``fading_db`` of fading, and rows below the tracking threshold are lost. For a strong direct
  signal w ≈ 10^(−L_s/10) is small; w grows tenfold per 10 dB of lost C/N0, the speed
  coefficient k(C/N0) of σ² = σ_th² + (k·speed)² measured on the real drive.
* **Thermal noise.** σ_th² = σ_floor² + (σ_45·10^((45 − C/N0)/20))²: the tracking-loop noise
  (∝ (C/N0)^−½) on top of a floor the real receiver shows even at 45 dB-Hz.
* **Receiver clock.** A TCXO whose drift is a random walk of
  ``clock_drift_walk_mps_per_sqrt_s`` (m/s per √s: 0.17 m/s between 1-Hz epochs on the real
  drive).

:func:`real_canyon_config` gives the settings that reproduce the real drive's figures on the
simulator's default city (tests/sim/test_canyon_realism.py checks them).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import StrEnum
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from vo_doppler.sim.gnss_observations import Boxes, GnssSimConfig


class RealismLevel(StrEnum):
    """``simulate --canyon-realism``."""

    GEOMETRIC = "geometric"
    """Direct rays and specular facade reflections."""
    REAL = "real"
    """The canyon measured on real receivers (this module: :func:`real_canyon_config`)."""


@dataclass(frozen=True)
class CanyonRealism:
    """Diffraction, diffuse scattering and thermal floor of a real street canyon (module
    docstring); powers in dB-Hz and dB, times in s, distances in m, speeds in m/s."""

    scatter_loss_db: float = 20.0
    """Mean loss of the diffusely scattered power below the line-of-sight C/N0."""
    scatter_loss_spread_db: float = 3.0
    """Standard deviation of the loss between scatterers."""
    scatter_time_s: float = 6.0
    """Mean lifetime τ of a scatterer with the car at rest."""
    scatter_distance_m: float = 20.0
    """Distance L the car drives, on average, before the dominant scatterer changes."""
    scatter_elevation_deg: tuple[float, float] = (0.0, 35.0)
    """Range of the scatterers' elevations seen from the antenna (facades above the car)."""
    scatter_range_m: float = 60.0
    """Farthest scatterer: a ray hitting no building nearer scatters at this distance."""
    dominant_share: float = 0.5
    """Share a of the scattered power the dominant scatterer carries; the rest arrives from all
    around (no mean direction), so the scattered Doppler centroid is v·(u_d − a·u_P)."""
    shadow_fraction: float = 0.5
    """Share of the scatter episodes in which a thin obstacle (signboard, tree, footbridge)
    also shadows the coherent path."""
    shadow_db: tuple[float, float] = (3.0, 15.0)
    """Range of that shadow's attenuation (uniform)."""
    fading_db: float = 1.5
    """Fading of the received C/N0 around the mean of the two components."""
    doppler_floor_mps: float = 0.2
    """Range-rate noise floor σ_floor, independent of C/N0."""


def real_canyon_config(base: GnssSimConfig) -> GnssSimConfig:
    """``base`` with the real canyon's receiver: the M8T's C/N0 on a moving car (a roof patch
    antenna, 44 dB-Hz at the zenith, 28 at the horizon), rows reported down to 22 dB-Hz,
    σ_45 0.02 m/s over a 0.2 m/s floor, the clock drift's random walk of 0.17 m/s per √s, no
    specular facade reflections (facade relief of balconies, window frames and signboards is
    far beyond the Rayleigh criterion λ/(8·cos θ) ≈ 2.4 cm at L1, so the reflected energy is
    the diffuse scattering of :class:`CanyonRealism`)."""
    return replace(
        base,
        canyon=CanyonRealism(),
        nlos=False,
        cn0_zenith_dbhz=44.0,
        cn0_horizon_dbhz=28.0,
        tracking_threshold_dbhz=22.0,
        sigma_range_rate_mps=0.02,
        clock_drift_walk_mps_per_sqrt_s=0.17,
    )


def knife_edge_loss_db(nu: np.ndarray) -> np.ndarray:
    """Diffraction loss J(ν) of a single knife edge (ITU-R P.526-15 eq. 31), 0 for ν ≤ −0.78."""
    nu = np.asarray(nu, dtype=float)
    loss = 6.9 + 20.0 * np.log10(np.sqrt((nu - 0.1) ** 2 + 1.0) + nu - 0.1)
    return np.where(nu > -0.78, loss, 0.0)


@dataclass(frozen=True)
class Scatterers:
    """The dominant scatterer per (epoch, satellite): ``episode`` (K, S) indexes ``point``
    (E, 3, ENU m), ``loss_db`` (E,) and the coherent path's shadow ``shadow_db`` (E,)."""

    episode: np.ndarray
    point: np.ndarray
    loss_db: np.ndarray
    shadow_db: np.ndarray


def scatterers(
    position: np.ndarray,
    n_sats: int,
    dt: float,
    boxes: Boxes,
    realism: CanyonRealism,
    rng: np.random.Generator,
) -> Scatterers:
    """Scatter episodes per satellite along the antenna track ``position`` (K, 3): a new
    episode starts with probability 1 − exp(−(dt/τ + Δs/L)) per epoch (Δs the distance
    driven), and its point is the first facade hit of a ray from the antenna at the episode's
    first epoch (at ``scatter_range_m`` when nothing is nearer)."""
    from vo_doppler.sim.gnss_observations import ray_hits

    n_epochs = len(position)
    travel = np.concatenate([[0.0], np.linalg.norm(np.diff(position, axis=0), axis=1)])
    rate = dt / realism.scatter_time_s + travel / realism.scatter_distance_m
    new = rng.uniform(size=(n_sats, n_epochs)) < -np.expm1(-rate)[None, :]
    new[:, 0] = True
    flat = new.ravel()
    episode = (np.cumsum(flat) - 1).reshape(n_sats, n_epochs).T
    start = np.flatnonzero(flat) % n_epochs
    n = start.size
    azimuth = rng.uniform(0.0, 2.0 * np.pi, n)
    low, high = np.radians(realism.scatter_elevation_deg)
    elevation = rng.uniform(low, high, n)
    loss = realism.scatter_loss_db + rng.normal(0.0, realism.scatter_loss_spread_db, n)
    shadowed = rng.uniform(size=n) < realism.shadow_fraction
    shadow = np.where(shadowed, rng.uniform(*realism.shadow_db, n), 0.0)
    direction = np.column_stack(
        [
            np.cos(elevation) * np.sin(azimuth),
            np.cos(elevation) * np.cos(azimuth),
            np.sin(elevation),
        ]
    )
    origin = position[start]
    hits = ray_hits(origin, direction, boxes)
    reach = np.minimum(np.where(hits.hit, hits.distance, np.inf), realism.scatter_range_m)
    return Scatterers(episode, origin + reach[:, None] * direction, loss, shadow)


@dataclass(frozen=True)
class CanyonRows:
    """Per above-mask row: received C/N0 (dB-Hz, before measurement noise), ``received``, the
    extra path (m) and range rate (m/s) of what the receiver tracks, and the scattered power's
    share ``weight`` w."""

    cn0_dbhz: np.ndarray
    received: np.ndarray
    excess_m: np.ndarray
    excess_rate_mps: np.ndarray
    weight: np.ndarray


def canyon_rows(
    config: GnssSimConfig,
    los_enu: np.ndarray,
    elevation: np.ndarray,
    origins: np.ndarray,
    velocity: np.ndarray,
    blocked_distance: np.ndarray,
    blocked_box: np.ndarray,
    scatter: Scatterers,
    episode: np.ndarray,
    wavelength: np.ndarray,
    boxes: Boxes,
    rng: np.random.Generator,
) -> CanyonRows:
    """Mix the coherent (direct, diffracted or specular) and scattered components of each
    above-mask row (model in the module docstring). ``blocked_distance`` is the distance along
    the line of sight ``los_enu`` to the first building (inf when clear), ``blocked_box`` its
    index; ``episode`` the row's scatter episode in ``scatter``; ``origins``/``velocity`` the
    antenna's position and velocity per row (ENU)."""
    realism = config.canyon
    assert realism is not None
    n = len(elevation)
    c_los = config.cn0_horizon_dbhz + (config.cn0_zenith_dbhz - config.cn0_horizon_dbhz) * np.sin(
        elevation
    )
    blocked = np.isfinite(blocked_distance)
    coherent_db = c_los.copy()
    coherent_rate = np.zeros(n)
    coherent_excess = np.zeros(n)
    b = np.flatnonzero(blocked)
    if b.size:
        horizontal = blocked_distance[b] * np.cos(elevation[b])
        rise = boxes.hi[blocked_box[b], 2] - origins[b, 2]
        delta = np.maximum(np.arctan2(rise, horizontal) - elevation[b], 0.0)
        edge = np.hypot(horizontal, rise)
        nu = delta * np.sqrt(2.0 * edge / wavelength[b])
        coherent_db[b] = c_los[b] - knife_edge_loss_db(nu)
        h = los_enu[b, :2] / np.maximum(np.linalg.norm(los_enu[b, :2], axis=1), 1e-12)[:, None]
        v_h = np.einsum("ij,ij->i", velocity[b, :2], h)
        coherent_rate[b] = v_h * (np.cos(elevation[b]) - np.cos(elevation[b] + delta))
        coherent_excess[b] = edge * (1.0 - np.cos(delta))
    coherent_db -= scatter.shadow_db[episode]
    to_point = scatter.point[episode] - origins
    reach = np.linalg.norm(to_point, axis=1)
    u_point = to_point / np.maximum(reach, 1e-9)[:, None]
    share = realism.dominant_share
    scatter_rate = np.einsum("ij,ij->i", velocity, los_enu - share * u_point)
    scatter_excess = reach * (1.0 - np.einsum("ij,ij->i", los_enu, u_point))
    scatter_db = c_los - scatter.loss_db[episode]
    coherent_power = 10.0 ** (coherent_db / 10.0)
    scatter_power = 10.0 ** (scatter_db / 10.0)
    weight = scatter_power / (coherent_power + scatter_power)
    cn0 = 10.0 * np.log10(coherent_power + scatter_power) + rng.normal(0.0, realism.fading_db, n)
    return CanyonRows(
        cn0_dbhz=cn0,
        received=cn0 >= config.tracking_threshold_dbhz,
        excess_m=(1.0 - weight) * coherent_excess + weight * scatter_excess,
        excess_rate_mps=(1.0 - weight) * coherent_rate + weight * scatter_rate,
        weight=weight,
    )


def thermal_sigma_mps(config: GnssSimConfig, cn0_dbhz: np.ndarray) -> np.ndarray:
    """Range-rate noise σ_th at ``cn0_dbhz``: σ_45·10^((45 − C/N0)/20) over the canyon's floor
    (only the first term without :class:`CanyonRealism`)."""
    from vo_doppler.sim.gnss_observations import CN0_NOISE_REFERENCE_DBHZ

    loop = config.sigma_range_rate_mps * 10.0 ** ((CN0_NOISE_REFERENCE_DBHZ - cn0_dbhz) / 20.0)
    floor = config.canyon.doppler_floor_mps if config.canyon is not None else 0.0
    return np.hypot(loop, floor)
