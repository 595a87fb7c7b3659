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

A minimal heading CSV, for an absolute heading from elsewhere (a dual-antenna receiver, an INS,
another GNSS engine), has the columns gps_time_s, heading_deg or course_deg (degrees clockwise
from north; empty or ``nan`` where unavailable), sigma_deg (its standard deviation, degrees)
and optionally valid (0/1; without it every row with a heading is valid); other columns are
ignored. It reads as a table whose conventional heading is that heading (single-epoch, valid
and σ as given, for the conventional heading by the GNSS tests too) and which has no tightly
coupled heading and no calibration (gyro bias and wheel scale NaN): ``correct`` uses it as it
would a ``heading.csv`` with those conventional headings.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from vo_doppler.bounds import (
    DOP,
    HEADING_DEG,
    HEADING_SIGMA_DEG,
    MAX_COUNT,
    MAX_SATELLITES,
    MEASUREMENT_SIGMA,
    WHEEL_SCALE,
    YAW_RATE,
    SignalBounds,
)
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
    if missing and "gps_time_s" in header and any(c in header for c in MINIMAL_HEADINGS):
        return _read_minimal(path, lines, header)
    if missing:
        raise InputError(
            f"heading CSV lacks columns {missing}: expected the heading.csv of "
            f"`vo-doppler heading` ({', '.join(COLUMNS)}, ...) or {MINIMAL_FORMAT}",
            path,
            1,
        )
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
    _check_values(data, lines, path, [c for c in COLUMNS + OPTIONAL_COLUMNS if c in header])
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
FLAGS = ("tc_reliable", "conv_valid", "tc_verifiable", "conv_gnss_valid")
COUNTS = {"n_obs_window": MAX_COUNT, "n_sat_epoch": MAX_SATELLITES, "rejected_rows": MAX_COUNT}
GYRO_BIAS_DEG_S = SignalBounds(-math.degrees(YAW_RATE.high), math.degrees(YAW_RATE.high), "°/s")
"""A gyro bias beyond the largest yaw rate a car's gyro measures is not a bias."""
RANGES: dict[str, SignalBounds] = {
    "heading_tc_deg": HEADING_DEG,
    "heading_conv_deg": HEADING_DEG,
    "heading_tc_sigma_deg": HEADING_SIGMA_DEG,
    "heading_conv_sigma_deg": HEADING_SIGMA_DEG,
    "heading_conv_gnss_sigma_deg": HEADING_SIGMA_DEG,
    "conv_speed_sigma_mps": MEASUREMENT_SIGMA,
    "conv_hdop": DOP,
    "gyro_bias_dps": GYRO_BIAS_DEG_S,
    "wheel_scale": WHEEL_SCALE,
}
"""Physical bounds of the columns (:mod:`vo_doppler.bounds`); NaN, where a column
may hold it, is checked apart."""


def _check_values(data: np.ndarray, lines: list[str], path: Path, names: list[str]) -> None:
    """No infinite value anywhere, no NaN outside the heading and optional columns, every value
    within its column's bounds (``RANGES``), flags 0 or 1 and counts whole numbers from zero to
    their bound (``COUNTS``); an :class:`InputError` names the line and the column."""
    optional = np.zeros(data.shape[1], dtype=bool)
    optional[list(HEADING_COLUMNS)] = True
    optional[len(COLUMNS) :] = True  # optional columns may hold NaN (e.g. the conventional sigma)
    bad = np.isinf(data) | (np.isnan(data) & ~optional)
    why = np.full(data.shape, "", dtype=object)
    why[bad] = "is not usable"
    for column, name in enumerate(names):
        values = data[:, column]
        given = ~np.isnan(values)
        if name in RANGES:
            outside = given & RANGES[name].outside(values)
            why[outside & ~bad[:, column], column] = f"is outside {RANGES[name]}"
            bad[:, column] |= outside
        elif name in FLAGS:
            wrong = given & (values != 0) & (values != 1)
            why[wrong & ~bad[:, column], column] = "is not 0 or 1"
            bad[:, column] |= wrong
        elif name in COUNTS:
            wrong = given & ((values != np.round(values)) | (values < 0) | (values > COUNTS[name]))
            why[wrong & ~bad[:, column], column] = f"is not a count from 0 to {COUNTS[name]:g}"
            bad[:, column] |= wrong
    if bad.any():
        row, column = (int(v) for v in np.argwhere(bad)[0])
        number = [n for n, line in enumerate(lines[1:], start=2) if line.strip()][row]
        raise InputError(
            f"heading CSV column {names[column]}: {data[row, column]:g} {why[row, column]}",
            path,
            number,
        )


def _window_s(column: np.ndarray | None, path: Path) -> float:
    """The file's tight-heading window: one positive value, or the default for older files."""
    if column is None or not len(column):
        return DEFAULT_TC_WINDOW_S
    values = np.unique(column)
    if len(values) != 1 or not np.isfinite(values[0]) or values[0] <= 0:
        raise InputError(f"tc_window_s must be one positive value, found {values[:3]}", path)
    return float(values[0])


