"""Time order of a sensor's samples: the stated policy per sensor, and the counts it leaves.

Policies (every reader applies one; the counts go into ``vo-doppler run``'s summary):

* ``"error"`` — camera times, yaw-rate/speed/gyro/GPS CSVs, NMEA, TUM, heading tables: a sample
  earlier than the one before is an :class:`InputError` naming its line (a clock jump or a
  pasted block cannot be repaired by guessing).
* ``"sort"`` — CAN frames: buses read by several channels interleave, so frames late by at most
  ``max_back_s`` are sorted into place and counted; a frame later than that (e.g. a block of
  frames 5 s early) is an error naming it.

Under both, a sample at the same time as the one before with identical values is a duplicate,
dropped and counted (its line kept for the reader's warning). One with different values is,
under ``"error"``, an :class:`InputError` naming both lines (which of two values is the
measurement cannot be told); under ``"sort"`` the first is kept, counted as conflicting and
logged (a frame read by two channels). Non-finite times are an error.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError

log = logging.getLogger(__name__)

CAN_MAX_BACK_S = 0.5
"""Largest step back in time a CAN frame may take and still be sorted into place (s)."""


@dataclass
class TimeOrderReport:
    """What one sensor's time order needed: samples sorted, duplicates dropped."""

    sensor: str
    n_samples: int = 0
    n_out_of_order: int = 0
    n_duplicates: int = 0
    n_conflicting_duplicates: int = 0
    duplicate_lines: list[int] = field(default_factory=list)
    """Lines of the identical duplicates dropped (when the reader gave lines)."""

    def as_dict(self) -> dict[str, int]:
        return {
            "samples": self.n_samples,
            "out_of_order": self.n_out_of_order,
            "duplicates": self.n_duplicates,
            "conflicting_duplicates": self.n_conflicting_duplicates,
        }

    def problems(self) -> list[str]:
        """Sentences for the warnings of a run (empty when the order was clean)."""
        out = []
        if self.n_out_of_order:
            out.append(f"{self.sensor}: {self.n_out_of_order} samples out of time order, sorted")
        if self.n_conflicting_duplicates:
            out.append(
                f"{self.sensor}: {self.n_conflicting_duplicates} duplicate timestamps with "
                "different values (first kept)"
            )
        return out


def _line(lines: np.ndarray | None, index: int) -> int | None:
    return None if lines is None else int(lines[index])


def _values(row) -> str:
    """A sample's values for a message: one number, or a comma-separated row."""
    return ", ".join(f"{value:.10g}" for value in np.atleast_1d(row))


def order_samples(
    t: np.ndarray,
    values: np.ndarray,
    path: str | Path | None,
    sensor: str,
    lines: np.ndarray | None = None,
    policy: str = "error",
    max_back_s: float = CAN_MAX_BACK_S,
) -> tuple[np.ndarray, np.ndarray, TimeOrderReport]:
    """``t`` and ``values`` (rows aligned with ``t``) in time order without duplicate times,
    under ``policy`` (module docstring); ``lines`` are the samples' line numbers for messages."""
    if policy not in ("error", "sort"):
        raise ValueError(f"policy must be 'error' or 'sort', not {policy!r}")
    t = np.asarray(t, dtype=float)
    values = np.asarray(values)
    report = TimeOrderReport(sensor, len(t))
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise InputError(f"{sensor} time is {t[bad[0]]}", path, _line(lines, int(bad[0])))
    if len(t) > 1:
        latest = np.maximum.accumulate(t)
        late_by = np.concatenate([[0.0], latest[:-1] - t[1:]])
        late = np.flatnonzero(late_by > 0)
        if late.size:
            worst = late[np.argmax(late_by[late])] if policy == "sort" else late[0]
            if policy == "error" or late_by[worst] > max_back_s:
                raise InputError(
                    f"time goes backwards by {late_by[worst]:.6g} s in the {sensor} (to "
                    f"{t[worst]:.6f} s)",
                    path,
                    _line(lines, worst),
                )
            order = np.argsort(t, kind="stable")
            t, values = t[order], values[order]
            lines = None if lines is None else np.asarray(lines)[order]
            report.n_out_of_order = int(late.size)
        repeated = np.flatnonzero(np.diff(t) == 0) + 1
        if repeated.size:
            same = values[repeated] == values[repeated - 1]
            same = same.reshape(len(repeated), -1).all(axis=1)
            if policy == "error" and not same.all():
                first = repeated[~same][0]
                which = "two" if lines is None else f"lines {lines[first - 1]} and {lines[first]}"
                shown = [_values(values[k]) for k in (first - 1, first)]
                if lines is not None:
                    shown = [f"line {lines[k]}: {_values(values[k])}" for k in (first - 1, first)]
                raise InputError(
                    f"{which} of the {sensor} are both at t = {t[first]:.6f} s with different "
                    f"values ({'; '.join(shown)}): which is the measurement cannot be told; keep "
                    "one of them",
                    path,
                    _line(lines, int(first)),
                )
            report.n_duplicates = int(same.sum())
            if lines is not None:
                report.duplicate_lines = [int(lines[k]) for k in repeated[same]]
            report.n_conflicting_duplicates = int((~same).sum())
            if report.n_conflicting_duplicates:
                first = repeated[~same][0]
                log.warning(
                    "%s: %s has %d duplicate timestamps with different values (first at "
                    "t = %.6f s%s); the first sample of each is kept",
                    path,
                    sensor,
                    report.n_conflicting_duplicates,
                    t[first],
                    "" if lines is None else f", line {lines[first]}",
                )
            keep = np.ones(len(t), dtype=bool)
            keep[repeated] = False
            t, values = t[keep], values[keep]
    if report.n_out_of_order:
        log.warning("%s: %s", path, report.problems()[0])
    return t, values, report
