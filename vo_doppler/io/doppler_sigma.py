"""``doppler_sigma.csv``: receiver-reported σ of Doppler range rates, one row per
(epoch, satellite, Doppler code): ``gps_time_s,sat,code,sigma_mps`` (``gnss.doppler_sigma`` of a
sequence folder)."""

from __future__ import annotations

import csv
import re
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.io.rinex_common import PRN_RANGE, prn_in_range
from vo_doppler.model.doppler_sigma import TIME_RESOLUTION_S, ReportedSigma
from vo_doppler.model.gpstime import SECONDS_PER_WEEK

HEADER = ("gps_time_s", "sat", "code", "sigma_mps")
LAST_GPS_SECOND = 4096 * SECONDS_PER_WEEK
"""GPS time stays below week 4096 (a 12-bit week number) in every file the project reads."""
_SATELLITE = re.compile(r"[A-Z]\d\d")
_DOPPLER_CODE = re.compile(r"D\d[A-Z]?")


def write_doppler_sigma(path: str | Path, sigma: ReportedSigma) -> None:
    with Path(path).open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(HEADER)
        for row in zip(sigma.t, sigma.sat_id, sigma.code, sigma.sigma_mps, strict=True):
            writer.writerow((f"{row[0]:.3f}", row[1], row[2], f"{row[3]:.6g}"))


def read_doppler_sigma(path: str | Path) -> ReportedSigma:
    """The table. A malformed row, a time that is not a GPS time, a satellite that does not
    exist, a code that is not a Doppler code, a σ that is not a finite positive number or a
    repeated (epoch, satellite, code) is an error naming its line."""
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise InputError(f"cannot read Doppler sigma file: {exc}", path) from exc
    if not lines or tuple(lines[0].split(",")) != HEADER:
        raise InputError(f"header must be {','.join(HEADER)}", path, 1)
    t, sat, code, sigma = [], [], [], []
    first_line: dict[tuple[int, str, str], int] = {}
    for number, line in enumerate(lines[1:], start=2):
        row = _parse_row(line)
        if isinstance(row, str):
            raise InputError(f"{row} in row {line[:80]!r}", path, number)
        key = (round(row[0] / TIME_RESOLUTION_S), row[1], row[2])
        if key in first_line:
            raise InputError(
                f"repeats the epoch, satellite and code of line {first_line[key]}", path, number
            )
        first_line[key] = number
        for column, value in zip((t, sat, code, sigma), row, strict=True):
            column.append(value)
    return ReportedSigma(
        np.array(t, dtype=float),
        np.array(sat, dtype="U3"),
        np.array(code, dtype="U3"),
        np.array(sigma, dtype=float),
    )


def _parse_row(line: str) -> tuple[float, str, str, float] | str:
    """The row's values, or what is wrong with it."""
    fields = line.split(",")
    if len(fields) != len(HEADER):
        return f"{len(fields)} fields, not {len(HEADER)}"
    try:
        t, sigma = float(fields[0]), float(fields[3])
    except ValueError:
        return "a time or σ that is not a number"
    sat, code = fields[1], fields[2]
    if not 0.0 <= t < LAST_GPS_SECOND:
        return f"time {t:g} s is not a GPS time (weeks 0–4095)"
    if not (
        _SATELLITE.fullmatch(sat) and sat[0] in PRN_RANGE and prn_in_range(sat[0], int(sat[1:]))
    ):
        return f"no satellite {sat[:8]!r}"
    if not _DOPPLER_CODE.fullmatch(code):
        return f"{code[:8]!r} is not a RINEX Doppler code"
    if not (np.isfinite(sigma) and sigma > 0.0):
        return f"σ {sigma:g} m/s is not a finite positive number"
    return t, sat, code, sigma