MINIMAL_HEADINGS = ("heading_deg", "course_deg")
"""The heading column of a minimal heading CSV: one of these (degrees clockwise from north)."""
MINIMAL_FORMAT = (
    "a minimal heading CSV: gps_time_s, heading_deg or course_deg (degrees clockwise from "
    "north), sigma_deg (> 0, degrees) and optionally valid (0 or 1)"
)
MAX_HEADING_DEG = 360.0
"""Headings beyond ±360° are not angles anyone writes (a corrupt row or another unit)."""
MAX_SIGMA_DEG = 180.0
"""A standard deviation beyond 180° says nothing about a direction."""


def _read_minimal(path: Path, lines: list[str], header: list[str]) -> HeadingTable:
    """A minimal heading CSV (module docstring) as a table whose conventional heading is the
    file's; every bad row raises :class:`InputError` naming the line, the column and the
    columns expected."""
    names = [c for c in MINIMAL_HEADINGS if c in header]
    if len(names) > 1:
        raise InputError(
            f"heading CSV has both {' and '.join(names)}: give one ({MINIMAL_FORMAT})", path, 1
        )
    if "sigma_deg" not in header:
        raise InputError(f"heading CSV lacks column sigma_deg: expected {MINIMAL_FORMAT}", path, 1)
    columns = ["gps_time_s", names[0], "sigma_deg"] + (["valid"] if "valid" in header else [])
    index = [header.index(c) for c in columns]
    rows: list[tuple[float, float, float, bool]] = []
    for number, line in enumerate(lines[1:], start=2):
        if not line.strip():
            continue
        fields = next(csv.reader([line]))
        if len(fields) < len(header):
            raise InputError(
                f"heading CSV row has {len(fields)} fields, the header {len(header)} "
                f"({', '.join(header)})",
                path,
                number,
            )
        values = dict(zip(columns, (fields[i].strip() for i in index), strict=True))
        rows.append(_minimal_row(values, names[0], rows[-1][0] if rows else None, path, number))
    if not rows:
        raise InputError("heading CSV has its header but no rows", path)
    t, degrees, sigma_deg, valid = (np.array(c) for c in zip(*rows, strict=True))
    n = len(t)
    yaw = np.where(valid, course_to_yaw(np.radians(np.where(valid, degrees, 0.0))), np.nan)
    sigma = np.where(valid, np.radians(sigma_deg), np.nan)
    return HeadingTable(
        t=t,
        yaw_tc=np.full(n, np.nan),
        sigma_tc=np.full(n, np.nan),
        tc_reliable=np.zeros(n, dtype=bool),
        n_obs_window=np.zeros(n, dtype=int),
        n_sat_epoch=np.zeros(n, dtype=int),
        yaw_conv=yaw,
        conv_valid=valid.copy(),
        gyro_bias=np.full(n, np.nan),
        wheel_scale=np.full(n, np.nan),
        sigma_conv=sigma,
        conv_gnss_valid=valid.copy(),
        sigma_conv_gnss=sigma.copy(),
    )


def _minimal_row(
    values: dict[str, str], heading: str, previous_t: float | None, path: Path, number: int
) -> tuple[float, float, float, bool]:
    """(time, heading in degrees, σ in degrees, valid) of one row of a minimal heading CSV."""

    def number_of(column: str, text: str) -> float:
        try:
            return float(text) if text else math.nan
        except ValueError:
            raise InputError(
                f"{column} {text!r} is not a number (expected {MINIMAL_FORMAT})", path, number
            ) from None

    t = number_of("gps_time_s", values["gps_time_s"])
    if not math.isfinite(t):
        raise InputError(f"gps_time_s {values['gps_time_s']!r} is not a time", path, number)
    if previous_t is not None and t <= previous_t:
        raise InputError(f"gps_time_s {t} is not after the previous row's", path, number)
    degrees = number_of(heading, values[heading])
    sigma = number_of("sigma_deg", values["sigma_deg"])
    flag = values.get("valid", "1")
    if flag not in ("0", "1"):
        raise InputError(f"valid {flag!r} is not 0 or 1 (expected {MINIMAL_FORMAT})", path, number)
    valid = flag == "1" and not math.isnan(degrees)
    if math.isinf(degrees) or abs(degrees) > MAX_HEADING_DEG:
        raise InputError(
            f"{heading} {values[heading]!r} is not a direction in degrees (|value| <= "
            f"{MAX_HEADING_DEG:g}; expected {MINIMAL_FORMAT})",
            path,
            number,
        )
    if valid and not 0.0 < sigma <= MAX_SIGMA_DEG:
        raise InputError(
            f"sigma_deg {values['sigma_deg']!r} of a valid heading is not a standard deviation "
            f"in degrees (0 < sigma_deg <= {MAX_SIGMA_DEG:g}; expected {MINIMAL_FORMAT})",
            path,
            number,
        )
    return t, degrees, sigma, valid
