"""A deterministic two-gyro + GPS record: a long standstill, then one closed stadium loop.

Known truth: yaw, yaw rate and ENU position at every gyro-1 sample. Each gyro adds a constant
turn-on bias, a bias random walk (rate random walk K, rad/s/√s) and white noise (angle random
walk N, rad/s/√Hz); the GPS adds a first-order Gauss–Markov error per axis (a cheap receiver
wanders slowly rather than jumping) plus a little white noise. Yaw is CCW from east.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from vo_doppler.geo import EnuFrame, ecef_to_geodetic
from vo_doppler.io.gps_fixes import write_gps_csv
from vo_doppler.io.sensor_csv import YAW_RATE_COLUMN, write_sensor_csv
from vo_doppler.model.series import SensorSeries

DEG = np.pi / 180.0


@dataclass(frozen=True)
class TwoGyroSpec:
    """Parameters of the generated record (SI units, rates in rad/s)."""

    standstill_s: float = 600.0
    end_standstill_s: float = 10.0
    straight_m: float = 300.0
    radius_m: float = 50.0
    speed_mps: float = 10.0
    accel_mps2: float = 2.0
    gyro1_hz: float = 100.0
    gyro2_hz: float = 50.0
    gps_hz: float = 1.0
    bias1: float = 0.285 * DEG
    bias2: float = -0.15 * DEG
    arw1: float = 0.005 * DEG
    arw2: float = 0.01 * DEG
    rrw1: float = 5e-5 * DEG
    rrw2: float = 2e-4 * DEG
    gps_sigma_m: float = 1.5
    gps_tau_s: float = 300.0
    gps_white_m: float = 0.1
    origin_lat_deg: float = 35.0
    origin_lon_deg: float = 139.0
    t_start: float = 1_400_000_000.0
    seed: int = 7
    drive: bool = True

    @property
    def loop_length_m(self) -> float:
        return 2.0 * self.straight_m + 2.0 * np.pi * self.radius_m


@dataclass(frozen=True)
class TwoGyroRecord:
    """Sensor streams (t, value) and the truth on gyro 1's times."""

    spec: TwoGyroSpec
    gyro1: tuple[np.ndarray, np.ndarray]
    gyro2: tuple[np.ndarray, np.ndarray]
    gps: tuple[np.ndarray, np.ndarray, np.ndarray]
    truth_t: np.ndarray
    truth_yaw: np.ndarray
    truth_east: np.ndarray
    truth_north: np.ndarray

    @property
    def standstill(self) -> tuple[float, float]:
        return (self.spec.t_start, self.spec.t_start + self.spec.standstill_s)


def _arc_length(spec: TwoGyroSpec, t_rel: np.ndarray) -> tuple[np.ndarray, float]:
    """Distance along the loop at times since the drive starts: ramp up, cruise, ramp down."""
    v, a, total = spec.speed_mps, spec.accel_mps2, spec.loop_length_m
    t_ramp = v / a
    d_ramp = v * t_ramp / 2.0
    t_cruise = (total - 2.0 * d_ramp) / v
    t_drive = 2.0 * t_ramp + t_cruise
    t = np.clip(t_rel, 0.0, t_drive)
    up = a * np.minimum(t, t_ramp) ** 2 / 2.0
    cruise = v * np.clip(t - t_ramp, 0.0, t_cruise)
    t_down = np.clip(t - t_ramp - t_cruise, 0.0, t_ramp)
    down = v * t_down - a * t_down**2 / 2.0
    return up + cruise + down, t_drive


def _stadium(spec: TwoGyroSpec, s: np.ndarray):
    """Position and yaw along the stadium loop (straight east, left half-turn, straight west,
    left half-turn) at arc lengths ``s``; it closes on itself with yaw + 2π."""
    L, R = spec.straight_m, spec.radius_m
    s = np.asarray(s, dtype=float)
    east, north, yaw = np.zeros_like(s), np.zeros_like(s), np.zeros_like(s)
    seg1 = s < L
    seg2 = (s >= L) & (s < L + np.pi * R)
    seg3 = (s >= L + np.pi * R) & (s < 2 * L + np.pi * R)
    seg4 = s >= 2 * L + np.pi * R
    east[seg1] = s[seg1]
    phi = (s[seg2] - L) / R
    east[seg2], north[seg2], yaw[seg2] = L + R * np.sin(phi), R - R * np.cos(phi), phi
    east[seg3], north[seg3], yaw[seg3] = L - (s[seg3] - L - np.pi * R), 2 * R, np.pi
    phi = np.minimum(s[seg4] - 2 * L - np.pi * R, np.pi * R) / R
    east[seg4], north[seg4], yaw[seg4] = -R * np.sin(phi), R + R * np.cos(phi), np.pi + phi
    return east, north, yaw


