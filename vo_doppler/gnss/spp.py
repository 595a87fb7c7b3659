"""Pseudorange single-point positioning: position and one receiver clock per system, per epoch.

Model (IS-GPS-200 sec. 20.3.3.3.3): P = ρ + c·δt_r,sys − c·(δt_sv − T_GD) + T + ε with the
satellite state at transmission (``transmit_states``), Earth rotation during travel, the
Saastamoinen troposphere and the broadcast Klobuchar ionosphere (``atmosphere``); the positions
serve the line-of-sight vectors and the ENU origin. Gauss–Newton iterations, elevation
mask once the position is known, then chi-square fault exclusion (``lsq``) and a final pass
without the excluded rows.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT, ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.gnss.atmosphere import L1_HZ, klobuchar_delay, troposphere_delay
from vo_doppler.gnss.ephemeris import rotate_earth
from vo_doppler.gnss.lsq import lsq_with_exclusion, weighted_lsq
from vo_doppler.gnss.satellite_source import StateSource, satellite_source
from vo_doppler.gnss.signals import wavelengths
from vo_doppler.model.gnss_solutions import SppSolution
from vo_doppler.model.observations import Observations

log = logging.getLogger(__name__)

PSEUDORANGE_PRIORITY = {
    "G": ("C1C", "C1W", "C1X", "C1", "P1", "C2W", "C2L", "C5Q", "P2"),
    "R": ("C1C", "C1P", "C1", "P1", "C2C", "C2P", "P2"),
    "E": ("C1C", "C1X", "C1B", "C1", "C5Q", "C5X", "C7Q", "C7X"),
    "C": ("C2I", "C2X", "C1I", "C7I", "C1P", "C1X", "C6I"),
    "J": ("C1C", "C1X", "C1", "C2L", "C5Q"),
    "S": ("C1C", "C1"),
    "I": ("C5A", "C9A"),
}
SIGMA_PSEUDORANGE_M = 3.0
EARTH_SURFACE_M = 6.0e6


def pseudorange_codes(obs: Observations, systems: str) -> dict[str, str]:
    """The preferred pseudorange observable per system present in the file."""
    chosen = {}
    for system in systems:
        present = set(obs.codes_of(system))
        for code in PSEUDORANGE_PRIORITY.get(system, ()):
            if code in present:
                chosen[system] = code
                break
    return chosen


def no_system_message(obs: Observations, systems: str) -> str:
    """Why none of ``systems`` can be used: the systems whose pseudoranges the file holds."""
    in_file = "".join(sorted(set(np.unique(obs.system).tolist())))
    usable = "".join(pseudorange_codes(obs, in_file))
    message = f"the file has no pseudoranges of the systems {systems!r}"
    if usable:
        return message + f"; it has those of {usable} (e.g. --systems {usable})"
    return message + f"; it has none of any system (observations of {in_file or 'none'})"


def elevation_azimuth(
    receiver_ecef: np.ndarray, los: np.ndarray, lat_lon: tuple[float, float] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Elevation and azimuth (rad, azimuth clockwise from north) of unit vectors at receivers
    (``lat_lon`` of a single receiver may be passed to skip the geodetic conversion)."""
    if lat_lon is None:
        lat, lon, _ = ecef_to_geodetic(np.broadcast_to(receiver_ecef, los.shape))
    else:
        lat, lon = lat_lon
    lat, lon = np.atleast_1d(lat), np.atleast_1d(lon)
    east = np.stack([-np.sin(lon), np.cos(lon), np.zeros_like(lon)], axis=-1)
    north = np.stack([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)], axis=-1)
    up = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)
    e, n, u = (np.sum(los * axis, axis=-1) for axis in (east, north, up))
    return np.arcsin(np.clip(u, -1.0, 1.0)), np.mod(np.arctan2(e, n), 2.0 * np.pi)


