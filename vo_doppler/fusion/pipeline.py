"""The main job: VO → calibration → tightly coupled heading → heading correction.

Stages (DESIGN.md "Architecture"):

1. GNSS: SPP positions and the conventional Doppler velocity (sec. 3.2) with the Doppler rows
   behind it.
2. Calibration (sec. 3.3–3.4) and tightly coupled heading (sec. 3.5), epoch by epoch: the wheel
   scale and gyro bias current at each epoch, the heading of every epoch's window.
3. VO on the images with metric steps from the calibrated wheel speed.
4. Heading correction of the VO with the tightly coupled heading, by the seed's window
   (sec. 3.6, Eq. 11–13) or by our Kalman blend (:mod:`vo_doppler.fusion.heading_blend`); the
   conventional heading gives a second corrected trajectory for comparison.
5. A dead-reckoning trajectory from calibrated wheel speed and gyro, corrected the same way.

All trajectories are vehicle poses (x forward, y left, z up) in the sequence's ENU frame, on
GPS time. No file I/O here: :mod:`vo_doppler.io.sequence` reads the inputs.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.fusion.heading_blend import BlendConfig, blend_heading
from vo_doppler.fusion.heading_correction import correct_heading, vehicle_poses, yaw_of
from vo_doppler.geo import EnuFrame
from vo_doppler.gnss.pipeline import GnssVelocityResult, gnss_velocity
from vo_doppler.heading.conventional import velocity_heading_sigma
from vo_doppler.heading.from_gnss import heading_rows
from vo_doppler.heading.pipeline import HeadingPipelineConfig, HeadingTable, heading_pipeline
from vo_doppler.io.images import read_image
from vo_doppler.io.rinex_nav import Navigation
from vo_doppler.io.rinex_obs import Observations
from vo_doppler.io.sensor_csv import SensorSeries
from vo_doppler.lowcost.dead_reckoning import dead_reckon, yaw_increments
from vo_doppler.trajectory import Trajectory
from vo_doppler.vo.batch import VoOutput, run_visual_odometry
from vo_doppler.vo.camera import Camera
from vo_doppler.vo.config import VoConfig
from vo_doppler.vo.scale import travelled_distance

log = logging.getLogger(__name__)

CORRECTION_METHODS = ("window", "kalman")


@dataclass
class SequenceInputs:
    """Everything one run needs, already on GPS time and in SI units."""

    name: str
    image_paths: list[Path]
    image_times: np.ndarray
    camera: Camera
    observations: Observations
    navigation: Navigation
    yaw_rate: SensorSeries
    """Counter-clockwise positive, rad/s."""
    wheel_speed: SensorSeries
    enu: EnuFrame
    truth: Trajectory | None = None
    """Vehicle poses in the ENU frame, if known."""
    antenna_lever_arm_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    """GNSS antenna in the vehicle frame (x forward, y left, z up) from the vehicle origin (m)."""


@dataclass
class PipelineConfig:
    systems: str = "GREJC"
    elevation_mask_deg: float = 10.0
    heading: HeadingPipelineConfig = field(default_factory=HeadingPipelineConfig)
    vo: VoConfig = field(default_factory=VoConfig)
    correction_method: str = "window"
    """'window': the seed's sec. 3.6, Eq. 11–13; 'kalman': the adaptive blend (B1)–(B4) of
    :mod:`vo_doppler.fusion.heading_blend` (the smoother; ``blend.smooth=False`` is causal)."""
    blend: BlendConfig = field(default_factory=BlendConfig)
    """Kalman blend parameters; its ``reference`` is replaced by ``correction_reference``."""
    correction_window_s: float = 2.0
    correction_reference: str = "course"
    """What the absolute heading is compared with: the VO's 'course' (direction of travel, as a
    Doppler heading is) or its 'orientation' yaw (sec. 3.6 as written). The course is immune to
    camera-calibration and extrinsic yaw errors that skew the VO's motion against its axis."""
    correction_gate_deg: float = 0.0
    """If > 0, absolute headings this far from the corrected VO heading are not used. Off by
    default: a wrong first heading would then lock out the right ones (sec. 3.6 has no gate)."""
    tc_max_sigma_deg: float = 2.0
    """Tightly coupled headings with a larger standard deviation do not correct."""
    dead_reckoning_rate_hz: float = 20.0


