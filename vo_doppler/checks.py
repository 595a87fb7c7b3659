"""Plausibility checks that turn silent input errors into named warnings or errors.

Pure functions over model types and numpy (no file I/O, no stage): the library's entry points
call them (``run_sequence`` and ``heading_from_gnss``: errors raised before the work they
would spoil, warnings logged and returned), and so every command. The messages name the
signals as a :class:`~vo_doppler.model.vehicle_source.VehicleSignalSource` says (a file, a
CAN signal and its DBC, an option). Where the checks sit: docs/design.md, "Packages"; the
measurements behind their thresholds: docs/benchmarks.md, "Plausibility checks". Each check
states its threshold:

* yaw rate against its DBC unit: while the wheels turn faster than 2 m/s, a median |yaw rate|
  above 0.2 rad/s (11.5 °/s) or a median lateral acceleration |yaw rate × speed| above
  1.5 m/s² is no car's road driving (a skid pad would be); when the DBC says rad/s and the
  values read as deg/s would be ordinary, the hint says so;
* the yaw rate's sign against the GNSS Doppler course (:func:`yaw_rate_sign_agreement`): over
  the turns between two straights, the course change of the conventional heading (GNSS tests
  alone, at the wheel speed) and the integrated raw yaw rate must agree in sign; a summed
  course change of 30° or more at an agreement of −0.5 or less is an error, less turning is no
  verdict;
* the calibrated gyro bias: beyond ±4 °/s (a car yaw-rate sensor's specified offset) it is a
  warning;
* the CAN clock against the GNSS speed: the lag (±5 s, or a quarter of a shorter record) at
  which the scaled wheel speed agrees best with the horizontal Doppler speed at the valid GNSS
  epochs, by the median absolute difference (robust to the reflected epochs that pass the
  velocity's own tests, up to half of them), is the residual clock offset; beyond 0.2 s, or
  beyond 1 m along the track at the drive's median moving speed, it is a warning reporting the
  estimate next to the manifest's ``time_offset_s`` (``CLOCK_TOLERANCE_M``). The lag is only a
  lag when the agreement has a clear interior minimum: aligned, the two speeds differ by their
  noise alone, while misaligned by τ they differ by about |acceleration|·τ. A best difference
  above half the median over the lags (no shift matches: an offset beyond the range, or a speed
  too featureless), a best lag at the edge of the range (the agreement still improves beyond it)
  or a best difference above twice the GNSS speed's noise (aligned, the median difference is
  below that noise; a wrong shift leaves more) is "no lag found", a warning naming why, and no
  number. A drive steady more than half the time (a highway cruise) matches at every shift to
  the noise; without a clear minimum, the search is made again over the epochs where the wheel
  speed changes, |dv/dt| over ±0.5 s above five times its noise (at least 0.05 m/s²), with
  stricter guards: a best difference below a quarter of the median over the shifts and below
  twice the GNSS speed's noise, changes spread over more than twice the searched range (a single
  change can match another). A drive without speed changes then gets "no lag found" (the speed
  hardly changes);
* the wheel-speed times against the GNSS epochs: when more than 10 % of the epochs lie outside
  the wheel speed's time span, it is a warning, since those epochs get no tightly coupled
  heading. It tells why: vehicle signals whose clock the GNSS Doppler speed confirms where
  they overlap, or recorded over less than 90 % of the GNSS span, cover part of the drive; a
  wheel speed recorded as long but shifted is a clock offset wrong by more than the ±5 s
  searched, and the warning names the setting;
* the calibrated wheel scale: beyond 1 ± 0.10 it is a warning, since a tyre's rolling radius
  changes by a few per cent with wear and pressure, and a scale far from 1 means a speed in
  other units (km/h: 0.28, mph: 0.45) or a wheel speed that is not this drive's; so is the
  median ratio of the Doppler to the wheel speed at the valid moving epochs, which the
  calibration may never have seen (it takes only speeds within 10 % of each other);
* the ENU origin against the RINEX approximate position: more than 10 km apart is a warning;
* a standstill interval given by hand against the measured speed: a median speed above
  0.5 m/s inside it (GNSS speed noise at rest is a few cm/s to 0.2 m/s) is an error, since the
  gyro bias and the gyro combination of a moving "standstill" are the driving's.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from vo_doppler.bounds import RECEIVER_RADIUS
from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame, wrap_angle
from vo_doppler.model.gnss_solutions import VelocitySolution
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import integral_at
from vo_doppler.model.vehicle_source import VehicleSignalSource
from vo_doppler.robust import mad, nmad
from vo_doppler.time_hints import overlap_error, overlaps

MOVING_SPEED_MPS = 2.0
MAX_MEDIAN_YAW_RATE = 0.2
"""rad/s (11.5 °/s): a car's median |yaw rate| while moving is a few °/s at most (road drives:
1–2 °/s); a deg/s signal read as rad/s is 57 times its true value."""
MAX_MEDIAN_LATERAL_ACCELERATION = 1.5
"""m/s²: a car's median |yaw rate × speed| while moving (road drives: ≈ 0.3 m/s²)."""
CLOCK_TOLERANCE_S = 0.2
CLOCK_TOLERANCE_M = 1.0
"""Largest residual clock offset times the median moving speed (m) without a warning: on
comma2k19 the dead reckoning's error per 100 m grows once the vehicle signals are shifted by
more than this along the track, while the estimate's own error stays well below it
(docs/benchmarks.md, "Plausibility checks")."""
CLOCK_SEARCH_S = 5.0
CLOCK_RATE_HZ = 10.0
MAX_CLOCK_MATCH_RATIO = 0.5
"""Largest best-to-median ratio of the speed difference over the lags for a lag to count as
found: a true lag leaves the speeds' noise, a small fraction of the median, a chance alignment
of unrelated stretches of the drive or a featureless speed barely beats the rest
(docs/benchmarks.md, "Plausibility checks")."""
MIN_CLOCK_EPOCHS = 20
"""Fewest valid GNSS epochs inside the wheel speed's span (less the searched lag) to search,
and fewest of them where the wheel speed changes, at every searched lag."""
MAX_CHANGE_MATCH_RATIO = 0.25
"""``MAX_CLOCK_MATCH_RATIO`` of the search over the epochs where the speed changes: there a
true lag leaves a small fraction of the median, a chance match of a few changes a
quarter or more (docs/benchmarks.md, "Plausibility checks")."""
MAX_CLOCK_NOISE_MULTIPLE = 2.0
"""Largest best median difference for a lag, in units of the GNSS speed's sample noise σ: at
the true shift the two speeds differ by their noise, below one σ; a chance match differs by
more (docs/benchmarks.md, "Plausibility checks")."""
MIN_CLOCK_NOISE_MPS = 0.02
"""Least GNSS speed noise assumed (m/s): a noise-free speed still differs from the wheel
speed by interpolation and the sampling of the shifts."""
CLOCK_SLOPE_HALF_WINDOW_S = 0.5
"""The wheel speed's rate of change is its difference over ±0.5 s (s)."""
CLOCK_SLOPE_NOISE_FACTOR = 5.0
"""A speed change counts where |dv/dt| exceeds this many times the noise of the rate of change
(the wheel speed's sample noise, from its second differences, through the ±0.5-s difference)."""
MIN_CLOCK_ACCELERATION = 0.05
"""m/s²: the least |dv/dt| that counts as a speed change, however quiet the wheel speed (a
cruise control holds the speed within a few cm/s over seconds: 0.01-0.02 m/s²)."""
MIN_SPEED_COVERAGE = 0.9
WHEEL_SCALE_TOLERANCE = 0.10
STANDSTILL_MAX_MEDIAN_SPEED_MPS = 0.5
ORIGIN_TOLERANCE_M = 10_000.0
SIGN_SPAN_S = (1.0, 8.0)
"""Shortest and longest time (s) between the two conventional headings of a compared span:
the longest bridges a turn (a right angle at 30 °/s: 3 s) and a gap of the heading in a
street canyon around it."""
SIGN_STRAIGHT_RATE = np.radians(3.0)
"""rad/s: a span's ends are where the vehicle drives straight, the gyro's |mean rate| over the
surrounding second below this (sign aside), since in a canyon's turn the conventional course
is often reflected for seconds (a simulated canyon: 40–175° off with six or seven
satellites, at the wheel speed) while on the straights before and after it is not."""
SIGN_MIN_TURN_RATE = np.radians(2.0)
"""rad/s: a span is a turn when the Doppler course and the integrated yaw rate both turn
faster than this on average, beyond a raw car gyro's bias (well under 1 °/s on the drives
here) and slower than the curves of a highway (a few °/s)."""
SIGN_SPEED_TOLERANCE = (0.5, 0.10)
"""m/s and fraction: a conventional heading counts only where its horizontal speed lies within
max(these) of the calibrated wheel speed, as the calibration's own gate. In a street canyon a
velocity from four or five satellites can pass the GNSS tests and point the other way (a
simulated canyon: 175° off for seconds after a turn, at half the wheel speed)."""
SIGN_CONFIRM = (1.5, np.radians(5.0))
"""s and rad: a conventional course counts only when the next or previous one, at most 1.5 s
away, turned from it by the amount the gyro turned, within 5° (sign aside): a lone reflected
course (a simulated canyon: 62° off, seven satellites) has no such neighbour. 1.5 s admits the
neighbour of a 1-Hz receiver (at 0.5 s no course of a 1-Hz recording was ever confirmed, and a
negated yaw rate ran with exit 0); the gyro, not the time, carries the comparison."""
SIGN_NOISE_FACTOR = 5.0
"""A turn's course change also exceeds this many σ of the two conventional headings."""
SIGN_MAX_TURN_RATIO = 1.5
"""The course and the gyro must turn by amounts within this factor of each other, sign aside
(a wrong sign leaves the amounts alike): a span across a reflected course (a simulated
canyon: 61° off at the wheel speed) turns by another amount than the gyro."""
SIGN_MAX_TURN = np.radians(150.0)
"""Spans turning more (by the gyro or the course) are left out: the wrap at 180° blurs them."""
SIGN_MIN_TOTAL_TURN = np.radians(30.0)
"""Least course change summed over the turns for a verdict: below it, no verdict."""
SIGN_MAX_AGREEMENT = -0.5
"""At or below this agreement (+1: every turn agrees in sign, −1: every turn disagrees) the
yaw rate has the wrong sign."""
MAX_GYRO_BIAS = np.radians(4.0)
"""rad/s (4 °/s): beyond the offset a car's yaw-rate sensor is specified for over its life
and temperature range (3.75 °/s, a Hyundai ESP yaw-rate/lateral-G sensor's shop-manual
specification; ESP units zero it at standstill, the drives here show 0.03–0.4 °/s). A
calibrated bias beyond it is the calibration absorbing a yaw rate that is wrong (its sign,
its axis), not a sensor's offset: 5.9 °/s on a 20 s simulated drive with the sign flipped."""


