"""GPS track reconstruction: thin the fixes, drop jitter clusters, interpolate back.

[KZ] Eq. (10): keep every M-th fix, and of those drop each fix lying closer than ``cluster_m`` to
the previously kept one (a standing receiver's scatter collapses onto one point).
[KZ] Eq. (11): linear interpolation of latitude and longitude between the kept fixes, evaluated at
every original fix time, so the track keeps one point per original time.
[KZ] Eq. (12)–(14): step length by the equirectangular approximation on a sphere of radius
R = 6371 km: x = Δλ·cos(φ_m), y = Δφ, d = R·√(x² + y²). The haversine formula is given for
comparison. Angles are radians.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.geo import EARTH_MEAN_RADIUS_M


def equirectangular_distance(lat1, lon1, lat2, lon2, radius_m: float = EARTH_MEAN_RADIUS_M):
    """[KZ] Eq. (12)–(14): distance (m) between points given in radians."""
    x = (np.asarray(lon2) - np.asarray(lon1)) * np.cos((np.asarray(lat1) + np.asarray(lat2)) / 2)
    y = np.asarray(lat2) - np.asarray(lat1)
    return radius_m * np.hypot(x, y)


def haversine_distance(lat1, lon1, lat2, lon2, radius_m: float = EARTH_MEAN_RADIUS_M):
    """Great-circle distance (m) by the haversine formula, points in radians."""
    dlat = np.asarray(lat2) - np.asarray(lat1)
    dlon = np.asarray(lon2) - np.asarray(lon1)
    a = np.sin(dlat / 2) ** 2 + np.cos(lat1) * np.cos(lat2) * np.sin(dlon / 2) ** 2
    return 2.0 * radius_m * np.arcsin(np.sqrt(np.clip(a, 0.0, 1.0)))


def step_lengths(lat: np.ndarray, lon: np.ndarray, method: str = "equirectangular") -> np.ndarray:
    """Distances (m) between consecutive points, (N − 1,), by [KZ] Eq. (12)–(14) or haversine."""
    lat = np.asarray(lat, dtype=float)
    lon = np.asarray(lon, dtype=float)
    formulas = {"equirectangular": equirectangular_distance, "haversine": haversine_distance}
    if method not in formulas:
        raise ValueError(f"unknown distance method {method!r} (expected {sorted(formulas)})")
    return formulas[method](lat[:-1], lon[:-1], lat[1:], lon[1:])


def select_fixes(
    lat: np.ndarray,
    lon: np.ndarray,
    downsample: int = 1,
    cluster_m: float = 3.0,
    always_keep: np.ndarray | None = None,
) -> np.ndarray:
    """[KZ] Eq. (10): indices of the kept fixes — every ``downsample``-th fix, minus those closer
    than ``cluster_m`` metres to the previously kept fix. The first and the last fix are always
    kept, so that interpolation never has to hold a stale position at either end.

    ``always_keep`` (our addition) names fixes kept whatever their distance, e.g. the last fix
    of a standstill: without it the first metres of a drive are lost while the vehicle drives
    up to a stale standstill fix.
    """
    if downsample < 1:
        raise ValueError(f"downsample must be ≥ 1, got {downsample}")
    if cluster_m < 0:
        raise ValueError(f"cluster distance must be ≥ 0, got {cluster_m}")
    lat = np.asarray(lat, dtype=float)
    lon = np.asarray(lon, dtype=float)
    if len(lat) == 0:
        return np.zeros(0, dtype=int)
    forced = set() if always_keep is None else {int(i) for i in always_keep}
    forced.add(len(lat) - 1)
    candidates = sorted({*range(downsample, len(lat), downsample), *forced} - {0})
    kept = [0]
    for i in candidates:
        last = kept[-1]
        if (
            i in forced
            or equirectangular_distance(lat[last], lon[last], lat[i], lon[i]) >= cluster_m
        ):
            kept.append(i)
    return np.asarray(kept, dtype=int)


@dataclass(frozen=True)
class ReconstructedTrack:
    """One point per original fix time, from the kept fixes by [KZ] Eq. (11)."""

    t: np.ndarray
    lat: np.ndarray
    lon: np.ndarray
    kept: np.ndarray

    def step_lengths(self, method: str = "equirectangular") -> np.ndarray:
        return step_lengths(self.lat, self.lon, method)


def reconstruct_track(
    t: np.ndarray,
    lat: np.ndarray,
    lon: np.ndarray,
    downsample: int = 1,
    cluster_m: float = 3.0,
    always_keep: np.ndarray | None = None,
) -> ReconstructedTrack:
    """[KZ] Eq. (10)–(11): select fixes, then interpolate latitude and longitude linearly between
    the
    kept fixes at every original time.

    ``t`` must be strictly increasing (see ``vo_doppler.lowcost.series.clean_series``).
    """
    t = np.asarray(t, dtype=float)
    lat = np.asarray(lat, dtype=float)
    lon = np.asarray(lon, dtype=float)
    if not (len(t) == len(lat) == len(lon)):
        raise InputError(f"fix arrays disagree: {len(t)} times, {len(lat)} lat, {len(lon)} lon")
    if len(t) == 0:
        raise InputError("no GPS fixes")
    if np.any(np.diff(t) <= 0):
        raise InputError("GPS fix times must be strictly increasing")
    kept = select_fixes(lat, lon, downsample, cluster_m, always_keep)
    lon_unwrapped = np.unwrap(lon)
    lat_out = np.interp(t, t[kept], lat[kept])
    lon_out = (np.interp(t, t[kept], lon_unwrapped[kept]) + np.pi) % (2 * np.pi) - np.pi
    return ReconstructedTrack(t, lat_out, lon_out, kept)
