"""Messages for sensor times that do not overlap the GNSS epochs: the two spans in plain
numbers and a guess at the cause with the option that fixes it; and the check of a join of two
clocks (:func:`time_base_check`): how much of one the other covers, and times that are frame
numbers rather than seconds."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.model.gpstime import GPS_MINUS_UTC_LATEST_S, UNIX_TIME_AT_GPS_EPOCH_S

UNIX_OFFSET_S = GPS_MINUS_UTC_LATEST_S - UNIX_TIME_AT_GPS_EPOCH_S
"""GPS time − Unix time today, the offset that puts a Unix-time log on GPS time."""


def span(t) -> str:
    """``first..last s`` of a time array (plain numbers, no numpy brackets)."""
    if len(t) == 0:
        return "no samples"
    return f"{float(t[0]):.3f}..{float(t[-1]):.3f} s"


def offset_hint(sensor_t0: float, gnss_t0: float, option: str) -> str:
    """What ``option`` (e.g. ``--time-offset-can``) should probably be, from the first times."""
    gap = gnss_t0 - sensor_t0
    if abs(gap - UNIX_OFFSET_S) < 3600.0:
        return (
            f"the sensor times look like Unix time: pass {option} {UNIX_OFFSET_S:.0f} "
            f"(GPS - Unix = {-UNIX_TIME_AT_GPS_EPOCH_S:.0f} s "
            f"+ {GPS_MINUS_UTC_LATEST_S:.0f} leap seconds)"
        )
    if abs(sensor_t0) < 1.0e5:
        return (
            "the sensor times look like seconds since the start of the log: pass "
            f"{option} with the GPS time of that start (about {gap:.0f} if both start together)"
        )
    return (
        f"pass {option} with GPS time minus sensor time (about {gap:.0f} s if they start together)"
    )


def epochs_offset_fix(t: np.ndarray, epochs: np.ndarray) -> str:
    """What fixes a file of epochs (``run --heading FILE``) not on the GPS time of the times
    ``t`` it is joined with: the offset to add to its times, from the first of each."""
    gap = float(t[0]) - float(epochs[0]) if len(t) and len(epochs) else 0.0
    return (
        "the file's times must be GPS seconds, as the recording's are: add the GPS time of its "
        f"first row to each (about {gap:.0f} s if it starts with the recording)"
    )


FRAME_NUMBER_FIX = (
    "pass --times with the images' times.txt (a KITTI poses file has no times; then "
    "--time-offset to GPS time)"
)
"""What fixes a KITTI trajectory read without its times (``correct``, ``eval``)."""

FRAME_STEP_TOLERANCE_S = 1e-6
"""Steps within this of 1 s are "exactly 1 s" (the rounding of a time near 10⁹ s is 1.2·10⁻⁷ s)."""


def looks_like_frame_numbers(t: np.ndarray) -> bool:
    """Whether times step by exactly 1 s (at least three of them): frame numbers 0, 1, 2, …
    (shifted perhaps by an offset), which a reader gives a file without times. No car camera
    runs at 1 Hz, so seconds spaced so are not a camera's. Judged on the steps alone: the
    same whatever the time origin."""
    t = np.asarray(t, dtype=float)
    return bool(len(t) > 2 and np.all(np.abs(np.diff(t) - 1.0) <= FRAME_STEP_TOLERANCE_S))


def coverage(t: np.ndarray, epochs: np.ndarray) -> float:
    """Share of the span of ``t`` inside the span of ``epochs`` (0 when they do not meet or
    either is empty; for a single time, 1 when it lies inside)."""
    if not overlaps(t, epochs):
        return 0.0
    length = float(t[-1] - t[0])
    inside = min(float(t[-1]), float(epochs[-1])) - max(float(t[0]), float(epochs[0]))
    return 1.0 if length <= 0 else min(1.0, max(inside, 0.0) / length)


MIN_COVERAGE = 0.05
"""Epochs covering less than this share of the times they are joined with: the clocks differ
(an error). Frame numbers 0..800 joined with headings on image time (0..80 s) are covered to
10 %; no one corrects a drive by the headings of its first twentieth."""
LOW_COVERAGE = 0.5
"""Below this share the join is plausible (GNSS lost for part of a drive) but doubtful: a
warning naming the option that sets the clock."""
FRAME_NUMBER_COVERAGE = 0.9
"""Frame numbers covered less than this by the epochs are an error: only epochs on the same
frame clock (covering it all) could join them."""


@dataclass(frozen=True)
class TimeBase:
    """The verdict of :func:`time_base_check`: an error (raise it, exit 1), a warning (log it
    and report it), or neither, with the share of the times the epochs cover."""

    coverage: float
    error: str | None = None
    warning: str | None = None


def time_base_check(
    t: np.ndarray,
    epochs: np.ndarray,
    what: str,
    epochs_what: str,
    offset_option: str,
    frame_fix: str = FRAME_NUMBER_FIX,
    offset_fix: str | None = None,
) -> TimeBase:
    """Check a join of two clocks: ``t`` (``what``'s times, after any offset) with ``epochs``
    (``epochs_what``'s, GPS time), each increasing.

    An error when the spans do not meet, when the epochs cover less than
    :data:`MIN_COVERAGE` of the times, or when the times are frame numbers
    (:func:`looks_like_frame_numbers`) covered less than :data:`FRAME_NUMBER_COVERAGE`; a
    warning when the epochs cover less than :data:`LOW_COVERAGE`, or when frame numbers are
    covered (plausible only with epochs on a frame clock too). Each message gives both spans,
    the cause guessed and the option that fixes it: ``frame_fix`` for frame numbers, else
    ``offset_fix`` when given (the epochs are on the wrong clock, e.g.
    :func:`epochs_offset_fix`), else ``offset_option`` with the likely offset
    (:func:`offset_hint`)."""
    t = np.asarray(t, dtype=float)
    epochs = np.asarray(epochs, dtype=float)
    share = coverage(t, epochs)
    spans = f"the {what} times ({span(t)}) and the {epochs_what} ({span(epochs)}, GPS time)"
    frames = looks_like_frame_numbers(t)
    frame_cause = f"the {what} times step by exactly 1 s: they are frame numbers, not seconds"
    if frames and share < FRAME_NUMBER_COVERAGE:
        meet = f"meet over {share:.0%} of the {what}" if share > 0 else "do not overlap"
        return TimeBase(share, error=f"{spans} {meet}: {frame_cause}; {frame_fix}")
    offset = offset_fix or (
        offset_hint(float(t[0]), float(epochs[0]), offset_option) if len(t) and len(epochs) else ""
    )
    if share <= 0:
        return TimeBase(share, error=f"{spans} do not overlap" + (f"; {offset}" if offset else ""))
    if share < MIN_COVERAGE:
        return TimeBase(
            share,
            error=f"{spans} meet over {share:.1%} of the {what} only: the two clocks differ; "
            f"{offset}",
        )
    if share < LOW_COVERAGE:
        return TimeBase(
            share,
            warning=f"{spans} meet over {share:.0%} of the {what} only: the rest is joined with "
            f"no {epochs_what}; if the two clocks differ, {offset}",
        )
    if frames:
        return TimeBase(
            share,
            warning=f"the {what} times step by exactly 1 s, as frame numbers do: they were "
            f"joined with the {epochs_what} as they are, right only if those count frames too; "
            f"otherwise {frame_fix}",
        )
    return TimeBase(share)


def overlaps(t: np.ndarray, epochs: np.ndarray) -> bool:
    """Whether the span of ``t`` meets the span of ``epochs``."""
    return bool(len(t) and len(epochs) and t[-1] >= epochs[0] and t[0] <= epochs[-1])


def overlap_error(what: str, t: np.ndarray, epochs: np.ndarray, option: str, path=None):
    """The project's error for ``what``'s times (``t``, GPS s after the offsets) missing the
    GNSS epochs, with the likely offset (see :func:`offset_hint`)."""
    hint = offset_hint(float(t[0]), float(epochs[0]), option) if len(t) and len(epochs) else ""
    return InputError(
        f"the {what} times ({span(t)}) do not overlap the GNSS epochs ({span(epochs)}, GPS "
        f"time)" + (f"; {hint}" if hint else ""),
        path,
    )
