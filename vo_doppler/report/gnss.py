"""CSV tables and a figure for GNSS velocity and SPP results (people-facing units: degrees)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from vo_doppler.geo import EnuFrame, ecef_to_geodetic
from vo_doppler.gnss.doppler_velocity import VelocitySolution
from vo_doppler.gnss.spp import SppSolution

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
        ],
        ["{:.3f}"] + ["{:.4f}"] * 4 + ["{:.2f}", "{:.4f}", "{:d}", "{:.4f}", "{:d}"],
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
        ],
        ["{:.3f}", "{:.9f}", "{:.9f}"] + ["{:.3f}"] * 7 + ["{:d}", "{:.3f}", "{:.2f}", "{:d}"],
    )


def velocity_figure(path: str | Path, solution: VelocitySolution, title: str = "") -> None:
    """Speed, course and satellite count over time (PNG)."""
    t = solution.t - solution.t[0] if solution.t.size else solution.t
    fig = Figure(figsize=(9, 7))
    axes = fig.subplots(3, 1, sharex=True)
    axes[0].plot(t, solution.speed_mps, ".-", ms=3)
    axes[0].set_ylabel("speed (m/s)")
    course = np.where(solution.speed_mps > 0.2, solution.course_deg, np.nan)
    axes[1].plot(t, course, ".", ms=3)
    axes[1].set_ylabel("course (deg, cw from N)\nspeed > 0.2 m/s")
    axes[1].set_ylim(0, 360)
    axes[2].step(t, solution.n_sat, where="mid")
    if not solution.valid.all():
        missing = ~solution.valid
        axes[2].plot(t[missing], solution.n_sat[missing], "rx", label="unavailable")
        axes[2].legend(loc="best")
    axes[2].set_ylabel("satellites")
    axes[2].yaxis.set_major_locator(MaxNLocator(integer=True))
    axes[2].set_xlabel("time since first epoch (s)")
    fig.suptitle(title or "GNSS Doppler velocity")
    _save(fig, path)


def spp_figure(path: str | Path, solution: SppSolution, title: str = "") -> None:
    """East/north/up about the median fix and satellite count over time (PNG)."""
    t = solution.t - solution.t[0] if solution.t.size else solution.t
    fig = Figure(figsize=(9, 6))
    axes = fig.subplots(2, 1, sharex=True)
    if solution.valid.any():
        frame = EnuFrame.from_ecef(np.median(solution.position_ecef[solution.valid], axis=0))
        enu = frame.ecef_to_enu(solution.position_ecef)
        for k, name in enumerate("enu"):
            axes[0].plot(t, enu[:, k], ".", ms=3, label=name)
        axes[0].legend(loc="best")
    axes[0].set_ylabel("position about median (m)")
    axes[1].step(t, solution.n_sat, where="mid")
    axes[1].set_ylabel("satellites")
    axes[1].yaxis.set_major_locator(MaxNLocator(integer=True))
    axes[1].set_xlabel("time since first epoch (s)")
    fig.suptitle(title or "GNSS single-point positions")
    _save(fig, path)


def _save(fig, path: str | Path) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
