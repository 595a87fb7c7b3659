"""``doppler_sigma.csv``: receiver-reported σ of Doppler range rates, one row per
(epoch, satellite, Doppler code): ``gps_time_s,sat,code,sigma_mps`` (``gnss.doppler_sigma`` of a
sequence folder)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.model.doppler_sigma import ReportedSigma

HEADER = ("gps_time_s", "sat", "code", "sigma_mps")


def write_doppler_sigma(path: str | Path, sigma: ReportedSigma) -> None:
    with Path(path).open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(HEADER)
        for row in zip(sigma.t, sigma.sat_id, sigma.code, sigma.sigma_mps, strict=True):
            writer.writerow((f"{row[0]:.3f}", row[1], row[2], f"{row[3]:.6g}"))


def read_doppler_sigma(path: str | Path) -> ReportedSigma:
    """The table; a malformed row or a σ that is not positive is an error naming its line."""
    path = Path(path)
    try:
        lines = path.read_text().splitlines()
    except OSError as exc:
        raise InputError(f"cannot read Doppler sigma file: {exc}", path) from exc
    if not lines or tuple(lines[0].split(",")) != HEADER:
        raise InputError(f"header must be {','.join(HEADER)}", path, 1)
    t, sat, code, sigma = [], [], [], []
    for number, line in enumerate(lines[1:], start=2):
        fields = line.split(",")
        try:
            value = float(fields[3])
            t.append(float(fields[0]))
        except (ValueError, IndexError):
            raise InputError(f"bad row {line!r}", path, number) from None
        if not value > 0.0 or len(fields) != 4:
            raise InputError(f"bad row {line!r} (σ must be a positive number)", path, number)
        sat.append(fields[1])
        code.append(fields[2])
        sigma.append(value)
    return ReportedSigma(
        np.array(t), np.array(sat, dtype="U3"), np.array(code, dtype="U3"), np.array(sigma)
    )