@dataclass(frozen=True)
class ClockOffsetEstimate:
    """Residual offset (s) to add to the sensor's ``time_offset_s``; the median absolute
    difference (m/s) of the GNSS and the scaled wheel speed at that shift and unshifted. When
    the search has no real answer, ``residual_s`` is None and ``no_lag_reason`` says why."""

    residual_s: float | None
    difference_mps: float | None = None
    unshifted_difference_mps: float | None = None
    search_s: float = CLOCK_SEARCH_S
    """Half-width of the searched lags (s)."""
    no_lag_reason: str = ""
    moving_speed_mps: float | None = None
    """Median GNSS speed over the searched epochs faster than 2 m/s (None without one)."""


def moving_yaw_rate_medians(yaw_rate: SensorSeries, speed: SensorSeries) -> tuple[float, float]:
    """Median |yaw rate| (rad/s) and median |yaw rate × speed| (m/s²) over the yaw-rate samples
    where the wheel speed exceeds 2 m/s (NaNs when the vehicle never moves)."""
    if len(yaw_rate) == 0 or len(speed) < 2:
        return float("nan"), float("nan")
    v = np.interp(yaw_rate.t, speed.t, speed.value, left=0.0, right=0.0)
    moving = v > MOVING_SPEED_MPS
    if not moving.any():
        return float("nan"), float("nan")
    rate = np.abs(yaw_rate.value[moving])
    return float(np.median(rate)), float(np.median(rate * v[moving]))


