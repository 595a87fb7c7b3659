"""Plain sensor CSV files: ``t,yaw_rate_rad_s`` (counter-clockwise positive) and ``t,speed_mps``.

One header row naming the two columns, then one sample per row; ``#`` comments and blank lines
are allowed. Times are seconds on the sensor's clock; a per-sensor offset maps them to GPS time.
"""

from __future__ import annotations

import csv
import logging
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.model.series import SensorSeries

log = logging.getLogger(__name__)

YAW_RATE_COLUMN = "yaw_rate_rad_s"
SPEED_COLUMN = "speed_mps"


def read_sensor_csv(path: str | Path, column: str, time_offset_s: float = 0.0) -> SensorSeries:
    """Read a two-column sensor CSV whose header is ``t,<column>``.

    Rows with a non-numeric or non-finite field are skipped, counted and logged; rows out of
    time order raise :class:`InputError` naming the line.
    """
    path = Path(path)
    try:
        text = path.read_text()
    except OSError as exc:
        raise InputError(f"cannot read sensor CSV: {exc.strerror or exc}", path) from exc
    lines = [
        (number, line)
        for number, line in enumerate(text.splitlines(), start=1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not lines:
        raise InputError("sensor CSV has no header row", path)
    _, header = lines[0]
    names = [name.strip() for name in next(csv.reader([header]))]
    if "t" not in names or column not in names:
        raise InputError(f"header must name columns 't' and '{column}', found {names}", path, 1)
    i_t, i_v = names.index("t"), names.index(column)
    times: list[float] = []
    values: list[float] = []
    skipped = 0
    for number, line in lines[1:]:
        fields = next(csv.reader([line]))
        try:
            t_value, v_value = float(fields[i_t]), float(fields[i_v])
        except (ValueError, IndexError):
            t_value, v_value = np.nan, np.nan
        if not (np.isfinite(t_value) and np.isfinite(v_value)):
            skipped += 1
            log.warning("%s:%d: unusable sensor row skipped", path, number)
            continue
        if times and t_value < times[-1]:
            raise InputError("time goes backwards", path, number)
        times.append(t_value)
        values.append(v_value)
    if skipped:
        log.warning("%s: %d of %d rows skipped", path, skipped, len(lines) - 1)
    unit = "rad/s" if column == YAW_RATE_COLUMN else "m/s" if column == SPEED_COLUMN else ""
    return SensorSeries(np.array(times) + time_offset_s, np.array(values), column, unit)


def read_yaw_rate_csv(path: str | Path, time_offset_s: float = 0.0) -> SensorSeries:
    """``t,yaw_rate_rad_s`` — yaw rate counter-clockwise positive (turning left), rad/s."""
    return read_sensor_csv(path, YAW_RATE_COLUMN, time_offset_s)


def read_speed_csv(path: str | Path, time_offset_s: float = 0.0) -> SensorSeries:
    """``t,speed_mps`` — vehicle speed, m/s."""
    return read_sensor_csv(path, SPEED_COLUMN, time_offset_s)


def write_sensor_csv(path: str | Path, series: SensorSeries, column: str) -> None:
    """Write ``t,<column>`` with full double precision."""
    data = np.column_stack([series.t, series.value])
    np.savetxt(path, data, fmt="%.9f", delimiter=",", header=f"t,{column}", comments="")
