"""The main job on one recording: GNSS → calibration and tight heading → VO → correction.

Stages (docs/design.md, "The main job"):

1. GNSS: SPP positions and the conventional Doppler velocity ([TK18] sec. 3.2) with the
   Doppler rows behind it.
2. Calibration ([TK18] sec. 3.3–3.4) and the tightly coupled heading ([TK18] sec. 3.5), epoch
   by epoch: the wheel scale and gyro bias current at each epoch, the heading of every epoch's
   window.
3. VO on the images with metric steps from the calibrated wheel speed; its camera poses become
   vehicle poses once (:func:`vo_doppler.vo.frames.vehicle_trajectory`).
4. Heading correction of the VO by the tightly coupled heading (the adaptive blend by default,
   [TK18] Eq. 11–13 on request); the conventional heading gives a second corrected trajectory.
5. A dead-reckoning trajectory ([KZ] Eq. 15–17) from the calibrated wheel speed and gyro,
   corrected the same way.

All trajectories are vehicle poses (x forward, y left, z up) in the sequence's ENU frame, on GPS
time. A recording without a camera runs every pipeline that needs none; one without GNSS (an
imported KITTI raw drive) runs the VO and the dead reckoning alone (:func:`run_without_gnss`).
An absolute heading from elsewhere (:class:`GivenHeading`, ``run --heading FILE``) replaces
stage 2's, on a recording with or without GNSS (:func:`run_with_given_heading`).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from enum import StrEnum
from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.checks import check_vehicle_overlap, check_yaw_rate_unit, origin_warning
from vo_doppler.choices import checked_letters
from vo_doppler.errors import InputError
from vo_doppler.fusion.correction import (
    CorrectionConfig,
    absolute_heading,
    conventional_absolute_heading,
    correct,
    tight_absolute_heading,
    usable_tight_heading,
)
from vo_doppler.fusion.placement import (  # noqa: F401 (INITIAL_HEADING_SPAN_S, yaw_offset: API)
    INITIAL_HEADING_SPAN_S,
    initial_yaw_offset,
    yaw_offset,
)
from vo_doppler.geo import EnuFrame
from vo_doppler.gnss.pipeline import GnssVelocityResult, check_elevation_mask, gnss_velocity
from vo_doppler.gnss.receiver_track import smoothed_track
from vo_doppler.gnss.spp import EARTH_SURFACE_M, nearest_time
from vo_doppler.heading.from_gnss import heading_from_gnss
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.lowcost.dead_reckoning import wheel_gyro_track
from vo_doppler.memory import release_free_heap
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.signals import DEFAULT_SYSTEMS, SatelliteSystem
from vo_doppler.model.timeseries import time_grid
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.vo.config import VoConfig
from vo_doppler.vo.frames import vehicle_trajectory

if TYPE_CHECKING:
    from vo_doppler.vo.batch import VoOutput

log = logging.getLogger(__name__)


class Pipeline(StrEnum):
    """The trajectories of a run (their values are the file and summary keys)."""

    VO = "vo"
    VO_GPS_CONV = "vo_gps_conv"
    VO_GPS_TC = "vo_gps_tc"
    DR = "dr"
    DR_GPS_CONV = "dr_gps_conv"
    DR_GPS_TC = "dr_gps_tc"


@dataclass
class RunConfig:
    """Everything :func:`run_sequence` can be told (SI units, radians)."""

    systems: str = DEFAULT_SYSTEMS
    """RINEX letters of the GNSS systems used (:class:`SatelliteSystem`)."""
    elevation_mask_rad: float = np.radians(10.0)
    heading: HeadingPipelineConfig = field(default_factory=HeadingPipelineConfig.auto)
    """The heading stage's settings; by default ``--heading-method auto``'s (robust below
    10 Hz GNSS, snooping from 10 Hz)."""
    vo: VoConfig = field(default_factory=VoConfig)
    correction: CorrectionConfig = field(default_factory=CorrectionConfig)
    dead_reckoning_rate_hz: float = 20.0

    def __post_init__(self) -> None:
        """Refuse values out of their domain now (an :class:`~vo_doppler.errors.InputError`
        naming the field), not as an empty result later: a mask of 10 (degrees given for
        radians) removes every satellite and leaves no heading, silently."""
        checked_letters(SatelliteSystem, self.systems, "RunConfig.systems")
        check_elevation_mask(self.elevation_mask_rad, "RunConfig.elevation_mask_rad")
        rate = self.dead_reckoning_rate_hz
        if not (isinstance(rate, (int, float, np.number)) and math.isfinite(rate) and rate > 0):
            raise InputError(f"RunConfig.dead_reckoning_rate_hz = {rate!r}: expected a rate > 0 Hz")

    def for_sequence(self, sequence: Sequence) -> RunConfig:
        """The settings a run of ``sequence`` applies: the heading stage's for its GNSS rate
        (:meth:`~vo_doppler.heading.pipeline.HeadingPipelineConfig.for_rate`), so that the
        report shows what ran, not ``auto``."""
        if not sequence.has_gnss:
            return self
        return replace(self, heading=self.heading.for_rate(sequence.observations.epoch_time))


@dataclass
class RunResult:
    gnss: GnssVelocityResult | None
    """None for a recording without GNSS (so is ``heading``)."""
    heading: HeadingTable | None
    vo: VoOutput | None
    """None for a recording without a camera."""
    calibrated_speed: SensorSeries
    trajectories: dict[Pipeline, Trajectory]
    """Vehicle poses in ENU."""
    antenna: AntennaTrack
    """The antenna positions that placed the trajectories."""
    tc_usable: np.ndarray
    """Epochs whose tightly coupled heading was allowed to correct."""
    warnings: list[str] = field(default_factory=list)
    """What the checks found doubtful in the inputs and the calibration (each also logged):
    the origin against the RINEX approximate position, then the heading stage's
    (``heading.warnings``)."""
    heading_source: str = ""
    """Where ``heading`` came from, in words, when it was given (:class:`GivenHeading`);
    empty when the heading stage computed it from GNSS."""


@dataclass(frozen=True)
class AntennaTrack:
    """Where the trajectories are placed: the GNSS antenna's ENU positions ``position`` (N, 3, m)
    at the GPS times ``t`` (N,) of the valid SPP fixes; ``t`` empty with one untimed position
    (no fix: the RINEX approximate position or the origin). Heights come only from the positions
    whose ``height_sigma`` (N,, m; None: all) is at most ``PLACEMENT_VERTICAL_SIGMA_M``; without
    any, from the sequence origin (the first pose at up 0). ``height_source`` says which, in
    words, for the report."""

    t: np.ndarray
    position: np.ndarray
    height_sigma: np.ndarray | None = None
    height_source: str = "the antenna positions"

    @property
    def height_rows(self) -> np.ndarray:
        """Indices of the positions whose heights may place a trajectory."""
        if self.height_sigma is None:
            return np.arange(len(self.position))
        return np.flatnonzero(
            np.nan_to_num(self.height_sigma, nan=np.inf) <= PLACEMENT_VERTICAL_SIGMA_M
        )


PLACEMENT_VERTICAL_SIGMA_M = 5.0
"""Largest vertical σ (m) of a valid fix whose height may place the trajectories. A street
canyon's fixes are worst in height (the satellites left are high, their reflections all
delays): the sample's valid fixes lay 46 m above the road, the Hong Kong drive's 14 m at the
median with σ_u 14 m; a fix this good is a better height than the origin's guess, a worse one
is not."""
ORIGIN_HEIGHT = (
    "the sequence origin (no valid fix with a vertical σ of at most {limit:g} m): the first "
    "pose at its height"
)


def _height_sigma(spp: SppSolution, rows: np.ndarray) -> tuple[np.ndarray, str]:
    """σ_u (m) of the fixes ``rows`` (inf where unknown) and what places the heights."""
    sigma = np.full(rows.size, np.inf)
    if spp.vertical_sigma_m is not None:
        sigma = np.nan_to_num(spp.vertical_sigma_m[rows], nan=np.inf)
    good = sigma <= PLACEMENT_VERTICAL_SIGMA_M
    if not good.any():
        return sigma, ORIGIN_HEIGHT.format(limit=PLACEMENT_VERTICAL_SIGMA_M)
    return sigma, (
        f"the valid fixes with a vertical σ of at most {PLACEMENT_VERTICAL_SIGMA_M:g} m "
        f"({good.sum()} of {rows.size}; median σ_u {np.median(sigma[good]):.1f} m), their "
        "inverse-variance weighted median"
    )


def antenna_track(
    spp: SppSolution,
    velocity: VelocitySolution,
    approx_position: np.ndarray | None,
    enu: EnuFrame,
) -> AntennaTrack:
    """The antenna's positions that place every trajectory (:func:`level_with_yaw`).

    At the epochs of the valid SPP fixes, the fixes smoothed along the final Doppler velocities
    (:func:`vo_doppler.gnss.receiver_track.smoothed_track`, robust: Huber, then Cauchy
    weights, so that one bad fix among its neighbours barely moves the track). Only there: an
    epoch without a fix would be the fixes carried to it by the Doppler velocities, which in a
    street canyon (few satellites, reflections) drift by tens of metres over seconds; the
    trajectory itself carries the fixes back to its start. With one valid fix, that fix;
    without any, ``approx_position`` (ECEF, the RINEX header's), else the ENU origin (untimed,
    with a warning).
    """
    valid = np.flatnonzero(spp.valid)
    if valid.size >= 2:
        fixes = np.where(spp.valid[:, None], spp.position_ecef, np.nan)
        known = velocity.valid
        if velocity.untestable is not None:
            known = known | velocity.untestable
        track = smoothed_track(
            spp.t, fixes, spp.horizontal_sigma_m, velocity.velocity_ecef, velocity.covariance, known
        )
        if track is not None:
            sigma, source = _height_sigma(spp, valid)
            return AntennaTrack(spp.t[valid], enu.ecef_to_enu(track[valid]), sigma, source)
    if valid.size:
        sigma, source = _height_sigma(spp, valid)
        return AntennaTrack(spp.t[valid], enu.ecef_to_enu(spp.position_ecef[valid]), sigma, source)
    origin = ORIGIN_HEIGHT.format(limit=PLACEMENT_VERTICAL_SIGMA_M)
    approx = np.asarray(approx_position if approx_position is not None else np.nan, dtype=float)
    if np.all(np.isfinite(approx)) and np.linalg.norm(approx) > EARTH_SURFACE_M:
        log.warning("no SPP fix: the trajectories start at the RINEX approximate position")
        return AntennaTrack(
            np.zeros(0), enu.ecef_to_enu(approx.reshape(1, 3)), np.full(1, np.inf), origin
        )
    log.warning("no SPP fix and no approximate position: the trajectories start at the origin")
    return AntennaTrack(np.zeros(0), np.zeros((1, 3)), np.full(1, np.inf), origin)


PLACEMENT_SPAN_S = 60.0
"""Seconds of antenna positions, from the first inside a trajectory, that place it. A street
canyon's fixes are off by tens of metres for seconds at a time (reflections), while a
trajectory carries a fix back with its own drift, a few metres per minute even for the VO
alone. First DR pose against the truth, 5 s → 60 s: the sample 48.7 → 4.1 m (its first
five seconds of fixes lie 49 m off, the rest 4–5 m), the 60-s NLOS drive 20.3 → 16.0 m,
comma2k19 0.7 → 0.6 m, the clean 120-s drives 3.2 → 4.0 and 0.9 → 0.9 m."""
PLACEMENT_MIN_FIXES = 5
"""At least this many antenna positions place a trajectory (if it has them), however long."""


def level_with_yaw(
    trajectory: Trajectory,
    turn: float,
    antenna: AntennaTrack,
    lever_arm_m: tuple[float, float, float] = (0.0, 0.0, 0.0),
) -> Trajectory:
    """Rotate vehicle poses (first-vehicle frame) about z by ``turn`` (rad), then move them by
    the median, per axis, of (antenna position − the trajectory's antenna) over the antenna
    positions of the first ``PLACEMENT_SPAN_S`` seconds inside the trajectory's times (at least
    ``PLACEMENT_MIN_FIXES``): each fix is carried back to the start along the trajectory
    itself, the vehicle placed where it was then, not where it was seconds later, and one bad
    fix cannot move it. The height likewise, from the positions whose heights are good
    (``AntennaTrack.height_rows``: valid fixes with a small vertical σ), their inverse-variance
    weighted median; without any, the first pose at the sequence origin's height (up 0). The
    trajectory's antenna at a fix's time: its position interpolated
    there plus the lever arm (``lever_arm_m`` from the vehicle's origin, x forward, y left,
    z up) turned by its pose nearest in time. Without an antenna position inside, the one
    nearest in time places the trajectory's nearest end (with a warning); an untimed one, the
    first pose.
    """
    rotation = np.eye(4)
    rotation[:3, :3] = Rotation.from_euler("z", turn).as_matrix()
    out = rotation @ trajectory.matrices
    t = trajectory.t
    if not antenna.t.size:
        shift = antenna.position[0] - out[0, :3, 3]
        if not antenna.height_rows.size:
            shift[2] = -out[0, 2, 3]
        out[:, :3, 3] += shift
        return Trajectory.from_matrices(t, out)
    lever = np.asarray(lever_arm_m, dtype=float)
    rows = _placing_rows(antenna.t, np.arange(antenna.t.size), t, warn=True)
    shift = np.median(antenna.position[rows] - _carried(out, t, antenna.t[rows], lever), axis=0)
    heights = antenna.height_rows
    if heights.size:
        rows = _placing_rows(antenna.t, heights, t, warn=False)
        carried = _carried(out, t, antenna.t[rows], lever)[:, 2]
        weight = np.ones(rows.size)
        if antenna.height_sigma is not None:
            weight = np.maximum(antenna.height_sigma[rows], 1e-3) ** -2.0
        shift[2] = weighted_median(antenna.position[rows, 2] - carried, weight)
    else:
        shift[2] = -out[0, 2, 3]
    out[:, :3, 3] += shift
    return Trajectory.from_matrices(t, out)


def _placing_rows(t_fix: np.ndarray, rows: np.ndarray, t: np.ndarray, warn: bool) -> np.ndarray:
    """Of the antenna positions ``rows`` (times ``t_fix[rows]``), those of the first
    ``PLACEMENT_SPAN_S`` seconds inside the trajectory's times ``t`` (at least
    ``PLACEMENT_MIN_FIXES``); without any inside, the nearest in time (with a warning if
    ``warn``)."""
    outside_s = np.maximum(t[0] - t_fix[rows], t_fix[rows] - t[-1])
    inside = rows[outside_s <= 0.0]
    if inside.size:
        span = t_fix[inside] <= t_fix[inside[0]] + PLACEMENT_SPAN_S
        return inside[: max(int(span.sum()), PLACEMENT_MIN_FIXES)]
    nearest = int(np.argmin(outside_s))
    if warn:
        log.warning(
            "no GNSS fix within the trajectory from %.1f to %.1f s: it is placed by the antenna "
            "position %.1f s outside it",
            t[0],
            t[-1],
            outside_s[nearest],
        )
    return rows[[nearest]]


def _carried(poses: np.ndarray, t: np.ndarray, t_fix: np.ndarray, lever: np.ndarray):
    """The trajectory's antenna (position interpolated at ``t_fix`` plus the lever arm turned
    by the pose nearest in time), (M, 3)."""
    t_fix = np.clip(t_fix, t[0], t[-1])
    carried = np.column_stack([np.interp(t_fix, t, poses[:, axis, 3]) for axis in range(3)])
    return carried + poses[nearest_time(t, t_fix), :3, :3] @ lever


def weighted_median(values: np.ndarray, weights: np.ndarray) -> float:
    """The value at which the cumulative weight of the sorted ``values`` reaches half of the
    total (the lower one on a tie): the median when the weights are equal and unmoved by values
    holding less than half of the weight, however far off."""
    order = np.argsort(values, kind="stable")
    cumulative = np.cumsum(weights[order])
    return float(values[order][np.searchsorted(cumulative, 0.5 * cumulative[-1])])


def correct_all(
    sequence: Sequence,
    table: HeadingTable,
    vo_vehicle: Trajectory | None,
    speed: SensorSeries,
    antenna: AntennaTrack,
    config: RunConfig,
    yaw_rate: SensorSeries | None = None,
    tight_source: str = "tc",
) -> dict[Pipeline, Trajectory]:
    """The VO and the wheel + gyro dead reckoning, each alone and corrected by the conventional
    and by the tightly coupled heading (vehicle poses, ENU).

    Every trajectory is turned to the absolute headings of its first seconds
    (:func:`initial_yaw_offset`) and placed by the antenna track (:func:`level_with_yaw`). Only
    usable tightly coupled headings correct the tightly coupled pipelines (``tight_source``
    "tc"; "tc+conv" for a table without them, the conventional ones). The dead reckoning
    integrates ``yaw_rate`` (default: the sequence's, less the table's gyro bias).
    """
    if yaw_rate is None:
        yaw_rate = table.calibrated_yaw_rate(sequence.yaw_rate)
    begin, end = max(speed.t[0], yaw_rate.t[0]), min(speed.t[-1], yaw_rate.t[-1])
    if vo_vehicle is not None:
        begin, end = max(begin, vo_vehicle.t[0]), min(end, vo_vehicle.t[-1])
    t_dr = time_grid(begin, end, 1.0 / config.dead_reckoning_rate_hz)
    dr = wheel_gyro_track(speed, yaw_rate, t_dr) if len(t_dr) > 1 else None
    usable = usable_tight_heading(table, config.correction.tc_max_sigma_rad)
    tight = (
        tight_absolute_heading(table, config.correction)
        if tight_source == "tc"
        else absolute_heading(table, tight_source, config.correction)
    )
    conventional = conventional_absolute_heading(table)
    lever = sequence.antenna_lever_arm_m
    reference = config.correction.reference
    trajectories: dict[Pipeline, Trajectory] = {}
    if vo_vehicle is not None:
        vo_level = level_with_yaw(
            vo_vehicle,
            initial_yaw_offset(table, usable, vo_vehicle, reference=reference),
            antenna,
            lever,
        )
        trajectories[Pipeline.VO] = vo_level
        trajectories[Pipeline.VO_GPS_CONV] = correct(
            vo_level, conventional, config.correction
        ).vehicle
        trajectories[Pipeline.VO_GPS_TC] = correct(vo_level, tight, config.correction).vehicle
    if dr is not None:
        dr_level = level_with_yaw(
            dr, initial_yaw_offset(table, usable, dr, reference=reference), antenna, lever
        )
        trajectories[Pipeline.DR] = dr_level
        trajectories[Pipeline.DR_GPS_CONV] = correct(
            dr_level, conventional, config.correction
        ).vehicle
        trajectories[Pipeline.DR_GPS_TC] = correct(dr_level, tight, config.correction).vehicle
    return trajectories


def sequence_gnss(
    sequence: Sequence, config: RunConfig, fit_noise: bool = False
) -> GnssVelocityResult:
    """The GNSS stage on a recording: SPP, Doppler rows (weighted by the receiver's reported σ
    where the recording has it, or a σ fitted from the data) and conventional velocities."""
    return gnss_velocity(
        sequence.observations,
        sequence.navigation,
        config.systems,
        config.elevation_mask_rad,
        reported_sigma=sequence.doppler_sigma,
        fit_noise=fit_noise,
    )


def sequence_heading(
    sequence: Sequence,
    rows: DopplerRows,
    velocity: VelocitySolution,
    config: HeadingPipelineConfig,
) -> HeadingTable:
    """The heading stage on a recording's vehicle signals from given Doppler rows and
    conventional velocities (``heading_from_gnss``)."""
    return heading_from_gnss(
        sequence.observations.epoch_time,
        rows,
        velocity,
        sequence.wheel_speed,
        sequence.yaw_rate,
        sequence.enu,
        config,
        sequence.antenna_lever_arm_m,
        sequence.forward_acceleration,
        sequence.vehicle_source,
    )


def sequence_vo(
    sequence: Sequence,
    config: VoConfig,
    speed: SensorSeries,
    on_frame: Callable[[int], None] | None = None,
    images: Iterable[np.ndarray] | None = None,
) -> VoOutput:
    """The VO stage on a recording with a camera, scaled by the calibrated wheel speed; images
    are read from ``sequence.image_paths`` unless given."""
    # OpenCV and pycolmap (about 70 MiB resident) load here, not with the module: a recording
    # without a camera never needs them, and the stages before the VO run without them.
    from vo_doppler.io.images import prefetch_images
    from vo_doppler.vo.batch import run_visual_odometry

    frames = images if images is not None else prefetch_images(sequence.image_paths)
    return run_visual_odometry(
        frames, sequence.image_times, sequence.camera, config, (speed.t, speed.value), on_frame
    )


def vehicle_vo(
    sequence: Sequence,
    config: VoConfig,
    speed: SensorSeries,
    on_frame: Callable[[int], None] | None = None,
    images: Iterable[np.ndarray] | None = None,
) -> tuple[VoOutput | None, Trajectory | None]:
    """:func:`sequence_vo` and its camera poses as vehicle poses, (None, None) for a recording
    without a camera."""
    if not sequence.has_camera:
        return None, None
    vo = sequence_vo(sequence, config, speed, on_frame, images)
    vo_vehicle = vehicle_trajectory(vo.trajectory, sequence.camera.T_vehicle_camera)
    release_free_heap()
    return vo, vo_vehicle


def run_sequence(
    sequence: Sequence,
    config: RunConfig | None = None,
    on_frame: Callable[[int], None] | None = None,
    images: Iterable[np.ndarray] | None = None,
    given: GivenHeading | None = None,
) -> RunResult:
    """Run every stage on a recording. ``images`` replaces reading ``sequence.image_paths``
    (e.g. frames already in memory); ``on_frame`` is called after each VO frame; ``given``,
    an absolute heading from elsewhere, replaces the heading stage
    (:func:`run_with_given_heading`).

    The inputs are checked as ``vo-doppler run`` checks them (:mod:`vo_doppler.checks`):
    vehicle signals whose times miss the GNSS epochs, a yaw rate too large for a car (before
    the GNSS stage) or turning against the GNSS Doppler
    course (after the heading stage, before the VO) raises :class:`InputError`; the rest are
    warnings, logged and returned in ``RunResult.warnings``."""
    config = (config or RunConfig()).for_sequence(sequence)
    if given is not None:
        return run_with_given_heading(sequence, given, config, on_frame, images)
    if not sequence.has_gnss:
        return run_without_gnss(sequence, config, on_frame, images)
    obs = sequence.observations
    check_vehicle_overlap(
        sequence.wheel_speed, sequence.yaw_rate, obs.epoch_time, sequence.vehicle_source
    )
    check_yaw_rate_unit(sequence.yaw_rate, sequence.wheel_speed, sequence.vehicle_source)
    origin = origin_warning(sequence.enu, obs.header.approx_position)
    if origin:
        log.warning("%s", origin)
    gnss = sequence_gnss(sequence, config)
    release_free_heap()
    table = sequence_heading(sequence, gnss.rows, gnss.velocity, config.heading)
    release_free_heap()
    speed = table.calibrated_speed(sequence.wheel_speed)
    vo, vo_vehicle = vehicle_vo(sequence, config.vo, speed, on_frame, images)
    if vo is None:
        log.warning("%s has no camera: only the non-visual pipelines run", sequence.name)
    antenna = antenna_track(gnss.spp, gnss.velocity, obs.header.approx_position, sequence.enu)
    trajectories = correct_all(sequence, table, vo_vehicle, speed, antenna, config)
    release_free_heap()
    usable = usable_tight_heading(table, config.correction.tc_max_sigma_rad)
    warnings = ([origin] if origin else []) + table.warnings
    return RunResult(gnss, table, vo, speed, trajectories, antenna, usable, warnings)


NO_GNSS = (
    "{name} has no GNSS: only the VO and the wheel + gyro dead reckoning ran (the GNSS "
    "pipelines, VO + GPS and DR + GPS, were not run), with the wheel speed and yaw rate as "
    "recorded (no wheel-scale or gyro-bias calibration) and no absolute heading: the "
    "trajectories start at the ENU origin facing east"
)


def run_without_gnss(
    sequence: Sequence,
    config: RunConfig,
    on_frame: Callable[[int], None] | None = None,
    images: Iterable[np.ndarray] | None = None,
) -> RunResult:
    """:func:`run_sequence` on a recording without GNSS: the VO (scaled by the wheel speed as
    recorded) and the wheel + gyro dead reckoning, each started at the ENU origin facing east
    (the only placement without a fix or an absolute heading); ``gnss`` and ``heading`` are
    None and the warning says which pipelines were not run."""
    check_yaw_rate_unit(sequence.yaw_rate, sequence.wheel_speed, sequence.vehicle_source)
    note = NO_GNSS.format(name=sequence.name)
    log.warning("%s", note)
    speed, yaw_rate = sequence.wheel_speed, sequence.yaw_rate
    vo, vo_vehicle = vehicle_vo(sequence, config.vo, speed, on_frame, images)
    begin, end = max(speed.t[0], yaw_rate.t[0]), min(speed.t[-1], yaw_rate.t[-1])
    if vo_vehicle is not None:
        begin, end = max(begin, vo_vehicle.t[0]), min(end, vo_vehicle.t[-1])
    t_dr = time_grid(begin, end, 1.0 / config.dead_reckoning_rate_hz)
    origin = AntennaTrack(np.zeros(0), np.zeros((1, 3)), None, "the sequence origin (no GNSS)")
    tracks = {Pipeline.VO: vo_vehicle}
    if len(t_dr) > 1:
        tracks[Pipeline.DR] = wheel_gyro_track(speed, yaw_rate, t_dr)
    trajectories = {
        name: level_with_yaw(track, float(-track.yaw()[0]), origin)
        for name, track in tracks.items()
        if track is not None
    }
    return RunResult(None, None, vo, speed, trajectories, origin, np.zeros(0, dtype=bool), [note])


@dataclass(frozen=True)
class GivenHeading:
    """An absolute heading from elsewhere (a dual-antenna receiver, an INS, an earlier run's
    ``heading.csv``) that ``run`` uses instead of computing the tightly coupled heading from
    GNSS: ``table`` as :func:`vo_doppler.io.heading_csv.read_heading_csv` reads it,
    ``source`` (e.g. the file) names it in the summary."""

    table: HeadingTable
    source: str

    @property
    def has_tight(self) -> bool:
        """The table holds a tightly coupled heading (a ``heading.csv``; a minimal heading CSV
        holds its heading as the conventional one)."""
        return bool(self.table.tc_available.any())

    @property
    def has_calibration(self) -> bool:
        """The table holds a wheel scale and gyro bias at every row (a ``heading.csv``)."""
        table = self.table
        return bool(np.isfinite(table.wheel_scale).all() and np.isfinite(table.gyro_bias).all())

    def describe(self) -> str:
        """The summary's ``heading_source``."""
        what = (
            "its tightly coupled heading corrects the tightly coupled pipelines, its "
            "conventional heading the conventional ones"
            if self.has_tight
            else "its heading corrects the tightly coupled pipelines (there are no conventional "
            "ones)"
        )
        calibration = (
            "its wheel scale and gyro bias calibrate the vehicle signals"
            if self.has_calibration
            else "the wheel speed and yaw rate are used as recorded (no calibration)"
        )
        return f"given: {self.source}, not computed from GNSS; {what}; {calibration}"


