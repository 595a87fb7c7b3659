"""``heading.csv``: one row per GNSS epoch, headings as course in degrees clockwise from north.

Columns: gps_time_s, heading_tc_deg, heading_tc_sigma_deg, tc_reliable, n_obs_window,
n_sat_epoch, heading_conv_deg, conv_valid, gyro_bias_dps, wheel_scale, then rejected_rows (rows
of the window rejected as biased, NLOS) and tc_verifiable (a bias on any satellite used would
have shown), tc_window_s (the tight heading's window, the same on every row),
conv_speed_sigma_mps and conv_hdop (the conventional velocity's speed standard deviation and
horizontal DOP) and heading_conv_sigma_deg (the conventional heading's standard deviation),
conv_gnss_valid and heading_conv_gnss_sigma_deg (the conventional heading's validity by the GNSS
tests alone and its σ from the velocity solution: the published method, the comparison
pipeline's input; ``conv_valid`` adds every integrity test). Unavailable headings are written as
``nan``; flags as 0/1. Reading converts back to yaw (rad, counter-clockwise from east); the last
eight columns are optional (files written before they existed read as zero, or NaN for the
standard deviations and the DOP; without conv_gnss_valid the GNSS validity is conv_valid's).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.geo import course_to_yaw
from vo_doppler.io.textfile import read_text
from vo_doppler.model.heading import DEFAULT_TC_WINDOW_S, HeadingTable

COLUMNS = (
    "gps_time_s",
    "heading_tc_deg",
    "heading_tc_sigma_deg",
    "tc_reliable",
    "n_obs_window",
    "n_sat_epoch",
    "heading_conv_deg",
    "conv_valid",
    "gyro_bias_dps",
    "wheel_scale",
)
OPTIONAL_COLUMNS = (
    "rejected_rows",
    "tc_verifiable",
    "tc_window_s",
    "conv_speed_sigma_mps",
    "conv_hdop",
    "heading_conv_sigma_deg",
    "conv_gnss_valid",
    "heading_conv_gnss_sigma_deg",
)


def write_heading_csv(path: str | Path, table: HeadingTable) -> None:
    columns = [
        table.t,
        np.degrees(table.course_tc),
        np.degrees(table.sigma_tc),
        table.tc_reliable.astype(int),
        table.n_obs_window.astype(int),
        table.n_sat_epoch.astype(int),
        np.degrees(table.course_conv),
        table.conv_valid.astype(int),
        np.degrees(table.gyro_bias),
        table.wheel_scale,
        table.rejected_rows.astype(int),
        table.tc_verifiable.astype(int),
        np.full(len(table), table.tc_window_s),
        table.speed_sigma_conv,
        table.hdop_conv,
        np.degrees(table.sigma_conv),
        table.published_conventional[0].astype(int),
        np.degrees(table.published_conventional[1]),
    ]
    formats = (
        "{:.3f}",
        "{:.4f}",
        "{:.4f}",
        "{:d}",
        "{:d}",
        "{:d}",
        "{:.4f}",
        "{:d}",
        "{:.5f}",
        "{:.6f}",
        "{:d}",
        "{:d}",
        "{:g}",
        "{:.4f}",
        "{:.3f}",
        "{:.4f}",
        "{:d}",
        "{:.4f}",
    )
    with Path(path).open("w", newline="") as handle:
        handle.write(",".join(COLUMNS + OPTIONAL_COLUMNS) + "\n")
        for values in zip(*columns, strict=True):
            handle.write(",".join(f.format(v) for f, v in zip(formats, values, strict=True)) + "\n")


def read_heading_csv(path: str | Path) -> HeadingTable:
    """Read a heading CSV; bad rows (and times that do not increase) raise
    :class:`InputError` naming the line."""
    path = Path(path)
    lines = read_text(path, "heading CSV").splitlines()
    if not lines:
        raise InputError("heading CSV is empty", path)
    header = [name.strip() for name in next(csv.reader([lines[0]]))]
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        raise InputError(f"heading CSV lacks columns {missing}", path, 1)
    index = [header.index(c) for c in COLUMNS + OPTIONAL_COLUMNS if c in header]
    rows = []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = next(csv.reader([line]))
        try:
            rows.append([float(fields[i]) for i in index])
        except (ValueError, IndexError) as exc:
            raise InputError(f"bad heading row ({exc})", path, number) from exc
        if not np.isfinite(rows[-1][0]) or (len(rows) > 1 and rows[-1][0] <= rows[-2][0]):
            raise InputError(
                f"gps_time_s {rows[-1][0]} is not after the previous row's", path, number
            )
    if not rows:
        raise InputError("heading CSV has its header but no rows", path)
    data = np.array(rows, dtype=float).reshape(-1, len(index))
    _check_values(data, lines, path)
    optional = {
        c: data[:, len(COLUMNS) + i]
        for i, c in enumerate(c for c in OPTIONAL_COLUMNS if c in header)
    }
    tc_deg, conv_deg = data[:, 1], data[:, 6]
    gnss_valid, gnss_sigma_deg = (
        optional.get(c) for c in ("conv_gnss_valid", "heading_conv_gnss_sigma_deg")
    )
    return HeadingTable(
        t=data[:, 0],
        yaw_tc=np.where(np.isfinite(tc_deg), course_to_yaw(np.radians(tc_deg)), np.nan),
        sigma_tc=np.radians(data[:, 2]),
        tc_reliable=data[:, 3] > 0.5,
        n_obs_window=data[:, 4].astype(int),
        n_sat_epoch=data[:, 5].astype(int),
        yaw_conv=np.where(np.isfinite(conv_deg), course_to_yaw(np.radians(conv_deg)), np.nan),
        conv_valid=(data[:, 7] > 0.5) & np.isfinite(conv_deg),
        gyro_bias=np.radians(data[:, 8]),
        wheel_scale=data[:, 9],
        rejected_rows=optional.get("rejected_rows", np.zeros(len(data))).astype(int),
        tc_verifiable=optional.get("tc_verifiable", np.zeros(len(data))) > 0.5,
        sigma_conv=np.radians(optional.get("heading_conv_sigma_deg", np.full(len(data), np.nan))),
        speed_sigma_conv=optional.get("conv_speed_sigma_mps", np.full(len(data), np.nan)),
        hdop_conv=optional.get("conv_hdop", np.full(len(data), np.nan)),
        tc_window_s=_window_s(optional.get("tc_window_s"), path),
        conv_gnss_valid=None if gnss_valid is None else (gnss_valid > 0.5) & np.isfinite(conv_deg),
        sigma_conv_gnss=None if gnss_sigma_deg is None else np.radians(gnss_sigma_deg),
    )


HEADING_COLUMNS = (1, 2, 6)
"""Heading and sigma columns: NaN where unavailable; every other column must be finite."""


def _check_values(data: np.ndarray, lines: list[str], path: Path) -> None:
    """No infinite value anywhere and no NaN outside the heading columns (names the line)."""
    optional = np.zeros(data.shape[1], dtype=bool)
    optional[list(HEADING_COLUMNS)] = True
    optional[len(COLUMNS) :] = True  # optional columns may hold NaN (e.g. the conventional sigma)
    bad = np.isinf(data) | (np.isnan(data) & ~optional)
    if bad.any():
        row, column = (int(v) for v in np.argwhere(bad)[0])
        number = [n for n, line in enumerate(lines[1:], start=2) if line.strip()][row]
        raise InputError(f"heading CSV value {data[row, column]} is not usable", path, number)


def _window_s(column: np.ndarray | None, path: Path) -> float:
    """The file's tight-heading window: one positive value, or the default for older files."""
    if column is None or not len(column):
        return DEFAULT_TC_WINDOW_S
    values = np.unique(column)
    if len(values) != 1 or not np.isfinite(values[0]) or values[0] <= 0:
        raise InputError(f"tc_window_s must be one positive value, found {values[:3]}", path)
    return float(values[0])