def solve_spp(
    obs: Observations,
    source: StateSource,
    systems: str = "GREJC",
    elevation_mask_rad: float = np.deg2rad(10.0),
) -> SppSolution:
    """Single-point position per data epoch of ``obs`` (invalid epochs NaN, never guessed),
    satellite states from ``source`` (broadcast or precise, ``satellite_source``)."""
    codes = pseudorange_codes(obs, systems)
    if not codes:
        raise InputError(no_system_message(obs, systems), obs.header.path)
    source = satellite_source(source)
    rows = np.zeros(len(obs), dtype=bool)
    for system, code in codes.items():
        rows |= obs.mask(system, code)
    sel = obs.subset(rows & np.isfinite(obs.value) & (obs.value > 1e6))
    travel = sel.value / SPEED_OF_LIGHT
    first = source.states(sel.system, sel.prn, sel.time - travel)
    t_tx = sel.time - travel - np.nan_to_num(first.clock_bias_s)
    states = source.states(sel.system, sel.prn, t_tx)
    group_delay = source.group_delay_s(sel.system, states, codes)
    satellite_clock_m = SPEED_OF_LIGHT * (states.clock_bias_s - np.nan_to_num(group_delay))
    n_no_ephemeris = int((~states.valid).sum())
    channels = {**source.glonass_channels(), **obs.header.glonass_channels}
    frequency = np.full(len(sel), L1_HZ)
    for system, code in codes.items():
        hit = sel.system == system
        lam = wavelengths(sel.system[hit], sel.prn[hit], code, channels, obs.header.version)
        frequency[hit] = np.nan_to_num(SPEED_OF_LIGHT / lam, nan=L1_HZ)
    epoch = np.searchsorted(obs.epoch_time, sel.time)
    bounds = np.searchsorted(epoch, np.arange(obs.epoch_time.size + 1))
    start = obs.header.approx_position
    if start is None or np.linalg.norm(start) < EARTH_SURFACE_M:
        start = np.zeros(3)
    model = _Model(sorted(codes), elevation_mask_rad, source.klobuchar)
    n_epochs = obs.epoch_time.size
    position = np.full((n_epochs, 3), np.nan)
    clocks = {s: np.full(n_epochs, np.nan) for s in model.systems}
    n_sat = np.zeros(n_epochs, dtype=np.int64)
    rms = np.full(n_epochs, np.nan)
    pdop = np.full(n_epochs, np.nan)
    quality = np.full((n_epochs, 2), np.nan)
    valid = np.zeros(n_epochs, dtype=bool)
    verified = np.zeros(n_epochs, dtype=bool)
    for k in range(n_epochs):
        r = np.arange(bounds[k], bounds[k + 1])
        r = r[states.valid[r]]
        data = _EpochData(
            obs.epoch_time[k],
            states.position[r],
            sel.value[r] + satellite_clock_m[r],
            sel.system[r],
            sel.prn[r],
            frequency[r],
        )
        result = _solve_epoch(data, model, start)
        if result is None:
            continue
        x, clock, used, residuals, dop, fit = result
        valid[k] = verified[k] = fit.passed
        quality[k] = _horizontal_quality(x, fit.design, fit.covariance[:3, :3])
        position[k] = x
        for s, value in clock.items():
            clocks[s][k] = value
        n_sat[k] = used
        rms[k] = residuals
        pdop[k] = dop
        start = x
    return SppSolution(
        obs.epoch_time,
        position,
        clocks,
        n_sat,
        rms,
        pdop,
        valid,
        n_no_ephemeris,
        verified=verified,
        hdop=quality[:, 0],
        horizontal_sigma_m=quality[:, 1],
    )


@dataclass(frozen=True)
class _EpochData:
    """One epoch's pseudoranges, corrected for the satellite clock and group delay."""

    t: float
    sat_position: np.ndarray
    corrected_range: np.ndarray
    system: np.ndarray
    prn: np.ndarray
    frequency: np.ndarray


@dataclass(frozen=True)
class _Model:
    systems: list[str]
    mask: float
    klobuchar: np.ndarray | None


def _solve_epoch(data: _EpochData, model: _Model, start: np.ndarray):
    """Gauss–Newton with elevation mask and FDE; None when fewer than 3 + n_clock satellites."""
    keep = np.ones(data.corrected_range.size, dtype=bool)
    x = np.asarray(start, dtype=float).copy()
    clocks = np.zeros(len(model.systems))
    for _ in range(2):
        for _ in range(12):
            H, residual, sigma, keep_now, present = _linearise(data, model, x, clocks, keep)
            if keep_now.sum() < 3 + present.sum():
                return None
            H = H[keep_now][:, np.r_[True, True, True, present]]
            dx, _, _ = weighted_lsq(H, residual[keep_now], sigma[keep_now])
            x += dx[:3]
            clocks[present] += dx[3:]
            if np.linalg.norm(dx[:3]) < 1e-4:
                break
        groups = np.char.add(data.system[keep_now], data.prn[keep_now].astype(str))
        result = lsq_with_exclusion(
            H, residual[keep_now], sigma[keep_now], groups, 3 + int(present.sum())
        )
        if not result.valid:
            return None
        if result.used.all():
            break
        keep[np.flatnonzero(keep_now)[~result.used]] = False
    if np.linalg.norm(x) < EARTH_SURFACE_M:
        return None
    used = keep_now.sum()
    rms_value = float(np.sqrt(np.mean(result.residuals[result.used] ** 2)))
    pdop = float(np.sqrt(np.trace(np.linalg.inv(H.T @ H)[:3, :3])))
    clock = {s: clocks[i] for i, s in enumerate(model.systems) if present[i]}
    fit = _Fit(result.passed, result.dof, result.covariance, H[result.used])
    return x, clock, int(used - (~result.used).sum()), rms_value, pdop, fit