def check_yaw_rate_unit(
    yaw_rate: SensorSeries, speed: SensorSeries, source: VehicleSignalSource | None = None
) -> None:
    """Raise when the yaw rate is implausibly large for a moving car (module docstring),
    naming the yaw rate's origin and, when its values read as deg/s would be ordinary and it
    declares rad/s, what to fix (``source``; generic words without one)."""
    source = source or VehicleSignalSource()
    rate, lateral = moving_yaw_rate_medians(yaw_rate, speed)
    if not (rate > MAX_MEDIAN_YAW_RATE or lateral > MAX_MEDIAN_LATERAL_ACCELERATION):
        return
    hint = ""
    as_degrees = np.radians([rate, lateral])
    if source.yaw_rate_unit.strip().lower().replace(" ", "") == "rad/s" and (
        as_degrees[0] <= MAX_MEDIAN_YAW_RATE and as_degrees[1] <= MAX_MEDIAN_LATERAL_ACCELERATION
    ):
        hint = f"; the values look like deg/s: {source.yaw_rate_unit_fix}"
    raise InputError(
        f"{source.yaw_rate}: implausibly large for a moving car: median |yaw rate| "
        f"{rate:.3g} rad/s ({np.degrees(rate):.3g} °/s), median |yaw rate × speed| "
        f"{lateral:.3g} m/s² while moving (declared unit {source.yaw_rate_unit!r}){hint}"
    )


def estimate_clock_offset(
    speed: SensorSeries, t_gnss: np.ndarray, speed_gnss: np.ndarray
) -> ClockOffsetEstimate:
    """Residual clock offset of ``speed`` (already on GPS time by the manifest's offset) against
    the GNSS speed: the shift s (0.1-s steps within ±5 s or a quarter of the record, refined by
    a parabola through the best step) minimising median |gnss(t) − k·speed(t − s)| over the
    valid GNSS epochs (no interpolation across GNSS gaps), k the median ratio of the two speeds
    where the wheels turn faster than 2 m/s (the wheel scale error). No lag (``residual_s``
    None, with the reason) with fewer than ``MIN_CLOCK_EPOCHS`` epochs inside the overlap,
    without moving epochs, with the best shift at the edge of the range or no clear minimum
    (``MAX_CLOCK_MATCH_RATIO``; module docstring).

    Without a clear minimum over all epochs, the search is made again over the epochs where the
    wheel speed changes (:func:`speed_change_threshold`): at a steady speed every shift matches,
    so a drive steady more than half the time has the median at the noise at every shift. That
    second search has stricter guards against a chance match of a few speed changes
    (``MAX_CHANGE_MATCH_RATIO``, ``MAX_CLOCK_NOISE_MULTIPLE``, changes spread over twice the
    searched range)."""
    t_gnss, speed_gnss = np.asarray(t_gnss, dtype=float), np.asarray(speed_gnss, dtype=float)
    if len(speed) < 2:
        return ClockOffsetEstimate(None, no_lag_reason="the wheel speed has fewer than 2 samples")
    span = min(CLOCK_SEARCH_S, (speed.t[-1] - speed.t[0]) / 4)
    inside = (
        np.isfinite(speed_gnss) & (t_gnss >= speed.t[0] + span) & (t_gnss <= speed.t[-1] - span)
    )
    if np.count_nonzero(inside) < MIN_CLOCK_EPOCHS:
        return ClockOffsetEstimate(
            None,
            search_s=span,
            no_lag_reason=f"only {np.count_nonzero(inside)} valid GNSS epochs lie inside the "
            f"wheel speed's span, {MIN_CLOCK_EPOCHS} needed",
        )
    t, reference = t_gnss[inside], speed_gnss[inside]
    estimate, unclear = _lag_search(speed, t, reference, span, None)
    if unclear:
        changes, unclear = _lag_search(speed, t, reference, span, speed_change_threshold(speed))
        estimate = estimate if unclear else changes
    moving = reference[reference > MOVING_SPEED_MPS]
    return replace(estimate, moving_speed_mps=float(np.median(moving)) if moving.size else None)


