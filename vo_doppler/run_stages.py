"""Each stage of the main job on a recording (a :class:`~vo_doppler.model.sequence.Sequence`),
configured by :class:`RunConfig`: what :func:`vo_doppler.run.run_sequence` chains, and what the
benchmarks and tests call one by one (docs/design.md, "Packages")."""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, TypeVar

import numpy as np

from vo_doppler.child_process import call_in_child
from vo_doppler.choices import checked_letters
from vo_doppler.errors import InputError
from vo_doppler.fusion.antenna_track import AntennaTrack
from vo_doppler.fusion.correction import CorrectionConfig, HeadingSource
from vo_doppler.fusion.pipelines import Pipeline, correct_all, dead_reckoning
from vo_doppler.gnss.pipeline import GnssVelocityResult, check_elevation_mask, gnss_velocity
from vo_doppler.heading.from_gnss import heading_from_gnss
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.memory import release_free_heap
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.gnss_solutions import VelocitySolution
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.signals import DEFAULT_SYSTEMS, SatelliteSystem
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.vo.config import VoConfig
from vo_doppler.vo.frames import vehicle_trajectory

if TYPE_CHECKING:
    from vo_doppler.model.visual_odometry import VoOutput

T = TypeVar("T")


@dataclass
class RunConfig:
    """Everything :func:`vo_doppler.run.run_sequence` can be told (SI units, radians)."""

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
        sequence.vehicle_signals,
        sequence.enu,
        config,
        sequence.antenna_lever_arm_m,
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
    in_child: bool = False,
) -> tuple[VoOutput | None, Trajectory | None]:
    """:func:`sequence_vo` and its camera poses as vehicle poses, (None, None) for a recording
    without a camera. With ``in_child`` the VO runs in a forked child process
    (:func:`~vo_doppler.child_process.call_in_child`: the same result, and OpenCV and pycolmap
    leave with the child instead of staying loaded through the correction and the outputs),
    the heap trimmed first."""
    if not sequence.has_camera:
        return None, None
    if in_child:
        release_free_heap()  # what the caller let go is not held resident through the VO
        vo = call_in_child(
            lambda report: sequence_vo(sequence, config, speed, report, images), on_frame
        )
    else:
        vo = sequence_vo(sequence, config, speed, on_frame, images)
    vo_vehicle = vehicle_trajectory(vo.trajectory, sequence.camera.T_vehicle_camera)
    release_free_heap()
    return vo, vo_vehicle


def sequence_trajectories(
    sequence: Sequence,
    table: HeadingTable,
    vo_vehicle: Trajectory | None,
    speed: SensorSeries,
    antenna: AntennaTrack,
    config: RunConfig,
    yaw_rate: SensorSeries | None = None,
    tight_source: HeadingSource | str = HeadingSource.TC,
) -> tuple[dict[Pipeline, Trajectory], np.ndarray]:
    """The fusion stage on a recording: the dead reckoning of the calibrated wheel ``speed``
    and ``yaw_rate`` (default: the sequence's, less the table's gyro bias) over the VO's time
    (:func:`~vo_doppler.fusion.pipelines.dead_reckoning`), then every trajectory turned, placed
    by ``antenna`` (the sequence's lever arm) and corrected
    (:func:`~vo_doppler.fusion.pipelines.correct_all`, which also returns the epochs whose
    heading corrected the tightly coupled pipelines)."""
    if yaw_rate is None:
        yaw_rate = table.calibrated_yaw_rate(sequence.yaw_rate)
    dr = dead_reckoning(speed, yaw_rate, config.dead_reckoning_rate_hz, vo_vehicle)
    lever = sequence.antenna_lever_arm_m
    return correct_all(table, vo_vehicle, dr, antenna, config.correction, lever, tight_source)


def gnss_and_heading(
    sequence: Sequence, config: RunConfig, in_child: bool = False, keep_rows: bool = True
) -> tuple[GnssVelocityResult, HeadingTable]:
    """The GNSS stage (:func:`without_rows`: its result without the Doppler rows) and the
    heading stage on its rows. With ``in_child`` each runs in a forked child process of its
    own (:func:`~vo_doppler.child_process.call_in_child`) and only its result comes back: the
    heap each stage leaves fragmented (their transients grow with the drive) leaves with its
    child instead of staying under the next stage, the VO, the correction and the outputs.
    With ``keep_rows`` False, ``sequence.observations`` becomes its ``epochs_only()`` as soon
    as the GNSS stage has used its rows, before the heading stage (11 MiB on a 30-min drive at
    20 Hz)."""

    def run(task: Callable[[object], T]) -> T:
        return call_in_child(task) if in_child else task(None)

    def gnss_stage(_: object) -> tuple[DopplerRows, GnssVelocityResult]:
        gnss = sequence_gnss(sequence, config)
        result = gnss.rows.in_enu().required_only(), without_rows(gnss)
        del gnss
        release_free_heap()  # the child's heap is not held beside the parent's copy
        return result

    rows, gnss = run(gnss_stage)
    if not keep_rows:
        sequence.observations = sequence.observations.epochs_only()
    release_free_heap()
    table = run(lambda _: sequence_heading(sequence, rows, gnss.velocity, config.heading))
    return gnss, table


def without_rows(gnss: GnssVelocityResult) -> GnssVelocityResult:
    """``gnss`` with no Doppler row (their counts of rows not formed kept): nothing after the
    heading stage reads them, and the rows of a 30-min drive at 20 Hz are 28 MiB held through
    the VO and the outputs. :func:`gnss_and_heading` lets them go as soon as it has them in the
    ENU frame the heading stage takes, with the columns it reads alone
    (:meth:`~vo_doppler.model.doppler.DopplerRows.required_only`), which share every array but
    the vectors with them."""
    return replace(gnss, rows=gnss.rows.select(np.zeros(0, dtype=int)))
