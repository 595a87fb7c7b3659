"""CSV tables of GNSS velocity and SPP results (``vel.csv``, ``pos.csv``; degrees for people)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from vo_doppler.geo import EnuFrame, ecef_to_geodetic
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution

VELOCITY_COLUMNS = (
    "gps_time_s",
    "ve",
    "vn",
    "vu",
    "speed_mps",
    "course_deg",
    "clock_drift_mps",
    "n_sat",
    "residual_rms_mps",
    "valid",
    "verified",
    "speed_sigma_mps",
    "course_sigma_deg",
    "pdop",
    "hdop",
    "hpl_mps",
)
SPP_COLUMNS = (
    "gps_time_s",
    "lat_deg",
    "lon_deg",
    "height_m",
    "x_m",
    "y_m",
    "z_m",
    "e_m",
    "n_m",
    "u_m",
    "n_sat",
    "residual_rms_m",
    "pdop",
    "valid",
    "verified",
    "hdop",
    "horizontal_sigma_m",
    "vertical_sigma_m",
    "hpl_m",
    "vpl_m",
)


def _write(path: Path, columns: tuple[str, ...], table: list[np.ndarray], formats: list[str]):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(columns)
        for row in zip(*table, strict=True):
            writer.writerow(
                "" if isinstance(v, float) and np.isnan(v) else f.format(v)
                for v, f in zip(row, formats, strict=True)
            )


def _or_nan(values: np.ndarray | None, n: int) -> np.ndarray:
    return np.full(n, np.nan) if values is None else values


def write_velocity_csv(path: str | Path, solution: VelocitySolution) -> None:
    """One row per epoch; unavailable epochs have empty numbers and valid = 0."""
    v = solution.velocity_enu
    _write(
        Path(path),
        VELOCITY_COLUMNS,
        [
            solution.t,
            v[:, 0],
            v[:, 1],
            v[:, 2],
            solution.speed_mps,
            solution.course_deg,
            solution.clock_drift_mps,
            solution.n_sat,
            solution.residual_rms_mps,
            solution.valid.astype(int),
            solution.verified.astype(int),
            solution.speed_sigma_mps,
            np.degrees(solution.course_sigma_rad),
            solution.dop[:, 1],
            solution.dop[:, 2],
            _or_nan(solution.horizontal_protection_mps, len(solution.t)),
        ],
        ["{:.3f}"]
        + ["{:.4f}"] * 4
        + ["{:.2f}", "{:.4f}", "{:d}", "{:.4f}", "{:d}", "{:d}"]
        + ["{:.4f}", "{:.3f}", "{:.2f}", "{:.2f}", "{:.3f}"],
    )


def write_spp_csv(path: str | Path, solution: SppSolution) -> None:
    """Positions per epoch: geodetic, ECEF and ENU about the median valid fix."""
    lat, lon, height = ecef_to_geodetic(solution.position_ecef)
    enu = np.full_like(solution.position_ecef, np.nan)
    if solution.valid.any():
        frame = EnuFrame.from_ecef(np.median(solution.position_ecef[solution.valid], axis=0))
        enu = frame.ecef_to_enu(solution.position_ecef)
    p = solution.position_ecef
    _write(
        Path(path),
        SPP_COLUMNS,
        [
            solution.t,
            np.rad2deg(lat),
            np.rad2deg(lon),
            height,
            p[:, 0],
            p[:, 1],
            p[:, 2],
            enu[:, 0],
            enu[:, 1],
            enu[:, 2],
            solution.n_sat,
            solution.residual_rms_m,
            solution.pdop,
            solution.valid.astype(int),
            solution.verified.astype(int),
            solution.hdop,
            solution.horizontal_sigma_m,
            _or_nan(solution.vertical_sigma_m, len(solution.t)),
            _or_nan(solution.horizontal_protection_m, len(solution.t)),
            _or_nan(solution.vertical_protection_m, len(solution.t)),
        ],
        ["{:.3f}", "{:.9f}", "{:.9f}"]
        + ["{:.3f}"] * 7
        + ["{:d}", "{:.3f}", "{:.2f}", "{:d}"]
        + ["{:d}", "{:.2f}", "{:.2f}", "{:.2f}", "{:.2f}", "{:.2f}"],
    )