def _lag_search(
    speed: SensorSeries, t: np.ndarray, reference: np.ndarray, span: float, threshold: float | None
) -> tuple[ClockOffsetEstimate, bool]:
    """The lag search of :func:`estimate_clock_offset` over all epochs (``threshold`` None) or
    over those where the wheel speed changes faster than ``threshold``; True beside a no-lag
    estimate when the agreement had no clear minimum (both searches without one: the reason
    given is the first's)."""
    step = 1.0 / CLOCK_RATE_HZ
    lags = np.arange(-span, span + step / 2, step)
    costs = np.array([_speed_difference(speed, t, reference, lag, threshold) for lag in lags])
    if not np.isfinite(costs).all():
        lag = lags[np.flatnonzero(~np.isfinite(costs))[0]]
        return _no_lag(span, _featureless(speed, t, lag, threshold)), False
    best = int(np.argmin(costs))
    typical = float(np.median(costs))
    ratio = MAX_CLOCK_MATCH_RATIO if threshold is None else MAX_CHANGE_MATCH_RATIO
    if not costs[best] < ratio * typical:  # a flat 0 is no minimum either
        return _no_lag(
            span,
            f"no shift matches, the smallest median difference ({costs[best]:.2f} m/s) "
            f"is not below {ratio:g} times their median ({typical:.2f} m/s): an offset beyond "
            "the range, or a featureless speed",
        ), True
    if best in (0, len(lags) - 1):
        return _no_lag(
            span,
            f"the agreement is best at the edge of the range, {lags[best]:+.1f} s "
            f"({costs[best]:.2f} m/s): the offset is beyond it",
        ), False
    above_noise = _above_noise(reference, lags[best], costs[best], threshold)
    if above_noise:
        return _no_lag(span, above_noise), threshold is None
    if threshold is not None:
        problem = _chance_match(speed, t, lags[best], costs[best], threshold, span)
        if problem:
            return _no_lag(span, problem), False
    # The refinement compares the three shifts on one set of epochs, the best shift's changing
    # ones: on each shift's own set the parabola would lean by the sets' difference.
    left, mid, right = (
        _speed_difference(speed, t, reference, lag, threshold, lags[best])
        for lag in lags[best - 1 : best + 2]
    )
    curvature = left - 2 * mid + right
    offset = 0.5 * (left - right) / curvature if curvature > 0 else 0.0
    residual = float(lags[best] + offset * step)
    return ClockOffsetEstimate(
        residual,
        _speed_difference(speed, t, reference, residual, threshold),
        _speed_difference(speed, t, reference, 0.0, threshold),
        span,
    ), False


def _no_lag(span: float, reason: str) -> ClockOffsetEstimate:
    return ClockOffsetEstimate(None, search_s=span, no_lag_reason=reason)


def _chance_match(
    speed: SensorSeries, t: np.ndarray, lag: float, cost: float, threshold: float, span: float
) -> str | None:
    """Why the best ``lag`` of the speed changes may be a chance match, or None: changes
    spread over less than twice the searched range (one change matching another)."""
    changing = t[np.abs(_slope(speed, t - lag)) > threshold]
    spread = float(changing[-1] - changing[0])
    if spread < 2 * span:
        return (
            f"at the best shift, {lag:+.1f} s ({cost:.2f} m/s), the wheel speed changes within "
            f"{spread:.1f} s only, less than the {2 * span:.3g} s searched: one change can match "
            "another at a wrong shift"
        )
    return None


def _above_noise(
    reference: np.ndarray, lag: float, cost: float, threshold: float | None
) -> str | None:
    """Why the best ``lag`` is no match, or None: its median difference ``cost`` above
    ``MAX_CLOCK_NOISE_MULTIPLE`` times the GNSS speed's noise (over the epochs where the wheel
    speed changes when a ``threshold`` is given)."""
    noise = max(sample_noise(reference), MIN_CLOCK_NOISE_MPS)
    if cost <= MAX_CLOCK_NOISE_MULTIPLE * noise:
        return None
    where = "" if threshold is None else " where the speed changes"
    return (
        f"no shift matches to the noise: the smallest median difference{where} "
        f"({cost:.2f} m/s, at {lag:+.1f} s) is above {MAX_CLOCK_NOISE_MULTIPLE:g} "
        f"times the GNSS speed's noise ({noise:.2f} m/s): an offset beyond the range"
    )


def sample_noise(values: np.ndarray) -> float:
    """Robust σ of a smooth signal's sample noise: the median absolute second difference
    (1.4826 MAD / √6), which the signal's own changes hardly touch."""
    second = np.diff(values, 2)
    return float(nmad(second, centre=False) / np.sqrt(6.0)) if second.size else 0.0


def speed_change_threshold(speed: SensorSeries) -> float:
    """The |dv/dt| (m/s²) above which the wheel speed changes: ``CLOCK_SLOPE_NOISE_FACTOR``
    times the noise of its ±``CLOCK_SLOPE_HALF_WINDOW_S`` difference (the sample noise from
    the median absolute second difference, which a drive's own accelerations hardly touch),
    at least ``MIN_CLOCK_ACCELERATION``."""
    slope_noise = sample_noise(speed.value) * np.sqrt(2.0) / (2.0 * CLOCK_SLOPE_HALF_WINDOW_S)
    return float(max(CLOCK_SLOPE_NOISE_FACTOR * slope_noise, MIN_CLOCK_ACCELERATION))


def _slope(speed: SensorSeries, t: np.ndarray) -> np.ndarray:
    """The wheel speed's rate of change (m/s²) at ``t``, over ±``CLOCK_SLOPE_HALF_WINDOW_S``."""
    h = CLOCK_SLOPE_HALF_WINDOW_S
    return (np.interp(t + h, speed.t, speed.value) - np.interp(t - h, speed.t, speed.value)) / (
        2.0 * h
    )