@dataclass
class PipelineResult:
    gnss: GnssVelocityResult
    heading: HeadingTable
    vo: VoOutput
    calibrated_speed: SensorSeries
    trajectories: dict[str, Trajectory]
    """'vo' (initial heading from the first absolute heading), 'vo_gps_conv', 'vo_gps_tc',
    'dr_gps_tc' — vehicle poses in ENU."""
    start_enu: np.ndarray
    tc_usable: np.ndarray
    """Epochs whose tightly coupled heading was allowed to correct."""


def calibrated_speed(wheel: SensorSeries, table: HeadingTable) -> SensorSeries:
    """Wheel speed × the wheel scale current at each sample (held between GNSS epochs)."""
    index = np.clip(np.searchsorted(table.t, wheel.t, side="right") - 1, 0, len(table.t) - 1)
    return SensorSeries(wheel.t, wheel.value * table.wheel_scale[index], "speed", "m/s")


def calibrated_yaw_rate(yaw_rate: SensorSeries, table: HeadingTable) -> SensorSeries:
    """Yaw rate minus the gyro bias current at each sample (held between GNSS epochs)."""
    index = np.clip(np.searchsorted(table.t, yaw_rate.t, side="right") - 1, 0, len(table.t) - 1)
    return SensorSeries(yaw_rate.t, yaw_rate.value - table.gyro_bias[index], "yaw rate", "rad/s")


def start_position(
    gnss: GnssVelocityResult, obs: Observations, enu: EnuFrame, span_s: float = 5.0
) -> np.ndarray:
    """Median SPP position (ENU) over the first ``span_s`` seconds of valid fixes; without any
    fix, the RINEX header's approximate position; without that, the ENU origin."""
    spp = gnss.spp
    valid = np.flatnonzero(spp.valid)
    if valid.size:
        near = valid[spp.t[valid] <= spp.t[valid[0]] + span_s]
        return np.median(enu.ecef_to_enu(spp.position_ecef[near]), axis=0)
    approx = obs.header.approx_position
    if approx is not None and np.all(np.isfinite(approx)) and np.linalg.norm(approx) > 6.0e6:
        log.warning("no SPP fix: the trajectories start at the RINEX approximate position")
        return enu.ecef_to_enu(np.asarray(approx, dtype=float))
    log.warning("no SPP fix and no approximate position: the trajectories start at the origin")
    return np.zeros(3)


def level_with_yaw(poses: np.ndarray, yaw0: float, start: np.ndarray) -> np.ndarray:
    """Rotate vehicle poses (first-vehicle frame) about z by ``yaw0`` and move them to ``start``."""
    rotation = np.eye(4)
    rotation[:3, :3] = Rotation.from_euler("z", yaw0).as_matrix()
    out = rotation @ poses
    out[:, :3, 3] += start - out[0, :3, 3]
    return out


def yaw_at(t: np.ndarray, poses: np.ndarray, t0: float) -> float:
    """Yaw of the pose (N, 4, 4) at the first time ≥ ``t0`` (the last pose after the end)."""
    k = int(np.clip(np.searchsorted(t, t0), 0, len(poses) - 1))
    return float(yaw_of(poses[k : k + 1, :3, :3])[0])


def first_heading(t: np.ndarray, yaw: np.ndarray, valid: np.ndarray) -> tuple[float, float]:
    """Time and yaw of the first valid absolute heading (NaNs when there is none)."""
    usable = np.flatnonzero(valid & np.isfinite(yaw))
    if usable.size == 0:
        return float("nan"), float("nan")
    return float(t[usable[0]]), float(yaw[usable[0]])


