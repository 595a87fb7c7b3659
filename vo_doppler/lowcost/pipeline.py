"""The low-cost path-mapping chain of [KZ] end to end: align → combine (Eq. 7) → de-bias
(Eq. 5–6) → threshold (Eq. 9) → GPS reconstruction (Eq. 10–14) → dead reckoning (Eq. 15–17) →
drift table.

Our additions to [KZ], stated: the standstill interval is found from a speed (wheel, GPS, or
the reconstructed track) when not given; ε0 is averaged over the last τ seconds of it (closest to
the drive); steps inside the standstill are set to zero; when no threshold is given, h is three
times the standard deviation of the de-biased combined standstill rate.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame
from vo_doppler.lowcost.dead_reckoning import (
    DeadReckoning,
    dead_reckon,
    track_yaw,
)
from vo_doppler.lowcost.drift import (
    VARIANTS,
    DriftRow,
    closed_loop_gap,
    drift_rate_deg_per_min,
    heading_error,
)
from vo_doppler.lowcost.gps_reconstruction import ReconstructedTrack, reconstruct_track
from vo_doppler.lowcost.gyro_combination import KChoices, choose_k, combine_rates
from vo_doppler.lowcost.rate_alignment import AlignedRates, align_rates
from vo_doppler.lowcost.series import SeriesReport, clean_series
from vo_doppler.lowcost.static_bias import (
    AllanDeviation,
    allan_deviation,
    choose_tau,
    detect_standstill,
    remove_bias,
    static_bias,
)
from vo_doppler.lowcost.threshold_filter import threshold_filter
from vo_doppler.model.timeseries import increments

log = logging.getLogger(__name__)

MOVING_SPEED_MPS = 2.0
SPEED_WINDOW_S = 5.0


@dataclass(frozen=True)
class DeadReckonConfig:
    """Choices of the chain; ``None`` means "propose it from the data".

    ``standstill_s`` is the interval (s) over which k and ε0 are estimated. With
    ``window_is_standstill=False`` it is instead a stretch of straight constant-course driving
    (a proxy when the record has no standstill): the vehicle moves there, so its GPS steps are
    kept.
    """

    k: float | None = None
    tau_s: float | None = None
    standstill_s: tuple[float, float] | None = None
    threshold_rad_s: float | None = None
    """h of [KZ] Eq. 9; None: 3σ of the de-biased standstill rate."""
    downsample: int = 1
    cluster_m: float = 3.0
    standstill_max_speed_mps: float = 0.2
    standstill_min_s: float = 5.0
    drift_window_s: float = 5.0
    zero_steps_at_standstill: bool = True
    window_is_standstill: bool = True


@dataclass(frozen=True)
class Reference:
    """A reference yaw history (rad, CCW from east) for the drift table, e.g. ground truth."""

    t: np.ndarray
    yaw: np.ndarray
    source: str = "reference"

    def at(self, t: np.ndarray) -> np.ndarray:
        return np.interp(t, self.t, np.unwrap(self.yaw), left=np.nan, right=np.nan)


def smoothed_track_speed(t: np.ndarray, east: np.ndarray, north: np.ndarray) -> np.ndarray:
    """Speed (m/s) at each point from the distance travelled over ``SPEED_WINDOW_S`` around it."""
    distance = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(east), np.diff(north)))])
    half = SPEED_WINDOW_S / 2.0
    ahead = np.interp(t + half, t, distance)
    behind = np.interp(t - half, t, distance)
    span = np.minimum(t + half, t[-1]) - np.maximum(t - half, t[0])
    return np.where(span > 0, (ahead - behind) / np.where(span > 0, span, 1.0), 0.0)


def _standstills(config, track_t, track_enu, speed):
    """The standstill used for k and ε0 (given, else the longest found) and all standstills."""
    if speed is None:
        speed = (track_t, smoothed_track_speed(track_t, track_enu[:, 0], track_enu[:, 1]))
        source = "reconstructed GPS track"
    else:
        source = "given speed"
    found = detect_standstill(
        speed[0], speed[1], config.standstill_max_speed_mps, config.standstill_min_s
    )
    if config.standstill_s is not None:
        t0, t1 = (float(v) for v in config.standstill_s)
        if t1 <= t0:
            raise InputError(f"standstill interval must end after it starts: {t0}, {t1}")
        others = [iv for iv in found if iv[1] < t0 or iv[0] > t1]
        if not config.window_is_standstill:
            return (t0, t1), others
        return (t0, t1), sorted([(t0, t1), *others])
    if not found:
        raise InputError(
            f"no standstill of ≥ {config.standstill_min_s} s at ≤ "
            f"{config.standstill_max_speed_mps} m/s found from the {source}; give the interval"
        )
    longest = max(found, key=lambda iv: iv[1] - iv[0])
    log.info("standstill %.2f–%.2f s found from the %s", *longest, source)
    return longest, found


def _standstill_knots(t: np.ndarray, intervals) -> np.ndarray:
    """Indices of the first and last fix inside each standstill interval."""
    knots = []
    for t0, t1 in intervals:
        inside = np.flatnonzero((t >= t0) & (t <= t1))
        if inside.size:
            knots += [int(inside[0]), int(inside[-1])]
    return np.asarray(knots, dtype=int)


def _gps_reference(t, track_enu, speed_mps) -> np.ndarray:
    yaw = track_yaw(track_enu[:, 0], track_enu[:, 1])
    yaw[speed_mps < MOVING_SPEED_MPS] = np.nan
    valid = np.flatnonzero(np.isfinite(yaw))
    if valid.size < 2:
        raise InputError("the GPS track never moves fast enough to give a reference course")
    # A parked vehicle keeps the course it drives off with: hold the nearest moving course.
    return np.interp(np.arange(len(t)), valid, np.unwrap(yaw[valid]))


def variant_rates(combined, omega1, omega2, eps0_combined, h) -> dict[str, np.ndarray]:
    """The six rate histories of the drift table (Table 1 layout)."""
    debiased = remove_bias(combined, eps0_combined)
    return dict(
        zip(
            VARIANTS,
            (
                omega1,
                omega2,
                combined,
                threshold_filter(combined, h),
                debiased,
                threshold_filter(debiased, h),
            ),
            strict=True,
        )
    )


@dataclass(frozen=True)
class PreparedTrack:
    """The cleaned fixes in ENU, the reconstructed track, and the standstills."""

    report: SeriesReport
    frame: EnuFrame
    raw_enu: np.ndarray
    track: ReconstructedTrack
    track_enu: np.ndarray
    standstill: tuple[float, float]
    standstills: list[tuple[float, float]]
    raw_t: np.ndarray | None = None
    """Times (s) of the cleaned fixes ``raw_enu``."""


def _prepare_track(fixes, config: DeadReckonConfig, speed) -> PreparedTrack:
    """Clean the fixes, find the standstills, and reconstruct with knots at their ends."""
    fix_t, latlon, report = clean_series(
        fixes[0], np.column_stack([fixes[1], fixes[2]]), "GPS fixes"
    )
    lat, lon = latlon[:, 0], latlon[:, 1]
    frame = EnuFrame(float(lat[0]), float(lon[0]), 0.0)

    def enu(lat_rad, lon_rad):
        return frame.geodetic_to_enu(lat_rad, lon_rad, 0.0)[:, :2]

    first = reconstruct_track(fix_t, lat, lon, config.downsample, config.cluster_m)
    standstill, standstills = _standstills(config, first.t, enu(first.lat, first.lon), speed)
    knots = _standstill_knots(fix_t, standstills)
    track = reconstruct_track(fix_t, lat, lon, config.downsample, config.cluster_m, knots)
    return PreparedTrack(
        report,
        frame,
        enu(lat, lon),
        track,
        enu(track.lat, track.lon),
        standstill,
        standstills,
        fix_t,
    )


@dataclass(frozen=True)
class BiasModel:
    """k, the combined rate, Allan deviations, τ, ε0 per series and the threshold h."""

    k_choices: KChoices
    k: float
    combined: np.ndarray
    allan: dict[str, AllanDeviation]
    tau: float
    eps0: dict[str, float]
    h: float


def _bias_model(rates: AlignedRates, standstill, config: DeadReckonConfig) -> BiasModel:
    """k ([KZ] Eq. 7), the Allan deviations, τ, ε0 (Eq. 5) and the threshold h over the
    standstill."""
    still = (rates.t >= standstill[0]) & (rates.t <= standstill[1])
    if np.sum(still) < 10:
        raise InputError(
            f"only {int(np.sum(still))} gyro samples inside the standstill "
            f"{standstill[0]:.3f}–{standstill[1]:.3f} s"
        )
    k_choices = choose_k(rates.t[still], rates.omega1[still], rates.omega2[still])
    k = k_choices.sweep.k if config.k is None else float(config.k)
    combined = combine_rates(rates.omega1, rates.omega2, k)
    series = {"sensor 1": rates.omega1, "sensor 2": rates.omega2, "combined": combined}
    allan = {
        name: allan_deviation(values[still], rates.report1.rate_hz)
        for name, values in series.items()
    }
    choice = choose_tau(
        config.tau_s, allan["combined"], standstill[1] - standstill[0], config.window_is_standstill
    )
    log.info("%s", choice.reason)
    tau = choice.tau
    window = (standstill[1] - tau, standstill[1])
    eps0 = {name: static_bias(rates.t, values, *window).eps0 for name, values in series.items()}
    if config.threshold_rad_s is None:
        h = 3.0 * float(np.std(remove_bias(combined[still], eps0["combined"])))
    else:
        h = float(config.threshold_rad_s)
    return BiasModel(k_choices, k, combined, allan, tau, eps0, h)


INITIAL_FIT_S = 10.0
"""Seconds of moving track, from the first, whose shape fits the initial heading when no
straight stretch is given (the gyro's drift over them is far below the fit's σ)."""
MIN_FIT_PATH_M = 5.0
"""Less track than this over the fit's span gives no direction: the first course instead."""