def _speed_difference(
    speed: SensorSeries,
    t: np.ndarray,
    reference: np.ndarray,
    lag: float,
    threshold: float | None,
    selection_lag: float | None = None,
) -> float:
    """median |reference − k·speed(t − lag)| over the epochs ``t`` (with a ``threshold``: those
    where the wheel speed shifted by ``selection_lag``, default ``lag``, changes faster), k the
    median ratio over the moving epochs; NaN without a moving epoch or with fewer than
    ``MIN_CLOCK_EPOCHS`` epochs selected.
    """
    shifted = np.interp(t - lag, speed.t, speed.value)
    moving = shifted > MOVING_SPEED_MPS
    if threshold is None:
        changing = np.ones(t.size, dtype=bool)
    else:
        selected = lag if selection_lag is None else selection_lag
        changing = np.abs(_slope(speed, t - selected)) > threshold
    if not moving.any() or np.count_nonzero(changing) < MIN_CLOCK_EPOCHS:
        return float("nan")
    scale = np.median(reference[moving] / shifted[moving])
    return mad((reference - scale * shifted)[changing], centre=False)


def _featureless(speed: SensorSeries, t: np.ndarray, lag: float, threshold: float | None) -> str:
    """Why the wheel speed shifted by ``lag`` gives nothing to align (``_speed_difference``
    NaN)."""
    fastest = float(np.max(speed.value, initial=0.0))
    if fastest <= MOVING_SPEED_MPS:
        return (
            f"the vehicle does not move: the wheel speed never exceeds {MOVING_SPEED_MPS:g} m/s "
            f"(at most {fastest:.2f} m/s), so its clock cannot be checked against the GNSS"
        )
    if threshold is None or not (np.interp(t - lag, speed.t, speed.value) > MOVING_SPEED_MPS).any():
        return (
            f"the vehicle hardly moves: shifted by {lag:+.1f} s the wheel speed exceeds "
            f"{MOVING_SPEED_MPS:g} m/s at no valid GNSS epoch"
        )
    changing = np.count_nonzero(np.abs(_slope(speed, t - lag)) > threshold)
    return (
        f"the speed hardly changes: shifted by {lag:+.1f} s, only {changing} valid GNSS epochs "
        f"see the wheel speed change faster than {threshold:.2g} m/s², {MIN_CLOCK_EPOCHS} "
        "needed (at a steady speed every shift matches)"
    )


def clock_warning(
    sensor: str,
    estimate: ClockOffsetEstimate,
    manifest_offset_s: float,
    offset_name: str = "the manifest's time_offset_s",
) -> str | None:
    """A warning when the estimated residual offset exceeds 0.2 s or 1 m along the track at
    the median moving speed, or when no lag was found (the offset is then unchecked);
    ``offset_name`` names the setting to fix."""
    if estimate.residual_s is None:
        return (
            f"{sensor} clock: no lag found between the wheel speed and the GNSS Doppler speed "
            f"within ±{estimate.search_s:.3g} s: {estimate.no_lag_reason}; {offset_name} "
            f"{manifest_offset_s:.3f} s is unchecked"
        )
    along = abs(estimate.residual_s) * (estimate.moving_speed_mps or 0.0)
    if abs(estimate.residual_s) <= CLOCK_TOLERANCE_S and along <= CLOCK_TOLERANCE_M:
        return None
    track = (
        f", {along:.1f} m along the track at {estimate.moving_speed_mps:.1f} m/s"
        if estimate.moving_speed_mps
        else ""
    )
    return (
        f"{sensor} clock: the wheel speed matches the GNSS Doppler speed best when shifted by "
        f"{estimate.residual_s:+.2f} s{track} (median difference "
        f"{estimate.difference_mps:.2f} m/s, "
        f"{estimate.unshifted_difference_mps:.2f} m/s unshifted); {offset_name} "
        f"{manifest_offset_s:.3f} s should be about "
        f"{manifest_offset_s + estimate.residual_s:.3f} s"
    )


SAME_SPAN_RATIO = 0.9
"""A wheel speed whose span is at least this share of the GNSS epochs' span was recorded over
as long as the GNSS: when it leaves epochs uncovered it is shifted (a clock offset), not cut."""


def coverage_warning(
    sensor: str,
    speed: SensorSeries,
    t_gnss: np.ndarray,
    offset_s: float,
    offset_name: str,
    clock: ClockOffsetEstimate | None = None,
) -> str | None:
    """A warning when more than 10 % of the GNSS epochs lie outside the wheel speed's time
    span (module docstring), telling part coverage from a clock offset: a clock the GNSS
    Doppler speed confirms where the two overlap (``clock``: its residual within the clock
    tolerance) or a wheel speed recorded over a shorter time than the GNSS (less than
    :data:`SAME_SPAN_RATIO` of it) covers part of the drive; one recorded as long but shifted
    is a clock offset beyond the ±5 s the clock check searches, and the warning names the
    setting that fixes it."""
    t_gnss = np.asarray(t_gnss, dtype=float)
    if t_gnss.size == 0 or len(speed) == 0:
        return None
    inside = (t_gnss >= speed.t[0]) & (t_gnss <= speed.t[-1])
    if inside.mean() >= MIN_SPEED_COVERAGE:
        return None
    starts, ends = speed.t[0] - t_gnss[0], speed.t[-1] - t_gnss[-1]
    recorded, drive = float(speed.t[-1] - speed.t[0]), float(t_gnss[-1] - t_gnss[0])
    found = (
        f"the wheel speed covers only {inside.mean():.0%} of the GNSS epochs (it "
        f"starts {starts:+.1f} s and ends {ends:+.1f} s from them), and the epochs outside get "
        "no tightly coupled heading"
    )
    confirmed = (
        clock is not None
        and clock.residual_s is not None
        and abs(clock.residual_s) <= CLOCK_TOLERANCE_S
    )
    if confirmed:
        return (
            f"{sensor}: {found}; where the two overlap, the wheel speed matches the GNSS "
            f"Doppler speed (clock residual {clock.residual_s:+.2f} s), so the vehicle signals "
            f"cover part of the drive: not a clock offset ({offset_name} {offset_s:.3f} s fits)"
        )
    if recorded < SAME_SPAN_RATIO * drive:
        return (
            f"{sensor}: {found}; the wheel speed was recorded over {recorded:.1f} s of the "
            f"{drive:.1f} s of GNSS, so they cover part of the drive (were they recorded over "
            f"all of it, {offset_name} {offset_s:.3f} s would be off by more than the "
            f"±{CLOCK_SEARCH_S:g} s the clock check searches)"
        )
    return (
        f"{sensor} clock: {found}; recorded over as long as the GNSS ({recorded:.1f} of "
        f"{drive:.1f} s) but shifted by {starts:+.1f} s, as a clock offset wrong by more than "
        f"the ±{CLOCK_SEARCH_S:g} s the clock check searches: check {offset_name} "
        f"{offset_s:.3f} s"
    )


