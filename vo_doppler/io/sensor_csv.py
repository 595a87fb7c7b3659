"""Headed numeric CSV files, and the sensor CSVs built on them: ``t,yaw_rate_rad_s``
(counter-clockwise positive) and ``t,speed_mps`` (any ``t,<column>`` signal).

One header row naming the columns, then one sample per row; ``#`` comments and blank lines are
allowed. Rows that cannot be read or hold non-finite numbers are skipped, counted and logged; a
file without a single usable row is an error. A column that holds a vehicle signal
(``speed_mps``, ``yaw_rate_rad_s``, ``forward_acceleration_mps2``, in whichever file it
appears) is checked against what a car can report (:mod:`vo_doppler.bounds`):
isolated rows beyond it are skipped, counted and logged like non-finite ones; more than 1 % of
the rows beyond it is an error naming the first such line (the column's unit or scale is
wrong). A file with a ``t`` column follows the ``"error"`` time-order policy of
:mod:`vo_doppler.io.time_order`: a row going back raises naming its line; a row repeating the
one before exactly is dropped, counted and warned with its line; two rows at one time with
different values raise naming both lines. Times are seconds on the sensor's clock, and a
per-sensor offset maps them to GPS time. Files are read through
:mod:`vo_doppler.io.textfile` (bounded, UTF-8, no binary).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vo_doppler.bounds import (
    FORWARD_ACCELERATION,
    SPEED,
    YAW_RATE,
    SignalBounds,
    too_many_out_of_range,
)
from vo_doppler.errors import InputError
from vo_doppler.io.textfile import read_text
from vo_doppler.io.time_order import TimeOrderReport, order_samples
from vo_doppler.model.series import SensorSeries

log = logging.getLogger(__name__)


@dataclass
class CsvReadReport:
    """Rows read and skipped in one CSV file (line numbers are 1-based)."""

    path: Path
    n_rows: int = 0
    n_malformed: int = 0
    n_non_finite: int = 0
    n_out_of_range: int = 0
    """Rows with a vehicle signal beyond what a car can report (isolated: skipped)."""
    first_out_of_range: str = ""
    """The first out-of-range value and its bounds, for the warning."""
    skipped_lines: list[int] = field(default_factory=list)
    row_lines: list[int] = field(default_factory=list)
    """Line of every row read, in order."""
    time_order: TimeOrderReport | None = None

    @property
    def n_skipped(self) -> int:
        return self.n_malformed + self.n_non_finite + self.n_out_of_range

    def problems(self) -> list[str]:
        """Sentences for the warnings of a run: the rows skipped, the duplicate rows dropped
        (empty when every row was used)."""
        found = []
        if self.n_skipped:
            found.append(
                f"{self.path}: skipped {self.n_malformed} malformed, {self.n_non_finite} "
                f"non-finite and {self.n_out_of_range} out-of-range rows"
                f"{self.first_out_of_range} (first lines: "
                f"{', '.join(map(str, self.skipped_lines[:5]))})"
            )
        duplicates = [] if self.time_order is None else self.time_order.duplicate_lines
        if duplicates:
            more = f" and {len(duplicates) - 10} more" if len(duplicates) > 10 else ""
            found.append(
                f"{self.path}: dropped {len(duplicates)} rows repeating the row before exactly "
                f"(lines {', '.join(map(str, duplicates[:10]))}{more})"
            )
        return found

    def log_summary(self) -> None:
        for problem in self.problems():
            log.warning("%s", problem)


def read_numeric_csv(
    path: str | Path, required: tuple[str, ...], optional: tuple[str, ...] = ()
) -> tuple[dict[str, np.ndarray], CsvReadReport]:
    """Columns of a headed numeric CSV by name; bad rows skipped and counted; rows in time order
    when the file has a ``t`` column."""
    path = Path(path)
    lines = read_text(path, "CSV file").splitlines()
    report = CsvReadReport(path)
    header: list[str] | None = None
    index: dict[str, int] = {}
    rows: list[list[float]] = []
    bounds = COLUMN_BOUNDS
    bounded: list[tuple[int, str]] = []
    out_of_range: list[tuple[int, str, float]] = []
    for number, line in enumerate(lines, start=1):
        stripped = line.strip()
        if not stripped or stripped.startswith("#"):
            continue
        fields = [f.strip() for f in stripped.split(",")]
        if header is None:
            header = [f.lower() for f in fields]
            missing = [name for name in required if name not in header]
            if missing:
                raise InputError(
                    f"CSV header {','.join(fields)!r} lacks column(s) {', '.join(missing)}; "
                    f"expected {','.join(required)}",
                    path,
                    number,
                )
            index = {name: header.index(name) for name in (*required, *optional) if name in header}
            bounded = [(j, name) for j, name in enumerate(index) if name in bounds]
            continue
        try:
            if len(fields) != len(header):
                raise ValueError(f"{len(fields)} fields, header has {len(header)}")
            values = [float(fields[i]) for i in index.values()]
        except ValueError:
            report.n_malformed += 1
            report.skipped_lines.append(number)
            continue
        if not np.all(np.isfinite(values)):
            report.n_non_finite += 1
            report.skipped_lines.append(number)
            continue
        beyond = [(name, values[j]) for j, name in bounded if bounds[name].outside(values[j])]
        if beyond:
            if not out_of_range:
                name, value = beyond[0]
                report.first_out_of_range = f" ({name} {value:g} beyond {bounds[name]})"
            out_of_range.append((number, *beyond[0]))
            report.n_out_of_range += 1
            report.skipped_lines.append(number)
            continue
        rows.append(values)
        report.row_lines.append(number)
    if header is None:
        raise InputError("CSV file is empty", path)
    if too_many_out_of_range(len(out_of_range), len(rows) + len(out_of_range)):
        line, name, value = out_of_range[0]
        raise InputError(
            f"{name} = {value:g} is outside what a vehicle can report, {bounds[name]}, and so "
            f"are {len(out_of_range)} of the {len(rows) + len(out_of_range)} rows: not isolated "
            "bad rows; check the column's unit",
            path,
            line,
        )
    if not rows:
        raise InputError("CSV file has no usable data rows", path)
    data = np.asarray(rows, dtype=float)
    if "t" in index:
        j = list(index).index("t")
        _, data, report.time_order = order_samples(
            data[:, j], data, path, f"{path.name} rows", np.asarray(report.row_lines)
        )
    report.n_rows = len(data)
    report.log_summary()
    return {name: data[:, j] for j, name in enumerate(index)}, report


def read_sensor_csv(path: str | Path, column: str, time_offset_s: float = 0.0) -> SensorSeries:
    """The ``t,<column>`` signal of a headed CSV, ``time_offset_s`` added to its times."""
    return read_sensor_csv_with_report(path, column, time_offset_s)[0]


def read_sensor_csv_with_report(
    path: str | Path, column: str, time_offset_s: float = 0.0
) -> tuple[SensorSeries, CsvReadReport]:
    """:func:`read_sensor_csv` and what reading skipped (for the warnings of a run)."""
    columns, report = read_numeric_csv(path, ("t", column))
    unit = COLUMN_BOUNDS[column].unit if column in COLUMN_BOUNDS else ""
    series = SensorSeries(
        columns["t"] + time_offset_s, columns[column], column, unit, report.n_skipped
    )
    return series, report


YAW_RATE_COLUMN = "yaw_rate_rad_s"
SPEED_COLUMN = "speed_mps"
FORWARD_ACCELERATION_COLUMN = "forward_acceleration_mps2"
"""Specific force along the vehicle's forward axis (an accelerometer's reading), m/s²."""
COLUMN_BOUNDS: dict[str, SignalBounds] = {
    SPEED_COLUMN: SPEED,
    YAW_RATE_COLUMN: YAW_RATE,
    FORWARD_ACCELERATION_COLUMN: FORWARD_ACCELERATION,
}
"""The columns checked against what a vehicle can report, wherever they appear."""


def read_yaw_rate_csv(path: str | Path, time_offset_s: float = 0.0) -> SensorSeries:
    """``t,yaw_rate_rad_s`` — yaw rate counter-clockwise positive (turning left), rad/s."""
    return read_sensor_csv(path, YAW_RATE_COLUMN, time_offset_s)


def read_speed_csv(path: str | Path, time_offset_s: float = 0.0) -> SensorSeries:
    """``t,speed_mps`` — vehicle speed, m/s."""
    return read_sensor_csv(path, SPEED_COLUMN, time_offset_s)


def write_sensor_csv(path: str | Path, series: SensorSeries, column: str) -> None:
    """Write ``t,<column>`` with full double precision (what :func:`read_sensor_csv` reads)."""
    data = np.column_stack([series.t, series.value])
    np.savetxt(path, data, fmt="%.17g", delimiter=",", header=f"t,{column}", comments="")