@dataclass(frozen=True)
class InitialHeading:
    """The dead reckoning's initial yaw (rad, CCW from east) and its σ (rad; NaN when taken
    from a single course), fitted over the GPS fixes of ``t0``–``t1`` (``fixes`` of them)."""

    yaw: float
    sigma: float
    t0: float
    t1: float
    fixes: int

    def to_dict(self) -> dict:
        """Degrees, course clockwise from north, for people."""
        return {
            "course_deg": float(np.mod(90.0 - np.degrees(self.yaw), 360.0)),
            "sigma_deg": float(np.degrees(self.sigma)),
            "t0_s": self.t0,
            "t1_s": self.t1,
            "fixes": self.fixes,
        }


def fit_initial_heading(
    t: np.ndarray, track: np.ndarray, shape: np.ndarray, span: tuple[float, float]
) -> InitialHeading | None:
    """The rotation about the vertical that best lays the dead-reckoned path ``shape`` (N, 2,
    east/north, started facing east: yaw 0) onto the GPS ``track`` (N, 2) over the epochs
    ``t`` inside ``span``: the least-squares rotation of the centred points (2-D Procrustes),

        ψ₀ = atan2(Σ d_i × g_i, Σ d_i · g_i),    σ_ψ² = s² / Σ |d_i|²,
        s² = Σ |g_i − R(ψ₀) d_i|² / (2n − 3)

    (d, g the centred shape and track points, s² the fixes' scatter per axis about the fitted
    path, 2n − 3 its degrees of freedom after the translation and the angle), Σ |d_i|² counted
    once per second (a receiver's fixes share its position filter's errors over about a
    second: ten 10-Hz fixes are one measurement, not ten). The path's own
    turns enter through the gyro, so the span need not be straight; its length pins ψ₀: 0.1 m
    of scatter over 50 m of path is 0.1°. None with fewer than three epochs or less than
    ``MIN_FIT_PATH_M`` of path in the span."""
    inside = (t >= span[0]) & (t <= span[1])
    n = int(inside.sum())
    if n < 3:
        return None
    d = shape[inside] - shape[inside].mean(axis=0)
    g = track[inside] - track[inside].mean(axis=0)
    if 2.0 * float(np.max(np.hypot(d[:, 0], d[:, 1]))) < MIN_FIT_PATH_M:
        return None
    spread = float(np.sum(d**2))
    yaw = float(np.arctan2(np.sum(d[:, 0] * g[:, 1] - d[:, 1] * g[:, 0]), np.sum(d * g)))
    c, s_ = np.cos(yaw), np.sin(yaw)
    fitted = d @ np.array([[c, s_], [-s_, c]])
    scatter = float(np.sum((g - fitted) ** 2)) / max(2 * n - 3, 1)
    independent = min(n, max(int(t[inside][-1] - t[inside][0]), 1) + 1)
    spread *= independent / n
    return InitialHeading(
        yaw, float(np.sqrt(scatter / spread)), float(t[inside][0]), float(t[inside][-1]), n
    )