def dead_reckoning_track(
    speed: SensorSeries, yaw_rate: SensorSeries, t: np.ndarray, yaw0: float, start: np.ndarray
) -> Trajectory:
    """Planar wheel + gyro dead reckoning (Eq. 15–17 of the low-cost method) at times ``t``."""
    steps = np.diff(travelled_distance(speed.t, speed.value, t))
    turns = yaw_increments(yaw_rate.t, yaw_rate.value, t)
    track = dead_reckon(t, steps, turns, yaw0, (float(start[0]), float(start[1])))
    positions = np.column_stack([track.east, track.north, np.full(len(t), start[2])])
    return Trajectory(t, positions, Rotation.from_euler("z", track.yaw[:, None]))


def heading_stage(
    inputs: SequenceInputs,
    gnss: GnssVelocityResult,
    config: HeadingPipelineConfig,
    antenna_lever_arm_m: tuple[float, ...] | None = None,
) -> HeadingTable:
    """The heading table of :func:`run_pipeline` (sec. 3.3–3.5) from the GNSS velocity result,
    with the sequence's antenna lever arm unless ``antenna_lever_arm_m`` replaces it."""
    return heading_pipeline(
        inputs.observations.epoch_time,
        heading_rows(gnss.rows),
        gnss.velocity.velocity_enu,
        gnss.velocity.valid,
        inputs.wheel_speed,
        inputs.yaw_rate,
        config,
        conventional_sigma_mps=gnss.velocity.sigma_mps,
        conventional_yaw_sigma=conventional_heading_sigma(gnss, inputs.enu),
        antenna_lever_arm_m=inputs.antenna_lever_arm_m
        if antenna_lever_arm_m is None
        else antenna_lever_arm_m,
    )


def run_pipeline(
    inputs: SequenceInputs,
    config: PipelineConfig | None = None,
    on_frame: Callable[[int], None] | None = None,
    initial_yaw: float | None = None,
) -> PipelineResult:
    """Run every stage; ``initial_yaw`` (rad) fixes the trajectories' starting yaw (e.g. from
    ground truth, for evaluation), else the first absolute heading sets it."""
    config = config or PipelineConfig()
    obs = inputs.observations
    gnss = gnss_velocity(
        obs, inputs.navigation, config.systems, np.radians(config.elevation_mask_deg)
    )
    table = heading_stage(inputs, gnss, config.heading)
    speed = calibrated_speed(inputs.wheel_speed, table)
    vo = run_visual_odometry(
        (read_image(p) for p in inputs.image_paths),
        inputs.image_times,
        inputs.camera,
        config.vo,
        (speed.t, speed.value),
        on_frame,
    )
    start = start_position(gnss, obs, inputs.enu)
    trajectories = correct_all(
        inputs,
        table,
        vo.trajectory,
        speed,
        start,
        config,
        initial_yaw,
    )
    usable = usable_tight_heading(table, config)
    return PipelineResult(gnss, table, vo, speed, trajectories, start, usable)


def conventional_heading_sigma(gnss: GnssVelocityResult, enu: EnuFrame) -> np.ndarray:
    """Standard deviation (rad) of each epoch's conventional heading, from its Doppler velocity
    covariance (:func:`~vo_doppler.heading.conventional.velocity_heading_sigma`)."""
    velocity = gnss.velocity
    return velocity_heading_sigma(velocity.velocity_enu, velocity.covariance, enu.rotation)