NO_GNSS_GIVEN = (
    "{name} has no GNSS: the trajectories start at the ENU origin (no fix places them), turned "
    "and corrected by the given heading"
)


def run_with_given_heading(
    sequence: Sequence,
    given: GivenHeading,
    config: RunConfig,
    on_frame: Callable[[int], None] | None = None,
    images: Iterable[np.ndarray] | None = None,
) -> RunResult:
    """:func:`run_sequence` with the absolute heading ``given`` instead of the heading stage.

    The GNSS stage still runs when the recording has GNSS (its fixes place the trajectories);
    without GNSS they start at the ENU origin. The vehicle signals are calibrated by the
    table's wheel scale and gyro bias when it has them (a ``heading.csv``), else used as
    recorded. The tightly coupled pipelines are corrected by the table's usable tightly coupled
    heading, or for a table without one (a minimal heading CSV) by its heading, and then the
    conventional pipelines, which would repeat them, are left out. Raises
    :class:`InputError` when no valid heading of the table lies within the recording."""
    table = given.table
    check_yaw_rate_unit(sequence.yaw_rate, sequence.wheel_speed, sequence.vehicle_source)
    tight_source = "tc" if given.has_tight else "tc+conv"
    usable = absolute_heading(table, tight_source, config.correction).valid
    times = np.concatenate([sequence.image_times, sequence.wheel_speed.t])
    if sequence.has_gnss:
        times = np.concatenate([times, sequence.observations.epoch_time])
    begin, end = float(np.min(times)), float(np.max(times))
    inside = (table.t >= begin) & (table.t <= end)
    if not (usable & inside).any():
        raise InputError(
            f"{given.source}: no valid heading within the recording's times (GPS {begin:.3f} "
            f"to {end:.3f} s; the file's rows run {table.t[0]:.3f} to {table.t[-1]:.3f} s, "
            f"{int(usable.sum())} of them valid): is it of this recording, on GPS time?"
        )
    warnings: list[str] = []
    gnss = None
    antenna = AntennaTrack(np.zeros(0), np.zeros((1, 3)))
    if sequence.has_gnss:
        obs = sequence.observations
        check_vehicle_overlap(
            sequence.wheel_speed, sequence.yaw_rate, obs.epoch_time, sequence.vehicle_source
        )
        origin = origin_warning(sequence.enu, obs.header.approx_position)
        warnings += [origin] if origin else []
        gnss = sequence_gnss(sequence, config)
        antenna = antenna_track(gnss.spp, gnss.velocity, obs.header.approx_position, sequence.enu)
        release_free_heap()
    else:
        warnings.append(NO_GNSS_GIVEN.format(name=sequence.name))
    for text in warnings:
        log.warning("%s", text)
    speed, yaw_rate = sequence.wheel_speed, sequence.yaw_rate
    if given.has_calibration:
        speed, yaw_rate = table.calibrated_speed(speed), table.calibrated_yaw_rate(yaw_rate)
    vo, vo_vehicle = vehicle_vo(sequence, config.vo, speed, on_frame, images)
    trajectories = correct_all(
        sequence, table, vo_vehicle, speed, antenna, config, yaw_rate, tight_source
    )
    if not given.has_tight:
        for name in (Pipeline.VO_GPS_CONV, Pipeline.DR_GPS_CONV):
            trajectories.pop(name, None)
    return RunResult(
        gnss, table, vo, speed, trajectories, antenna, usable, warnings, given.describe()
    )
