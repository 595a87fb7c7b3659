"""The main job on one recording: GNSS → calibration and tight heading → VO → correction.

Stages (docs/design.md, "The method"; each one on a recording in :mod:`vo_doppler.run_stages`):

1. GNSS: SPP positions and the conventional Doppler velocity ([TK18] sec. 3.2) with the
   Doppler rows behind it.
2. Calibration ([TK18] sec. 3.3–3.4) and the tightly coupled heading ([TK18] sec. 3.5), epoch
   by epoch: the wheel scale and gyro bias current at each epoch, the heading of every epoch's
   window.
3. VO on the images with metric steps from the calibrated wheel speed; its camera poses become
   vehicle poses once (:func:`vo_doppler.vo.frames.vehicle_trajectory`).
4. Heading correction of the VO by the tightly coupled heading (the adaptive blend by default,
   [TK18] Eq. 11–13 on request); the conventional heading gives a second corrected trajectory.
   Every trajectory is first turned and placed by the antenna track
   (:func:`vo_doppler.fusion.pipelines.correct_all`).
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
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from vo_doppler.checks import check_vehicle_overlap, check_yaw_rate_unit, origin_warning
from vo_doppler.errors import InputError
from vo_doppler.fusion.antenna_track import AntennaTrack, antenna_track
from vo_doppler.fusion.correction import HeadingSource, absolute_heading
from vo_doppler.fusion.pipelines import Pipeline, dead_reckoning
from vo_doppler.fusion.placement import level_with_yaw
from vo_doppler.gnss.pipeline import GnssVelocityResult
from vo_doppler.memory import Parked, release_free_heap
from vo_doppler.model.given_heading import GivenHeading
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.run_stages import (
    RunConfig,
    gnss_and_heading,
    sequence_gnss,
    sequence_trajectories,
    vehicle_vo,
    without_rows,
)

if TYPE_CHECKING:
    from vo_doppler.model.visual_odometry import VoOutput

log = logging.getLogger(__name__)


@dataclass
class RunResult:
    gnss: GnssVelocityResult | None
    """None for a recording without GNSS (so is ``heading``). Without the Doppler rows the
    heading stage used (:func:`without_rows`; ``sequence_gnss`` gives them)."""
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
    """What the checks found doubtful in the inputs and the calibration (each also logged): the
    origin against the RINEX approximate position, then ``heading.warnings``."""
    heading_source: str = ""
    """Where a given ``heading`` came from, in words (:class:`GivenHeading`); else empty."""


def run_sequence(
    sequence: Sequence,
    config: RunConfig | None = None,
    on_frame: Callable[[int], None] | None = None,
    images: Iterable[np.ndarray] | None = None,
    given: GivenHeading | None = None,
    in_child: bool = False,
    keep_rows: bool = True,
) -> RunResult:
    """Run every stage on a recording. ``images`` replaces reading ``sequence.image_paths``
    (e.g. frames already in memory); ``on_frame`` is called after each VO frame; ``given``,
    an absolute heading from elsewhere, replaces the heading stage
    (:func:`run_with_given_heading`). With ``in_child`` (``vo-doppler run`` and ``batch``) the
    GNSS stage, the heading stage and the VO each run in a forked child process, with the
    same result: OpenCV and pycolmap (about 70 MiB) and the heap the stages fragment leave with
    them instead of staying through the correction and the outputs, where the job peaks
    (:mod:`vo_doppler.child_process`; with ``given``, only the VO's). With ``keep_rows`` False,
    ``sequence.observations`` becomes its ``epochs_only()`` once the GNSS stage has used its
    rows, before the heading stage. The GNSS result and the heading table wait on disk through
    the VO (:class:`Parked`).

    The inputs are checked as ``vo-doppler run`` checks them (:mod:`vo_doppler.checks`, in
    :func:`~vo_doppler.heading.from_gnss.heading_from_gnss`): vehicle signals whose times miss
    the GNSS epochs, a yaw rate too large for a car or turning against the GNSS Doppler course
    raises :class:`InputError`; the rest are warnings, logged and in ``RunResult.warnings``."""
    config = (config or RunConfig()).for_sequence(sequence)
    if given is not None:
        return run_with_given_heading(
            sequence, given, config, on_frame, images, in_child, keep_rows
        )
    if not sequence.has_gnss:
        return run_without_gnss(sequence, config, on_frame, images, in_child)
    header = sequence.observations.header
    origin = origin_warning(sequence.enu, header.approx_position)
    if origin:
        log.warning("%s", origin)
    gnss, table = gnss_and_heading(sequence, config, in_child, keep_rows)
    speed = table.calibrated_speed(sequence.wheel_speed)
    parked = Parked((gnss, table), to_disk=sequence.has_camera)
    del gnss, table
    vo, vo_vehicle = vehicle_vo(sequence, config.vo, speed, on_frame, images, in_child)
    gnss, table = parked.take()
    if vo is None:
        log.warning("%s has no camera: only the non-visual pipelines run", sequence.name)
    antenna = antenna_track(gnss.spp, gnss.velocity, header.approx_position, sequence.enu)
    trajectories, usable = sequence_trajectories(
        sequence, table, vo_vehicle, speed, antenna, config
    )
    release_free_heap()
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
    in_child: bool = False,
) -> RunResult:
    """:func:`run_sequence` on a recording without GNSS: the VO (scaled by the wheel speed as
    recorded) and the wheel + gyro dead reckoning, each started at the ENU origin facing east
    (the only placement without a fix or an absolute heading); ``gnss`` and ``heading`` are
    None and the warning says which pipelines were not run."""
    check_yaw_rate_unit(sequence.yaw_rate, sequence.wheel_speed, sequence.vehicle_source)
    note = NO_GNSS.format(name=sequence.name)
    log.warning("%s", note)
    speed, yaw_rate = sequence.wheel_speed, sequence.yaw_rate
    vo, vo_vehicle = vehicle_vo(sequence, config.vo, speed, on_frame, images, in_child)
    origin = AntennaTrack(np.zeros(0), np.zeros((1, 3)), None, "the sequence origin (no GNSS)")
    tracks = {
        Pipeline.VO: vo_vehicle,
        Pipeline.DR: dead_reckoning(speed, yaw_rate, config.dead_reckoning_rate_hz, vo_vehicle),
    }
    trajectories = {
        name: level_with_yaw(track, float(-track.yaw()[0]), origin)
        for name, track in tracks.items()
        if track is not None
    }
    return RunResult(None, None, vo, speed, trajectories, origin, np.zeros(0, dtype=bool), [note])


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
    in_child: bool = False,
    keep_rows: bool = True,
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
    tight_source = HeadingSource.TC if given.has_tight else HeadingSource.TC_CONV
    valid = absolute_heading(table, tight_source, config.correction).valid
    times = np.concatenate([sequence.image_times, sequence.wheel_speed.t])
    if sequence.has_gnss:
        times = np.concatenate([times, sequence.observations.epoch_time])
    begin, end = float(np.min(times)), float(np.max(times))
    inside = (table.t >= begin) & (table.t <= end)
    if not (valid & inside).any():
        raise InputError(
            f"{given.source}: no valid heading within the recording's times (GPS {begin:.3f} "
            f"to {end:.3f} s; the file's rows run {table.t[0]:.3f} to {table.t[-1]:.3f} s, "
            f"{int(valid.sum())} of them valid): is it of this recording, on GPS time?"
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
        gnss = without_rows(sequence_gnss(sequence, config))
        if not keep_rows:
            sequence.observations = obs = obs.epochs_only()
        antenna = antenna_track(gnss.spp, gnss.velocity, obs.header.approx_position, sequence.enu)
    else:
        warnings.append(NO_GNSS_GIVEN.format(name=sequence.name))
    for text in warnings:
        log.warning("%s", text)
    speed, yaw_rate = sequence.wheel_speed, sequence.yaw_rate
    if given.has_calibration:
        speed, yaw_rate = table.calibrated_speed(speed), table.calibrated_yaw_rate(yaw_rate)
    parked = Parked(gnss, to_disk=sequence.has_camera)
    del gnss
    vo, vo_vehicle = vehicle_vo(sequence, config.vo, speed, on_frame, images, in_child)
    gnss = parked.take()
    trajectories, usable = sequence_trajectories(
        sequence, table, vo_vehicle, speed, antenna, config, yaw_rate, tight_source
    )
    if not given.has_tight:
        for name in (Pipeline.VO_GPS_CONV, Pipeline.DR_GPS_CONV):
            trajectories.pop(name, None)
    return RunResult(
        gnss, table, vo, speed, trajectories, antenna, usable, warnings, given.describe()
    )