def wheel_scale_warning(scale: float, found: str = "the calibration gives") -> str | None:
    """A warning when the wheel scale ``found`` lies beyond 1 ± 0.10 (module docstring)."""
    if not np.isfinite(scale) or abs(scale - 1.0) <= WHEEL_SCALE_TOLERANCE:
        return None
    return (
        f"wheel scale: {found} {scale:.3f}, beyond 1 ± {WHEEL_SCALE_TOLERANCE:g} "
        "(a tyre's radius changes by a few per cent): is the wheel speed in m/s (km/h reads "
        "0.278, mph 0.447) and its clock offset right?"
    )


def calibration_warnings(
    wheel_speed: SensorSeries,
    velocity: VelocitySolution,
    wheel_scale: float | None,
    sensor: str,
    offset_s: float,
    offset_name: str = "the manifest's time_offset_s",
) -> tuple[ClockOffsetEstimate, list[str]]:
    """The checks of a heading calibration, for ``run`` and ``heading`` alike: the wheel-speed
    times against the GNSS epochs (``coverage_warning``), its clock against the horizontal
    Doppler speed at the valid epochs (``clock_warning``) and the
    calibrated ``wheel_scale`` (``wheel_scale_warning``; None when the scale was fixed, not
    calibrated). Returns the clock estimate and the warnings."""
    horizontal = np.where(
        velocity.valid, np.linalg.norm(velocity.velocity_enu[:, :2], axis=1), np.nan
    )
    estimate = estimate_clock_offset(wheel_speed, velocity.t, horizontal)
    scale = None if wheel_scale is None else wheel_scale_warning(wheel_scale)
    if wheel_scale is not None and scale is None:
        scale = speed_ratio_warning(wheel_speed, velocity.t, horizontal, wheel_scale)
    found = [
        coverage_warning(sensor, wheel_speed, velocity.t, offset_s, offset_name, estimate),
        clock_warning(sensor, estimate, offset_s, offset_name),
        scale,
    ]
    return estimate, [warning for warning in found if warning]


def speed_ratio_warning(
    wheel_speed: SensorSeries, t_gnss: np.ndarray, gnss_speed: np.ndarray, wheel_scale: float
) -> str | None:
    """The median ratio of the GNSS speed ``gnss_speed`` (NaN where invalid) to the wheel speed
    at the GNSS epochs where the wheels turn faster than 2 m/s, judged as a calibrated wheel
    scale is (:func:`wheel_scale_warning`), from ``MIN_CLOCK_EPOCHS`` epochs on. The
    calibration takes only the Doppler speeds within 10 % of the wheel speed, so a wheel speed
    in other units is never calibrated on a short drive, and the scale of 1 it keeps would pass
    the check of a calibrated one (a simulated 20-s drive with its speed in km/h)."""
    if len(wheel_speed) < 2:
        return None
    wheel = np.interp(t_gnss, wheel_speed.t, wheel_speed.value, left=np.nan, right=np.nan)
    moving = np.isfinite(gnss_speed) & (np.nan_to_num(wheel) > MOVING_SPEED_MPS)
    if np.count_nonzero(moving) < MIN_CLOCK_EPOCHS:
        return None
    ratio = float(np.median(gnss_speed[moving] / wheel[moving]))
    return wheel_scale_warning(
        ratio,
        f"the calibration gives {wheel_scale:.3f} from the Doppler speeds within 10 % of the "
        f"wheel speed, but over {np.count_nonzero(moving)} valid GNSS epochs the Doppler speed "
        "is the wheel speed times",
    )


@dataclass(frozen=True)
class YawRateSignAgreement:
    """How the raw yaw rate agrees in sign with the GNSS Doppler course over the turns:
    ``agreement`` the turns' sign agreement weighted by their course change (+1 all agree, −1
    all disagree; NaN without a turn), ``turns`` their number, ``turn_rad`` their summed
    |course change|."""

    agreement: float
    turns: int
    turn_rad: float


