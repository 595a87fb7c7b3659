"""Geodetic, ECEF and local ENU transforms, and yaw/course conversions.

Conventions (docs/design.md): WGS-84; ENU world frame (x east, y north, z up) anchored at a
geodetic origin; yaw ψ counter-clockwise from east; course clockwise from north, course = 90° − ψ.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pymap3d

WGS84_A = 6378137.0
WGS84_F = 1.0 / 298.257223563
EARTH_MEAN_RADIUS_M = 6371000.0
SPEED_OF_LIGHT = 299792458.0


def geodetic_to_ecef(lat_rad, lon_rad, height_m) -> np.ndarray:
    """Geodetic latitude/longitude (rad) and ellipsoidal height (m) to ECEF (…, 3) in metres."""
    x, y, z = pymap3d.geodetic2ecef(lat_rad, lon_rad, height_m, deg=False)
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1).astype(float)


_WGS84 = pymap3d.Ellipsoid.from_name("wgs84")
_SEMIMAJOR, _SEMIMINOR = _WGS84.semimajor_axis, _WGS84.semiminor_axis
_LINEAR_ECCENTRICITY = np.sqrt(_SEMIMAJOR**2 - _SEMIMINOR**2)


def ecef_to_geodetic(ecef: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ECEF (…, 3) in metres to latitude (rad), longitude (rad), ellipsoidal height (m).

    Without iterations (R.-J. You, J. Surv. Eng. 2000, eqs. 4a–4c, 7, 13): pymap3d's
    ``ecef2geodetic`` (``deg=False``), the same NumPy operations in the same order, so the same
    bits; without its per-call ellipsoid lookup and ``isclose`` calls (``|a| ≤ 1e-8`` is
    ``isclose(a, 0)``), a fifth of its time on the SPP's single positions.
    """
    ecef = np.asarray(ecef, dtype=float)
    x, y, z = ecef[..., 0], ecef[..., 1], ecef[..., 2]
    a, b, e = _SEMIMAJOR, _SEMIMINOR, _LINEAR_ECCENTRICITY
    r = np.sqrt(x**2 + y**2 + z**2)
    u = np.sqrt(0.5 * (r**2 - e**2) + 0.5 * np.hypot(r**2 - e**2, 2 * e * z))
    hxy = np.hypot(x, y)
    hue = np.hypot(u, e)
    bad = (np.abs(u) <= 1e-8) | (np.abs(hxy) <= 1e-8)
    # Element-wise selections rather than masked assignments: one point (the SPP's every
    # iteration) costs a third of the time; the kept elements are the same operations.
    with np.errstate(divide="ignore", invalid="ignore"):
        beta = np.arctan(hue / u * z / hxy)
        beta = beta + ((b * u - a * hue + e**2) * np.sin(beta)) / (
            a * hue * 1 / np.cos(beta) - e**2 * np.cos(beta)
        )
    on_axis = bad & (np.abs(z) <= 1e-8)
    pole = np.where(z > 0, np.pi / 2, -np.pi / 2)
    beta = np.where(bad, np.where(on_axis, 0.0, pole), beta)
    lat = np.arctan(a / b * np.tan(beta))
    limit = np.pi / 2 - np.finfo(beta.dtype).eps
    lat = np.where(beta >= limit, np.pi / 2, lat)
    lat = np.where(beta <= -limit, -np.pi / 2, lat)
    lon = np.arctan2(y, x)
    cos_beta = np.cos(beta)
    cos_beta = np.where(beta >= limit, 0, cos_beta)
    cos_beta = np.where(beta <= -limit, 0, cos_beta)
    height = np.hypot(z - b * np.sin(beta), hxy - a * cos_beta)
    inside = x**2 / a**2 + y**2 / a**2 + z**2 / b**2 < 1
    height = np.where(inside, -height, height)
    return np.asarray(lat.squeeze()[()]), np.asarray(lon), np.asarray(height)


def ecef_to_enu_rotation(lat_rad: float, lon_rad: float) -> np.ndarray:
    """Rotation matrix R with v_enu = R @ v_ecef at the given geodetic point."""
    sl, cl = np.sin(lat_rad), np.cos(lat_rad)
    so, co = np.sin(lon_rad), np.cos(lon_rad)
    return np.array(
        [
            [-so, co, 0.0],
            [-sl * co, -sl * so, cl],
            [cl * co, cl * so, sl],
        ]
    )


@dataclass(frozen=True)
class EnuFrame:
    """A local east-north-up frame anchored at a geodetic origin."""

    lat_rad: float
    lon_rad: float
    height_m: float

    @classmethod
    def from_ecef(cls, origin_ecef: np.ndarray) -> EnuFrame:
        lat, lon, h = ecef_to_geodetic(np.asarray(origin_ecef, dtype=float))
        return cls(float(lat), float(lon), float(h))

    @property
    def origin_ecef(self) -> np.ndarray:
        return geodetic_to_ecef(self.lat_rad, self.lon_rad, self.height_m)

    @property
    def rotation(self) -> np.ndarray:
        return ecef_to_enu_rotation(self.lat_rad, self.lon_rad)

    def ecef_to_enu(self, ecef: np.ndarray) -> np.ndarray:
        """ECEF positions (…, 3) to ENU positions (…, 3) in this frame."""
        return (np.asarray(ecef, dtype=float) - self.origin_ecef) @ self.rotation.T

    def enu_to_ecef(self, enu: np.ndarray) -> np.ndarray:
        """ENU positions (…, 3) in this frame to ECEF positions (…, 3)."""
        return np.asarray(enu, dtype=float) @ self.rotation + self.origin_ecef

    def geodetic_to_enu(self, lat_rad, lon_rad, height_m) -> np.ndarray:
        return self.ecef_to_enu(geodetic_to_ecef(lat_rad, lon_rad, height_m))


def wrap_angle(angle_rad):
    """Wrap angles to [-π, π)."""
    return (np.asarray(angle_rad) + np.pi) % (2.0 * np.pi) - np.pi


def yaw_to_course(yaw_rad):
    """Yaw (counter-clockwise from east) to course (clockwise from north), radians in [0, 2π)."""
    return np.mod(np.pi / 2.0 - np.asarray(yaw_rad), 2.0 * np.pi)


def course_to_yaw(course_rad):
    """Course (clockwise from north) to yaw (counter-clockwise from east), radians in [-π, π)."""
    return wrap_angle(np.pi / 2.0 - np.asarray(course_rad))


def yaw_of(rotations: np.ndarray) -> np.ndarray:
    """Yaw (ZYX Euler, counter-clockwise about z) of (N, 3, 3) body-to-world rotations."""
    return np.arctan2(rotations[:, 1, 0], rotations[:, 0, 0])