@dataclass
class DeadReckonResult:
    """Everything the chain computed, for tables, files and figures."""

    rates: AlignedRates
    prepared: PreparedTrack
    model: BiasModel
    reference_source: str
    config: DeadReckonConfig
    trajectories: dict[str, DeadReckoning] = field(default_factory=dict)
    rows: list[DriftRow] = field(default_factory=list)
    selected: str = "combined + ε0 removed"
    initial_heading: InitialHeading | None = None
    """How the dead reckoning was started (None: from the first GPS course alone)."""

    @property
    def selected_trajectory(self) -> DeadReckoning:
        return self.trajectories[self.selected]


def run_deadreckon(
    gyro1: tuple[np.ndarray, np.ndarray],
    gyro2: tuple[np.ndarray, np.ndarray],
    fixes: tuple[np.ndarray, np.ndarray, np.ndarray],
    config: DeadReckonConfig | None = None,
    speed: tuple[np.ndarray, np.ndarray] | None = None,
    reference: Reference | None = None,
) -> DeadReckonResult:
    """Run the chain. ``gyro1``/``gyro2`` are (t, yaw rate rad/s CCW); ``fixes`` are
    (t, lat rad, lon rad); ``speed`` optional (t, m/s) for standstill detection; ``reference``
    optional yaw for the drift table (default: the course of the reconstructed GPS track)."""
    config = config or DeadReckonConfig()
    rates = align_rates(*gyro1, *gyro2)
    prepared = _prepare_track(fixes, config, speed)
    track, track_enu = prepared.track, prepared.track_enu
    model = _bias_model(rates, prepared.standstill, config)

    in_gyro = (track.t >= rates.t[0]) & (track.t <= rates.t[-1])
    if np.sum(in_gyro) < 2:
        raise InputError("fewer than 2 GPS fixes fall inside the gyro record")
    epochs = track.t[in_gyro]
    steps = track.step_lengths()[in_gyro[:-1] & in_gyro[1:]]
    if config.zero_steps_at_standstill:
        inside = np.zeros(len(epochs), dtype=bool)
        for t0, t1 in prepared.standstills:
            inside |= (epochs >= t0) & (epochs <= t1)
        steps = np.where(inside[:-1] & inside[1:], 0.0, steps)
    epoch_enu = track_enu[in_gyro]

    speed_at = smoothed_track_speed(track.t, track_enu[:, 0], track_enu[:, 1])[in_gyro]
    if reference is None:
        reference_yaw = _gps_reference(epochs, epoch_enu, speed_at)
        source = "reconstructed GPS course"
    else:
        reference_yaw = reference.at(epochs)
        source = reference.source
    valid = np.isfinite(reference_yaw)
    if np.sum(valid) < 2:
        raise InputError(f"the {source} covers fewer than 2 dead-reckoning epochs")

    result = DeadReckonResult(rates, prepared, model, source, config)
    if config.threshold_rad_s is not None:
        result.selected = "combined + ε0 removed + threshold"
    start = (float(epoch_enu[0, 0]), float(epoch_enu[0, 1]))
    rates_by_variant = variant_rates(
        model.combined, rates.omega1, rates.omega2, model.eps0["combined"], model.h
    )
    # The start comes from the GPS track, never from the reference (a ground truth scores the
    # result; it must not start it): the rotation that lays the path's first seconds onto the
    # fixes, over the straight stretch when one is given.
    shape = dead_reckon(
        epochs, steps, increments(rates.t, rates_by_variant[result.selected], epochs, "hold"), 0.0
    )
    moving = epochs[speed_at >= MOVING_SPEED_MPS]
    span = (epochs[0], epochs[0])
    if config.standstill_s is not None and not config.window_is_standstill:
        span = config.standstill_s
    elif moving.size:
        span = (moving[0], moving[0] + INITIAL_FIT_S)
    fix_t = prepared.raw_t
    shape_en = np.column_stack([np.interp(fix_t, epochs, v) for v in (shape.east, shape.north)])
    result.initial_heading = fit_initial_heading(fix_t, prepared.raw_enu, shape_en, span)
    if result.initial_heading is not None:
        yaw0 = result.initial_heading.yaw
    else:
        gps_yaw = (
            reference_yaw if reference is None else _gps_reference(epochs, epoch_enu, speed_at)
        )
        yaw0 = float(gps_yaw[np.flatnonzero(np.isfinite(gps_yaw))[0]])
    for name, rate in rates_by_variant.items():
        dr = dead_reckon(
            epochs, steps, increments(rates.t, rate, epochs, outside="hold"), yaw0, start
        )
        error = heading_error(dr.yaw[valid], reference_yaw[valid])
        result.trajectories[name] = dr
        result.rows.append(
            DriftRow(
                name,
                drift_rate_deg_per_min(epochs[valid], error, config.drift_window_s),
                float(np.degrees(error[-1])),
                closed_loop_gap(dr.east, dr.north, epoch_enu),
            )
        )
    return result