@dataclass(frozen=True)
class _Fit:
    """What the integrity figures need from an epoch's final least squares."""

    passed: bool
    dof: int
    covariance: np.ndarray
    design: np.ndarray


def _horizontal_quality(x: np.ndarray, design: np.ndarray, covariance: np.ndarray):
    """HDOP (unweighted geometry) and √(σ_e² + σ_n²) (weighted covariance) at position x."""
    lat, lon, _ = ecef_to_geodetic(x)
    rotation = ecef_to_enu_rotation(float(lat), float(lon))
    geometry = np.linalg.inv(design.T @ design)[:3, :3]
    horizontal = (rotation @ geometry @ rotation.T)[:2, :2]
    weighted = (rotation @ covariance @ rotation.T)[:2, :2]
    return np.sqrt(np.trace(horizontal)), np.sqrt(np.trace(weighted))


def _linearise(data: _EpochData, model: _Model, x, clocks, keep):
    travel = np.linalg.norm(data.sat_position - x, axis=1) / SPEED_OF_LIGHT
    vector = rotate_earth(data.sat_position, travel) - x
    rho = np.linalg.norm(vector, axis=1)
    los = vector / rho[:, None]
    keep_now = keep.copy()
    sigma = np.full(rho.size, SIGMA_PSEUDORANGE_M)
    atmosphere = np.zeros(rho.size)
    if np.linalg.norm(x) > EARTH_SURFACE_M:
        lat, lon, height = (float(v) for v in ecef_to_geodetic(x))
        elevation, azimuth = elevation_azimuth(x, los, (lat, lon))
        keep_now &= elevation >= model.mask
        sigma = SIGMA_PSEUDORANGE_M / np.sin(np.maximum(elevation, np.deg2rad(5.0)))
        atmosphere = troposphere_delay(lat, height, elevation)
        if model.klobuchar is not None:
            atmosphere = atmosphere + klobuchar_delay(
                model.klobuchar, lat, lon, elevation, azimuth, data.t, data.frequency
            )
    one_hot = np.stack([data.system == s for s in model.systems], axis=1).astype(float)
    present = one_hot[keep_now].any(axis=0)
    predicted = rho + one_hot @ clocks + atmosphere
    H = np.hstack([-los, one_hot])
    return H, data.corrected_range - predicted, sigma, keep_now, present


def receiver_positions(solution: SppSolution, fallback: np.ndarray | None) -> np.ndarray:
    """One position per epoch: the SPP fix, else the nearest valid fix in time, else
    ``fallback`` (e.g. the RINEX approximate position); NaN rows when none exists."""
    out = solution.position_ecef.copy()
    valid = solution.valid
    if valid.any():
        good = np.flatnonzero(valid)
        missing = ~valid
        nearest = good[nearest_time(solution.t[good], solution.t[missing])]
        out[missing] = solution.position_ecef[nearest]
    elif fallback is not None and np.linalg.norm(fallback) > EARTH_SURFACE_M:
        out[:] = fallback
    return out


def nearest_time(sorted_t: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Index into ascending times ``sorted_t`` (non-empty) of the nearest to each of ``t``: on a
    tie the earlier, among equal times the first, as ``argmin`` over all pairs would choose,
    in O((n + m) log n) time and O(m) memory instead of an (m × n) table."""
    last = sorted_t.size - 1
    after = np.searchsorted(sorted_t, t)
    before = np.searchsorted(sorted_t, sorted_t[np.maximum(after - 1, 0)])
    after = np.searchsorted(sorted_t, sorted_t[np.minimum(after, last)])
    use_before = np.abs(t - sorted_t[before]) <= np.abs(t - sorted_t[after])
    return np.where(use_before, before, after)