def _gyro(rng, t, true_rate_at, bias, arw, rrw, fs):
    walk = np.cumsum(rng.normal(0.0, rrw / np.sqrt(fs), len(t)))
    return true_rate_at(t) + bias + walk + rng.normal(0.0, arw * np.sqrt(fs), len(t))


def generate_two_gyro(spec: TwoGyroSpec | None = None) -> TwoGyroRecord:
    """Generate the record; the same spec always gives the same numbers."""
    spec = spec or TwoGyroSpec()
    rng = np.random.default_rng(spec.seed)
    drive_start = spec.t_start + spec.standstill_s
    _, t_drive = _arc_length(spec, np.zeros(1))
    duration = spec.standstill_s
    if spec.drive:
        duration += t_drive + spec.end_standstill_s

    def truth(t):
        s, _ = _arc_length(spec, t - drive_start)
        return _stadium(spec, s if spec.drive else np.zeros_like(s))

    def true_rate(t):
        dt = 1e-4
        return (truth(t + dt)[2] - truth(t - dt)[2]) / (2 * dt)

    t1 = spec.t_start + np.arange(0.0, duration, 1.0 / spec.gyro1_hz)
    t2 = spec.t_start + np.arange(0.0, duration, 1.0 / spec.gyro2_hz)
    omega1 = _gyro(rng, t1, true_rate, spec.bias1, spec.arw1, spec.rrw1, spec.gyro1_hz)
    omega2 = _gyro(rng, t2, true_rate, spec.bias2, spec.arw2, spec.rrw2, spec.gyro2_hz)

    tg = spec.t_start + np.arange(0.0, duration, 1.0 / spec.gps_hz)
    a = np.exp(-1.0 / (spec.gps_hz * spec.gps_tau_s))
    error = np.zeros((len(tg), 2))
    error[0] = rng.normal(0.0, spec.gps_sigma_m, 2)
    kicks = rng.normal(0.0, spec.gps_sigma_m * np.sqrt(1.0 - a * a), (len(tg), 2))
    for i in range(1, len(tg)):
        error[i] = a * error[i - 1] + kicks[i]
    error += rng.normal(0.0, spec.gps_white_m, error.shape)
    east_g, north_g, _ = truth(tg)
    frame = EnuFrame(spec.origin_lat_deg * DEG, spec.origin_lon_deg * DEG, 0.0)
    ecef = frame.enu_to_ecef(
        np.column_stack([east_g + error[:, 0], north_g + error[:, 1], np.zeros(len(tg))])
    )

    lat, lon, _ = ecef_to_geodetic(ecef)
    east, north, yaw = truth(t1)
    return TwoGyroRecord(
        spec, (t1, omega1), (t2, omega2), (tg, lat, lon), t1, np.unwrap(yaw), east, north
    )


def calibration_spec(
    spec: TwoGyroSpec, shift1: float = -0.035 * DEG, shift2: float = -0.04 * DEG
) -> TwoGyroSpec:
    """The same gyros on another power-up, standing still only: the turn-on biases differ by
    ``shift1``/``shift2`` (bias repeatability). The seed chooses k on such a record."""
    return replace(
        spec, drive=False, bias1=spec.bias1 + shift1, bias2=spec.bias2 + shift2, seed=spec.seed + 1
    )


def write_two_gyro(record: TwoGyroRecord, folder: str | Path) -> dict[str, Path]:
    """Write ``gyro1.csv``, ``gyro2.csv`` (t,yaw_rate_rad_s) and ``gps.csv`` (t,lat_deg,lon_deg)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    paths = {name: folder / f"{name}.csv" for name in ("gyro1", "gyro2", "gps")}
    for name in ("gyro1", "gyro2"):
        series = SensorSeries(*getattr(record, name))
        write_sensor_csv(paths[name], series, YAW_RATE_COLUMN)
    t, lat, lon = record.gps
    write_gps_csv(paths["gps"], t, lat, lon)
    return paths