def correct_all(
    inputs: SequenceInputs,
    table: HeadingTable,
    camera_trajectory: Trajectory,
    speed: SensorSeries,
    start: np.ndarray,
    config: PipelineConfig,
    initial_yaw: float | None = None,
) -> dict[str, Trajectory]:
    """The VO alone, the VO corrected by the conventional and by the tightly coupled heading,
    and dead reckoning corrected by the tightly coupled heading (vehicle poses, ENU).

    Every trajectory starts at ``start`` with yaw ``initial_yaw``; by default that is the
    first absolute heading (tightly coupled, else conventional), matched at its own time.
    Only reliable tightly coupled headings correct (the 10-epoch gyro-consistency test).
    """
    tc_valid = usable_tight_heading(table, config)
    vo_vehicle = vehicle_poses(camera_trajectory, inputs.camera.T_vehicle_camera)
    t_vo = camera_trajectory.t
    yaw_rate = calibrated_yaw_rate(inputs.yaw_rate, table)
    t_dr = np.arange(
        max(speed.t[0], yaw_rate.t[0], t_vo[0]),
        min(speed.t[-1], yaw_rate.t[-1], t_vo[-1]),
        1.0 / config.dead_reckoning_rate_hz,
    )
    dr = dead_reckoning_track(speed, yaw_rate, t_dr, 0.0, np.zeros(3)) if len(t_dr) > 1 else None
    if initial_yaw is None:
        t0, yaw0 = first_heading(table.t, table.yaw_tc, tc_valid)
        if not np.isfinite(yaw0):
            t0, yaw0 = first_heading(table.t, table.yaw_conv, table.conv_valid)
        if not np.isfinite(yaw0):
            log.warning("no absolute heading at any epoch: the trajectories start facing east")
            t0, yaw0 = t_vo[0], 0.0
        vo_yaw0 = yaw0 - yaw_at(t_vo, vo_vehicle, t0)
        dr_yaw0 = yaw0 - yaw_at(dr.t, dr.matrices, t0) if dr is not None else yaw0
    else:
        vo_yaw0 = dr_yaw0 = initial_yaw
    vo_level = Trajectory.from_matrices(t_vo, level_with_yaw(vo_vehicle, vo_yaw0, start))
    trajectories = {"vo": vo_level}
    tight = AbsoluteHeading(
        table.t, table.yaw_tc, tc_valid, table.sigma_tc, config.heading.tight.window_s
    )
    conventional = AbsoluteHeading(table.t, table.yaw_conv, table.conv_valid, table.sigma_conv)
    trajectories["vo_gps_conv"] = corrected_level(vo_level, conventional, config)
    trajectories["vo_gps_tc"] = corrected_level(vo_level, tight, config)
    if dr is not None:
        dr_level = Trajectory.from_matrices(dr.t, level_with_yaw(dr.matrices, dr_yaw0, start))
        trajectories["dr_gps_tc"] = corrected_level(dr_level, tight, config)
    return trajectories


def usable_tight_heading(table: HeadingTable, config: PipelineConfig) -> np.ndarray:
    """Epochs whose tightly coupled heading may correct: available, reliable, precise enough."""
    precise = np.nan_to_num(table.sigma_tc, nan=np.inf) < np.radians(config.tc_max_sigma_deg)
    return table.tc_available & table.tc_reliable & precise


@dataclass
class AbsoluteHeading:
    """Absolute yaw per GNSS epoch with its validity, standard deviation (NaN: unknown, the
    blend's default) and error-correlation time (s; 0 for single-epoch headings)."""

    t: np.ndarray
    yaw: np.ndarray
    valid: np.ndarray
    sigma: np.ndarray | None = None
    correlation_s: float = 0.0


def corrected_level(
    trajectory: Trajectory, heading: AbsoluteHeading, config: PipelineConfig
) -> Trajectory:
    """Heading correction of vehicle poses already in the level ENU world: the seed's window
    (Eq. 11–13) or the Kalman blend (B1)–(B4), per ``config.correction_method``."""
    if config.correction_method == "kalman":
        corrected = blend_heading(
            trajectory,
            heading.t,
            heading.yaw,
            heading.sigma,
            heading.valid,
            heading.correlation_s,
            np.eye(4),
            "level",
            replace(config.blend, reference=config.correction_reference),
        )
    elif config.correction_method == "window":
        gate = np.radians(config.correction_gate_deg) if config.correction_gate_deg > 0 else None
        corrected = correct_heading(
            trajectory,
            heading.t,
            heading.yaw,
            heading.valid,
            config.correction_window_s,
            np.eye(4),
            "level",
            gate_rad=gate,
            reference=config.correction_reference,
        )
    else:
        raise ValueError(
            f"unknown correction method {config.correction_method!r} {CORRECTION_METHODS}"
        )
    poses = corrected.vehicle.matrices
    poses[:, :3, 3] += trajectory.positions[0]
    return Trajectory.from_matrices(trajectory.t, poses)
