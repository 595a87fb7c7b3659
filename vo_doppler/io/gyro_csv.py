"""Yaw-rate CSV files: a header ``t,yaw_rate_rad_s`` then one sample per line.

``t`` in seconds (the clock shared with the GPS fixes), yaw rate in rad/s counter-clockwise
positive (DESIGN.md). Lines starting with ``#`` and blank lines are ignored. Rows that cannot
be read or hold non-finite numbers are skipped with a warning and counted; a file without a
single usable row is an error.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError

log = logging.getLogger(__name__)

GYRO_COLUMNS = ("t", "yaw_rate_rad_s")


@dataclass
class CsvReadReport:
    """Rows read and skipped in one CSV file (line numbers are 1-based)."""

    path: Path
    n_rows: int = 0
    n_malformed: int = 0
    n_non_finite: int = 0
    skipped_lines: list[int] = field(default_factory=list)

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
    """Columns of a headed numeric CSV by name; bad rows skipped and counted."""
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read CSV: {exc}", path) from exc
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
    if header is None:
        raise InputError("CSV file is empty", path)
    if not rows:
        raise InputError("CSV file has no usable data rows", path)
    report.n_rows = len(rows)
    report.log_summary()
    data = np.asarray(rows, dtype=float)
    return {name: data[:, j] for j, name in enumerate(index)}, report


@dataclass(frozen=True)
class GyroSeries:
    """Yaw-rate samples (t s, rate rad/s CCW) and how the file read."""

    t: np.ndarray
    yaw_rate: np.ndarray
    report: CsvReadReport

    def as_tuple(self) -> tuple[np.ndarray, np.ndarray]:
        return self.t, self.yaw_rate


def read_gyro_csv(path: str | Path) -> GyroSeries:
    """Read a ``t,yaw_rate_rad_s`` CSV file."""
    columns, report = read_numeric_csv(path, GYRO_COLUMNS)
    return GyroSeries(columns["t"], columns["yaw_rate_rad_s"], report)


def write_gyro_csv(path: str | Path, t: np.ndarray, yaw_rate: np.ndarray) -> None:
    """Write a ``t,yaw_rate_rad_s`` CSV file with full precision."""
    data = np.column_stack([np.asarray(t, dtype=float), np.asarray(yaw_rate, dtype=float)])
    np.savetxt(path, data, delimiter=",", fmt="%.17g", header=",".join(GYRO_COLUMNS), comments="")
