"""Broadcast atmosphere models for single-frequency pseudoranges.

- Troposphere: Saastamoinen (1972) zenith delays for a standard atmosphere (humidity 70 %),
  hydrostatic part with the Davis et al. (1985) gravity term, mapped with 1/cos z.
- Ionosphere: GPS Klobuchar model, IS-GPS-200 sec. 20.3.3.5.2.5 (L1 delay, scaled by
  (f_L1/f)² for other carriers).
"""

from __future__ import annotations

import numpy as np

from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.model.gpstime import time_of_week

L1_HZ = 1575.42e6


def troposphere_delay(lat_rad: float, height_m: float, elevation: np.ndarray) -> np.ndarray:
    """Slant delay (m): Saastamoinen zenith delays — hydrostatic with the Davis et al. (1985)
    gravity term, wet from a standard atmosphere at 70 % humidity — mapped with 1/cos z."""
    h = np.clip(height_m, 0.0, 1e4)
    pressure = 1013.25 * (1.0 - 2.2557e-5 * h) ** 5.2568
    temperature = 15.0 - 6.5e-3 * h + 273.16
    vapour = 6.108 * 0.7 * np.exp((17.15 * temperature - 4684.0) / (temperature - 38.45))
    cos_z = np.sin(np.maximum(elevation, np.deg2rad(3.0)))
    hydrostatic = 0.0022768 * pressure / (1.0 - 0.00266 * np.cos(2.0 * lat_rad) - 0.00028e-3 * h)
    wet = 0.002277 * (1255.0 / temperature + 0.05) * vapour
    return (hydrostatic + wet) / cos_z


def klobuchar_delay(
    coefficients: np.ndarray,
    lat_rad: float,
    lon_rad: float,
    elevation: np.ndarray,
    azimuth: np.ndarray,
    gps_time: np.ndarray,
    frequency_hz: np.ndarray | float = L1_HZ,
) -> np.ndarray:
    """Ionospheric delay (m) of the Klobuchar model (α0–α3, β0–β3 in ``coefficients``)."""
    alpha, beta = coefficients[:4], coefficients[4:]
    phi_u, lam_u = lat_rad / np.pi, lon_rad / np.pi  # semicircles
    e = np.asarray(elevation) / np.pi
    psi = 0.0137 / (e + 0.11) - 0.022
    phi_i = np.clip(phi_u + psi * np.cos(azimuth), -0.416, 0.416)
    lam_i = lam_u + psi * np.sin(azimuth) / np.cos(phi_i * np.pi)
    phi_m = phi_i + 0.064 * np.cos((lam_i - 1.617) * np.pi)
    _, tow = time_of_week(gps_time)
    t = np.mod(4.32e4 * lam_i + tow, 86400.0)
    slant = 1.0 + 16.0 * (0.53 - e) ** 3
    period = np.maximum(sum(b * phi_m**k for k, b in enumerate(beta)), 72000.0)
    amplitude = np.maximum(sum(a * phi_m**k for k, a in enumerate(alpha)), 0.0)
    x = 2.0 * np.pi * (t - 50400.0) / period
    delay = np.where(
        np.abs(x) < 1.57,
        slant * (5e-9 + amplitude * (1.0 - x**2 / 2.0 + x**4 / 24.0)),
        slant * 5e-9,
    )
    return SPEED_OF_LIGHT * delay * (L1_HZ / np.asarray(frequency_hz)) ** 2
