"""Part of a recording: the ``--start`` / ``--end`` of ``run``, ``heading``, ``gnss`` and ``vo``.

A bound is either seconds from the recording's first epoch (``30``, ``12.5``) or a GPS time
written ``gps:T`` (``gps:1425953430.5``, seconds since 1980-01-06 on the GPS time scale; for
``vo`` the time base of the image times). Both bounds are inclusive. The span is applied in one
place: :meth:`TimeSpan.resolve` turns it into GPS times against the recording's reference times
(its first and last GNSS epoch, or image), refusing a span that is empty or leaves the
recording (:class:`~vo_doppler.errors.UsageError`, exit 2); the ``trim_*`` functions keep the
samples of each input inside it, so that a result on a span is the result on the recording cut
to it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from vo_doppler.errors import InputError, UsageError
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.observations import Observations
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory

GPS_PREFIX = "gps:"
SPAN_SYNTAX = (
    "seconds from the recording's first epoch (e.g. 30) or a GPS time written gps:T (e.g. "
    "gps:1425953430.5)"
)


@dataclass(frozen=True)
class SpanBound:
    """One end of a span: ``seconds`` from the first epoch, or a GPS time when ``gps``."""

    seconds: float
    gps: bool = False

    def __post_init__(self) -> None:
        if not math.isfinite(self.seconds):
            raise ValueError(f"a span bound must be finite, not {self.seconds}")
        if not self.gps and self.seconds < 0:
            raise ValueError(f"seconds from the first epoch must be >= 0, not {self.seconds:g}")

    def at(self, first: float) -> float:
        """The bound as a GPS time, for a recording whose first epoch is ``first``."""
        return self.seconds if self.gps else first + self.seconds

    def __str__(self) -> str:
        return f"{GPS_PREFIX}{self.seconds:.3f}" if self.gps else f"{self.seconds:g} s"

    @classmethod
    def parse(cls, text: str) -> SpanBound:
        """``'30'`` → 30 s from the first epoch; ``'gps:1425953430.5'`` → that GPS time.
        Raises ``ValueError`` naming :data:`SPAN_SYNTAX` for anything else."""
        word = text.strip()
        gps = word.lower().startswith(GPS_PREFIX)
        number = word[len(GPS_PREFIX) :] if gps else word
        try:
            value = float(number)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise ValueError(f"{text!r} is not a time: expected {SPAN_SYNTAX}")
        if not gps and value < 0:
            raise ValueError(
                f"{text!r}: seconds from the first epoch must be >= 0 (a GPS time is written "
                f"{GPS_PREFIX}T)"
            )
        return cls(value, gps)


@dataclass(frozen=True)
class GpsInterval:
    """A resolved span: GPS times ``begin`` ≤ t ≤ ``end`` (s) of a recording whose first epoch
    (what seconds from the first epoch count from) is ``first``."""

    begin: float
    end: float
    first: float

    def mask(self, t: np.ndarray) -> np.ndarray:
        """Which of the times ``t`` lie inside (bounds included)."""
        t = np.asarray(t, dtype=float)
        return (t >= self.begin) & (t <= self.end)

    def to_dict(self) -> dict:
        """The span for a summary: GPS seconds and seconds from the first epoch."""
        return {
            "start_gps_s": self.begin,
            "end_gps_s": self.end,
            "start_from_first_epoch_s": self.begin - self.first,
            "end_from_first_epoch_s": self.end - self.first,
        }


@dataclass(frozen=True)
class TimeSpan:
    """``--start`` / ``--end``; either may be None (the recording's first or last epoch)."""

    start: SpanBound | None = None
    end: SpanBound | None = None

    @property
    def whole(self) -> bool:
        """No bound given: the whole recording."""
        return self.start is None and self.end is None

    def problem(self) -> str | None:
        """The problem visible without the data: two bounds of the same kind not increasing."""
        start, end = self.start, self.end
        if start is None or end is None or start.gps != end.gps:
            return None
        if start.seconds >= end.seconds:
            return f"--start {start} is not before --end {end}"
        return None

    def resolve(self, times: np.ndarray, what: str) -> GpsInterval:
        """The span as GPS times against a recording's reference ``times`` (its GNSS epochs or
        image times, named by ``what``): :class:`UsageError` when a bound lies outside them or
        the start is not before the end, naming the recording's span both ways;
        :class:`InputError` when none of ``times`` lies inside (a gap in the recording)."""
        times = np.asarray(times, dtype=float)
        if not times.size:
            raise InputError(f"the recording has no {what}: nothing to take a span of")
        first, last = float(times[0]), float(times[-1])
        begin = first if self.start is None else self.start.at(first)
        end = last if self.end is None else self.end.at(first)
        recording = (
            f"the recording's {what} run from {GPS_PREFIX}{first:.3f} to {GPS_PREFIX}{last:.3f} "
            f"(0 to {last - first:.3f} s from the first epoch)"
        )
        for name, bound, value in (("--start", self.start, begin), ("--end", self.end, end)):
            if bound is not None and not first <= value <= last:
                raise UsageError(f"{name} {bound} lies outside the recording: {recording}")
        if begin >= end:
            raise UsageError(
                f"--start {self.start or 'first epoch'} ({GPS_PREFIX}{begin:.3f}) is not before "
                f"--end {self.end or 'last epoch'} ({GPS_PREFIX}{end:.3f}): {recording}"
            )
        interval = GpsInterval(begin, end, first)
        if not interval.mask(times).any():
            raise no_data(what, interval)
        return interval


def no_data(what: str, interval: GpsInterval) -> InputError:
    """The error of a span that holds none of ``what``."""
    return InputError(
        f"the span {GPS_PREFIX}{interval.begin:.3f} to {GPS_PREFIX}{interval.end:.3f} holds no "
        f"{what}: choose --start / --end around data"
    )


def trim_observations(obs: Observations, interval: GpsInterval) -> Observations:
    """The observations of the epochs inside ``interval`` (header, codes and the reader's
    problems kept)."""
    epochs = interval.mask(obs.epoch_time)
    return replace(
        obs.subset(interval.mask(obs.time)),
        epoch_time=obs.epoch_time[epochs],
        epoch_flag=obs.epoch_flag[epochs],
    )


def trim_series(series: SensorSeries, interval: GpsInterval) -> SensorSeries:
    """The samples of a sensor signal inside ``interval``."""
    keep = interval.mask(series.t)
    return SensorSeries(
        series.t[keep], series.value[keep], series.name, series.unit, series.n_skipped
    )


def trim_trajectory(trajectory: Trajectory, interval: GpsInterval) -> Trajectory:
    """The poses inside ``interval``."""
    return trajectory.subset(np.flatnonzero(interval.mask(trajectory.t)))


def trim_sigma(sigma: ReportedSigma, interval: GpsInterval) -> ReportedSigma:
    """The reported Doppler σ of the epochs inside ``interval``."""
    keep = interval.mask(sigma.t)
    return ReportedSigma(sigma.t[keep], sigma.sat_id[keep], sigma.code[keep], sigma.sigma_mps[keep])


Trimmable = Observations | SensorSeries | Trajectory | ReportedSigma | None


def trim(item: Trimmable, interval: GpsInterval) -> Trimmable:
    """Any input cut to ``interval`` by the ``trim_*`` function of its type (None stays
    None)."""
    if item is None:
        return None
    for kind, function in (
        (Observations, trim_observations),
        (SensorSeries, trim_series),
        (Trajectory, trim_trajectory),
        (ReportedSigma, trim_sigma),
    ):
        if isinstance(item, kind):
            return function(item, interval)
    raise TypeError(f"cannot trim a {type(item).__name__} to a time span")


def reference_times(sequence: Sequence) -> tuple[np.ndarray, str]:
    """The times a span of a recording is measured on: its GNSS epochs, else (no GNSS) its
    image times, else (no camera either) its yaw-rate samples; with their name."""
    if sequence.has_gnss:
        return sequence.observations.epoch_time, "GNSS epochs"
    if sequence.has_camera:
        return sequence.image_times, "images"
    return sequence.yaw_rate.t, "yaw-rate samples"


def trim_sequence(sequence: Sequence, span: TimeSpan) -> tuple[Sequence, GpsInterval]:
    """The recording cut to ``span`` (resolved on :func:`reference_times`): every input's
    samples inside it (GNSS epochs, images, vehicle signals, reported σ, ground truth; the
    navigation data whole, as a cut recording keeps its ephemerides), with the GPS interval.
    Raises :class:`UsageError` for a span outside the recording and :class:`InputError` when
    the span holds no GNSS epoch, image, yaw-rate or wheel-speed sample the recording has."""
    times, what = reference_times(sequence)
    interval = span.resolve(times, what)
    images = interval.mask(sequence.image_times)
    timed = ("observations", "doppler_sigma", "yaw_rate", "wheel_speed", "forward_acceleration")
    cut = replace(
        sequence,
        image_paths=sequence.image_paths.select(images),
        image_times=sequence.image_times[images],
        truth=trim(sequence.truth, interval),
        **{name: trim(getattr(sequence, name), interval) for name in timed},
    )
    empty = [
        name
        for name, before, after in (
            ("GNSS epoch", _count(sequence.observations), _count(cut.observations)),
            ("image", len(sequence.image_paths), len(cut.image_paths)),
            ("yaw-rate sample", len(sequence.yaw_rate), len(cut.yaw_rate)),
            ("wheel-speed sample", len(sequence.wheel_speed), len(cut.wheel_speed)),
        )
        if before and not after
    ]
    if empty:
        raise no_data(" and no ".join(empty), interval)
    return cut, interval


def _count(obs: Observations | None) -> int:
    return 0 if obs is None else len(obs.epoch_time)
