"""Reading back ``vel.csv`` and ``pos.csv`` (written by :mod:`vo_doppler.io.gnss_csv`) to score
them: what the CSV holds comes back in the solution types; what it does not hold (the ECEF
velocity, the covariance, the DOPs other than PDOP and HDOP) is NaN.

Only the columns scoring needs are required (``gps_time_s``, ``ve``, ``vn``, ``vu``, ``valid``
for ``vel.csv``; ``gps_time_s``, ``x_m``, ``y_m``, ``z_m``, ``valid`` for ``pos.csv``), so files
of older versions read too. Blank numbers (unsolved epochs) are NaN; times must increase.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.io.gnss_csv import SPP_COLUMNS, VELOCITY_COLUMNS
from vo_doppler.io.textfile import read_text
from vo_doppler.io.truth_csv import HeadedColumns, headed_columns, increasing_times
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution

VELOCITY_REQUIRED = ("gps_time_s", "ve", "vn", "vu", "valid")
POSITION_REQUIRED = ("gps_time_s", "x_m", "y_m", "z_m", "valid")


def _table(path: str | Path, what: str, wanted, required) -> tuple[HeadedColumns, Path]:
    path = Path(path)
    table = headed_columns(read_text(path, what), path, what, tuple(wanted), required)
    increasing_times(table.columns["gps_time_s"], table.line, path, what)
    return table, path


def _flag(table: HeadedColumns, name: str, path: Path) -> np.ndarray:
    """A 0/1 column as booleans (blank or missing: False); another value names its line."""
    values = table.columns.get(name)
    if values is None:
        return np.zeros(len(table.line), dtype=bool)
    bad = np.isfinite(values) & (values != 0) & (values != 1)
    if bad.any():
        k = int(np.argmax(bad))
        raise InputError(f"{name} must be 0 or 1, found {values[k]:g}", path, int(table.line[k]))
    return values == 1


def _column(table: HeadedColumns, name: str) -> np.ndarray:
    return table.columns.get(name, np.full(len(table.line), np.nan))


def read_velocity_csv(path: str | Path) -> VelocitySolution:
    """A ``vel.csv`` as a :class:`VelocitySolution` (ENU velocity, validity, σ, DOP, HPL)."""
    table, path = _table(path, "velocity CSV", VELOCITY_COLUMNS, VELOCITY_REQUIRED)
    n = len(table.line)
    enu = np.column_stack([table.columns[c] for c in ("ve", "vn", "vu")])
    valid = _flag(table, "valid", path)
    bad = valid & ~np.isfinite(enu).all(axis=1)
    if bad.any():
        raise InputError("a valid epoch without a velocity", path, int(table.line[bad][0]))
    dop = np.full((n, 5), np.nan)
    dop[:, 1], dop[:, 2] = _column(table, "pdop"), _column(table, "hdop")
    n_sat = np.nan_to_num(_column(table, "n_sat")).astype(int)
    verified = _flag(table, "verified", path) if "verified" in table.columns else valid.copy()
    return VelocitySolution(
        t=table.columns["gps_time_s"],
        velocity_ecef=np.full((n, 3), np.nan),
        velocity_enu=enu,
        clock_drift_mps=_column(table, "clock_drift_mps"),
        covariance=np.full((n, 4, 4), np.nan),
        dop=dop,
        n_sat=n_sat,
        n_obs=n_sat.copy(),
        n_excluded=np.zeros(n, dtype=int),
        residual_rms_mps=_column(table, "residual_rms_mps"),
        valid=valid,
        verified=verified,
        speed_sigma_mps=_column(table, "speed_sigma_mps"),
        course_sigma_rad=np.radians(_column(table, "course_sigma_deg")),
        horizontal_protection_mps=_column(table, "hpl_mps"),
    )


def read_position_csv(path: str | Path) -> SppSolution:
    """A ``pos.csv`` as an :class:`SppSolution` (ECEF positions, validity, DOP, σ)."""
    table, path = _table(path, "position CSV", SPP_COLUMNS, POSITION_REQUIRED)
    ecef = np.column_stack([table.columns[c] for c in ("x_m", "y_m", "z_m")])
    valid = _flag(table, "valid", path)
    bad = valid & ~np.isfinite(ecef).all(axis=1)
    if bad.any():
        raise InputError("a valid epoch without a position", path, int(table.line[bad][0]))
    return SppSolution(
        t=table.columns["gps_time_s"],
        position_ecef=ecef,
        clock_bias_m={},
        n_sat=np.nan_to_num(_column(table, "n_sat")).astype(int),
        residual_rms_m=_column(table, "residual_rms_m"),
        pdop=_column(table, "pdop"),
        valid=valid,
        n_no_ephemeris=0,
        verified=_flag(table, "verified", path) if "verified" in table.columns else valid.copy(),
        hdop=_column(table, "hdop"),
        horizontal_sigma_m=_column(table, "horizontal_sigma_m"),
        vertical_sigma_m=_column(table, "vertical_sigma_m"),
        horizontal_protection_m=_column(table, "hpl_m"),
        vertical_protection_m=_column(table, "vpl_m"),
    )
