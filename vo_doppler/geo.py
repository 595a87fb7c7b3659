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


def ecef_to_geodetic(ecef: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ECEF (…, 3) in metres to latitude (rad), longitude (rad), ellipsoidal height (m)."""
    ecef = np.asarray(ecef, dtype=float)
    lat, lon, h = pymap3d.ecef2geodetic(ecef[..., 0], ecef[..., 1], ecef[..., 2], deg=False)
    return np.asarray(lat), np.asarray(lon), np.asarray(h)


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