def yaw_rate_sign_agreement(
    table: HeadingTable,
    velocity: VelocitySolution,
    wheel_speed: SensorSeries,
    yaw_rate: SensorSeries,
) -> YawRateSignAgreement:
    """Compare the integrated yaw rate with the change of the conventional Doppler course.

    The course is the conventional heading that passed the GNSS tests alone
    (:attr:`~vo_doppler.model.heading.HeadingTable.published_conventional`): the tightly
    coupled heading and the gyro-tested conventional one use the yaw rate themselves and would
    follow a wrong sign. A course counts where the conventional ``velocity`` (one row per
    table epoch) agrees with the calibrated ``wheel_speed`` (``SIGN_SPEED_TOLERANCE``), a
    neighbour confirms it (``SIGN_CONFIRM``) and the vehicle drives straight
    (``SIGN_STRAIGHT_RATE``): the GNSS tests alone pass reflected velocities in a canyon, most
    of all in its turns. From each such course, the first one ``SIGN_SPAN_S`` later (1 to 8 s)
    closes a span; spans do not overlap. A span is a turn when the course and the integrated
    raw yaw rate (uncalibrated: the calibration absorbs a wrong sign into the bias) both
    change by more than ``SIGN_MIN_TURN_RATE`` × its duration and less than
    ``SIGN_MAX_TURN``, by amounts within ``SIGN_MAX_TURN_RATIO`` of each other, the course by
    more than ``SIGN_NOISE_FACTOR`` σ."""
    valid, sigma = table.published_conventional
    t, course = table.t, table.yaw_conv
    if len(yaw_rate) < 2 or len(wheel_speed) < 2 or len(velocity.t) != len(t):
        return YawRateSignAgreement(float("nan"), 0, 0.0)
    wheel = table.wheel_scale * np.interp(t, wheel_speed.t, wheel_speed.value)
    gnss_speed = np.hypot(velocity.velocity_enu[:, 0], velocity.velocity_enu[:, 1])
    tolerance = np.maximum(SIGN_SPEED_TOLERANCE[0], SIGN_SPEED_TOLERANCE[1] * np.abs(wheel))
    agrees = np.abs(np.nan_to_num(gnss_speed - wheel, nan=np.inf)) <= tolerance
    rows = np.flatnonzero(
        valid & agrees & np.isfinite(course) & (t >= yaw_rate.t[0]) & (t <= yaw_rate.t[-1])
    )
    turned = integral_at(yaw_rate.t, yaw_rate.value, t[rows])
    around = integral_at(yaw_rate.t, yaw_rate.value, t[rows] + 0.5, "extend") - integral_at(
        yaw_rate.t, yaw_rate.value, t[rows] - 0.5, "extend"
    )
    alike = (np.diff(t[rows]) <= SIGN_CONFIRM[0]) & (
        np.abs(np.abs(wrap_angle(np.diff(course[rows]))) - np.abs(np.diff(turned)))
        <= SIGN_CONFIRM[1]
    )
    confirmed = np.concatenate([[False], alike]) | np.concatenate([alike, [False]])
    ends = confirmed & (np.abs(around) <= SIGN_STRAIGHT_RATE * 1.0)
    rows, turned = rows[ends], turned[ends]
    signs, weights = [], []
    start = 0
    while start < len(rows):
        end = int(np.searchsorted(t[rows], t[rows[start]] + SIGN_SPAN_S[0]))
        if end >= len(rows):
            break
        a, b = rows[start], rows[end]
        duration = t[b] - t[a]
        course_change = float(wrap_angle(course[b] - course[a]))
        gyro_change = float(turned[end] - turned[start])
        noise = SIGN_NOISE_FACTOR * float(np.hypot(*np.nan_to_num(sigma[[a, b]])))
        least = SIGN_MIN_TURN_RATE * duration
        if (
            duration <= SIGN_SPAN_S[1]
            and max(least, noise) < abs(course_change) < SIGN_MAX_TURN
            and least < abs(gyro_change) < SIGN_MAX_TURN
            and abs(course_change) <= SIGN_MAX_TURN_RATIO * abs(gyro_change)
            and abs(gyro_change) <= SIGN_MAX_TURN_RATIO * abs(course_change)
        ):
            signs.append(np.sign(course_change * gyro_change))
            weights.append(abs(course_change))
        start = end
    if not weights:
        return YawRateSignAgreement(float("nan"), 0, 0.0)
    total = float(np.sum(weights))
    return YawRateSignAgreement(float(np.dot(signs, weights)) / total, len(weights), total)


def check_yaw_rate_sign(
    table: HeadingTable,
    velocity: VelocitySolution,
    wheel_speed: SensorSeries,
    yaw_rate: SensorSeries,
    source: VehicleSignalSource | None = None,
) -> YawRateSignAgreement:
    """Raise when the yaw rate turns against the GNSS Doppler course (agreement at or below
    ``SIGN_MAX_AGREEMENT`` over at least ``SIGN_MIN_TOTAL_TURN`` of turns), naming the setting
    to change (``source``); too few turns give no verdict. Returns the agreement."""
    source = source or VehicleSignalSource()
    found = yaw_rate_sign_agreement(table, velocity, wheel_speed, yaw_rate)
    if found.turn_rad >= SIGN_MIN_TOTAL_TURN and found.agreement <= SIGN_MAX_AGREEMENT:
        raise InputError(
            f"{source.yaw_rate}: wrong sign: over {found.turns} turn(s) "
            f"totalling {np.degrees(found.turn_rad):.0f}° of GNSS Doppler course change, it "
            f"turns the other way (sign agreement {found.agreement:+.2f}, +1 when right); "
            f"{source.yaw_rate_sign_fix}"
        )
    return found


def gyro_bias_warning(bias: float) -> str | None:
    """A warning when the calibrated gyro bias (rad/s) exceeds ``MAX_GYRO_BIAS``."""
    if not np.isfinite(bias) or abs(bias) <= MAX_GYRO_BIAS:
        return None
    return (
        f"gyro bias: the calibration gives {np.degrees(bias):+.2f} °/s, beyond the ±"
        f"{np.degrees(MAX_GYRO_BIAS):g} °/s of a car's yaw-rate sensor: is the yaw rate "
        "counter-clockwise positive, in rad/s, about the vertical axis, and its clock right?"
    )


