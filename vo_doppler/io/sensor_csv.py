"""Headed numeric CSV files, and the sensor CSVs built on them: ``t,yaw_rate_rad_s``
(counter-clockwise positive) and ``t,speed_mps`` (any ``t,<column>`` signal).

One header row naming the columns, then one sample per row; ``#`` comments and blank lines are
allowed. Rows that cannot be read or hold non-finite numbers are skipped, counted and logged; a
file without a single usable row is an error. A file with a ``t`` column follows the ``"error"``
time-order policy of :mod:`vo_doppler.io.time_order` (a row going back raises naming its line;
duplicate times are dropped and counted). Times are seconds on the sensor's clock, and a
per-sensor offset maps them to GPS time. Files are read through :mod:`vo_doppler.io.textfile`
(bounded, UTF-8, no binary).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

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
    skipped_lines: list[int] = field(default_factory=list)
    row_lines: list[int] = field(default_factory=list)
    """Line of every row read, in order."""
    time_order: TimeOrderReport | None = None

    def log_summary(self) -> None:
        if self.n_malformed or self.n_non_finite:
            log.warning(
                "%s: skipped %d malformed and %d non-finite rows (first lines: %s)",
                self.path,
                self.n_malformed,
                self.n_non_finite,
                self.skipped_lines[:5],
            )


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
        rows.append(values)
        report.row_lines.append(number)
    if header is None:
        raise InputError("CSV file is empty", path)
    if not rows:
        raise InputError("CSV file has no usable data rows", path)
    report.n_rows = len(rows)
    report.log_summary()
    data = np.asarray(rows, dtype=float)
    if "t" in index:
        j = list(index).index("t")
        _, data, report.time_order = order_samples(
            data[:, j], data, path, f"{path.name} samples", np.asarray(report.row_lines)
        )
    return {name: data[:, j] for j, name in enumerate(index)}, report


def read_sensor_csv(path: str | Path, column: str, time_offset_s: float = 0.0) -> SensorSeries:
    """The ``t,<column>`` signal of a headed CSV, ``time_offset_s`` added to its times."""
    columns, report = read_numeric_csv(path, ("t", column))
    unit = {YAW_RATE_COLUMN: "rad/s", SPEED_COLUMN: "m/s", FORWARD_ACCELERATION_COLUMN: "m/s²"}
    unit = unit.get(column, "")
    skipped = report.n_malformed + report.n_non_finite
    return SensorSeries(columns["t"] + time_offset_s, columns[column], column, unit, skipped)


YAW_RATE_COLUMN = "yaw_rate_rad_s"
SPEED_COLUMN = "speed_mps"
FORWARD_ACCELERATION_COLUMN = "forward_acceleration_mps2"
"""Specific force along the vehicle's forward axis (an accelerometer's reading), m/s²."""


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