def heading_warnings(
    table: HeadingTable,
    velocity: VelocitySolution,
    wheel_speed: SensorSeries,
    yaw_rate: SensorSeries,
    source: VehicleSignalSource | None = None,
    scale_calibrated: bool = True,
    bias_calibrated: bool = True,
) -> tuple[ClockOffsetEstimate, list[str]]:
    """Every check of a heading stage's result, for the library and so for every command:
    raises for a yaw rate of the wrong sign (:func:`check_yaw_rate_sign`); returns the clock
    estimate and the warnings of :func:`calibration_warnings` and :func:`gyro_bias_warning`
    (the wheel scale and gyro bias only when calibrated, not fixed)."""
    source = source or VehicleSignalSource()
    sign = check_yaw_rate_sign(table, velocity, wheel_speed, yaw_rate, source)
    estimate, found = calibration_warnings(
        wheel_speed,
        velocity,
        float(table.wheel_scale[-1]) if scale_calibrated and len(table) else None,
        source.sensor,
        source.offset_s,
        source.offset_name,
    )
    bias = gyro_bias_warning(float(table.gyro_bias[-1])) if bias_calibrated and len(table) else None
    undecided = sign_undecided_warning(sign, source)
    untested = continuity_warning(velocity)
    return estimate, found + [w for w in (bias, undecided, untested) if w]


def continuity_warning(velocity: VelocitySolution) -> str | None:
    """A warning when the course-continuity test (2b) could not judge most valid epochs (its
    neighbours within ±0.5 s: a 1-Hz receiver has none), so that their validity rests on the
    epoch's own tests and the heading stage's gyro and wheel test alone."""
    tested = velocity.continuity_tested
    if tested is None or not velocity.valid.any():
        return None
    share = float(tested.sum() / velocity.valid.sum())
    if share >= 0.5:
        return None
    return (
        f"GNSS course continuity: judged {share:.0%} of the valid epochs only (it needs "
        "neighbours within ±0.5 s; the epochs are "
        f"{float(np.median(np.diff(velocity.t))):.2g} s apart): the others rest on their own "
        "chi-square and vertical tests and on the gyro and wheel test"
    )


def sign_undecided_warning(
    sign: YawRateSignAgreement, source: VehicleSignalSource | None = None
) -> str | None:
    """A warning when the yaw rate's sign could not be checked: fewer than
    ``SIGN_MIN_TOTAL_TURN`` of confirmed turns (a straight drive, or conventional courses too
    few or too scattered to confirm one another)."""
    if sign.turn_rad >= SIGN_MIN_TOTAL_TURN:
        return None
    name = (source or VehicleSignalSource()).yaw_rate
    return (
        f"{name}: its sign could not be checked against the GNSS Doppler course "
        f"({np.degrees(sign.turn_rad):.0f}° of confirmed turns, "
        f"{np.degrees(SIGN_MIN_TOTAL_TURN):.0f}° needed)"
    )


def check_vehicle_overlap(
    wheel_speed: SensorSeries,
    yaw_rate: SensorSeries,
    epoch_time: np.ndarray,
    source: VehicleSignalSource | None = None,
) -> None:
    """Raise when the wheel speed's or the yaw rate's times (GPS time after their offsets) do
    not meet the span of the GNSS epochs: no epoch would have them, so no heading could exist,
    and the cause is a clock offset (the message guesses which, :func:`offset_hint`)."""
    source = source or VehicleSignalSource()
    for what, series, option in (
        ("wheel-speed", wheel_speed, source.offset_name),
        ("yaw-rate", yaw_rate, source.yaw_rate_offset_name or source.offset_name),
    ):
        if not overlaps(series.t, epoch_time):
            raise overlap_error(f"{source.sensor} {what}", series.t, epoch_time, option)


def origin_warning(enu: EnuFrame, approx_position_ecef: np.ndarray | None) -> str | None:
    """A warning when the RINEX approximate position lies more than 10 km from the ENU origin
    (nothing when the file gives no usable approximate position)."""
    if approx_position_ecef is None:
        return None
    approx = np.asarray(approx_position_ecef, dtype=float)
    if RECEIVER_RADIUS.outside(np.linalg.norm(approx)):  # NaN, zeros or no place on Earth
        return None
    distance = float(np.linalg.norm(enu.ecef_to_enu(approx)[:2]))
    if distance <= ORIGIN_TOLERANCE_M:
        return None
    return (
        f"origin: the RINEX approximate position is {distance / 1000:.1f} km from the manifest's "
        "origin (lat_deg, lon_deg); check the origin"
    )


def check_standstill_is_still(
    interval: tuple[float, float], t: np.ndarray, speed: np.ndarray, source: str
) -> None:
    """Raise when the speed inside a standstill interval given by hand shows the vehicle moving
    (median above ``STANDSTILL_MAX_MEDIAN_SPEED_MPS``); nothing when no sample falls inside."""
    t0, t1 = interval
    inside = np.asarray(speed, dtype=float)[(np.asarray(t) >= t0) & (np.asarray(t) <= t1)]
    inside = inside[np.isfinite(inside)]
    if inside.size == 0:
        return
    median = mad(inside, centre=False)  # the median speed magnitude
    if median > STANDSTILL_MAX_MEDIAN_SPEED_MPS:
        raise InputError(
            f"standstill {t0:.2f}–{t1:.2f} s: the {source} shows the vehicle moving there (median "
            f"{median:.2f} m/s, up to {np.max(np.abs(inside)):.2f} m/s; a standstill is at most "
            f"{STANDSTILL_MAX_MEDIAN_SPEED_MPS} m/s); give a still interval or use --straight"
        )
