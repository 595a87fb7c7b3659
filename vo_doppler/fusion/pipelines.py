"""The run's trajectories: the VO and the wheel + gyro dead reckoning, each alone and corrected
by the conventional and by the tightly coupled heading, all turned to the absolute heading of
their first seconds and placed by the antenna track (docs/design.md, "Heading correction of
VO")."""

from __future__ import annotations

from enum import StrEnum

import numpy as np

from vo_doppler.fusion.antenna_track import AntennaTrack
from vo_doppler.fusion.correction import (
    CorrectionConfig,
    HeadingSource,
    absolute_heading,
    conventional_absolute_heading,
    correct,
    tight_absolute_heading,
)
from vo_doppler.fusion.placement import initial_yaw_offset, level_with_yaw
from vo_doppler.lowcost.dead_reckoning import wheel_gyro_track
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import time_grid
from vo_doppler.model.trajectory import Trajectory


class Pipeline(StrEnum):
    """The trajectories of a run (their values are the file and summary keys)."""

    VO = "vo"
    VO_GPS_CONV = "vo_gps_conv"
    VO_GPS_TC = "vo_gps_tc"
    DR = "dr"
    DR_GPS_CONV = "dr_gps_conv"
    DR_GPS_TC = "dr_gps_tc"


def dead_reckoning(
    speed: SensorSeries,
    yaw_rate: SensorSeries,
    rate_hz: float,
    vo_vehicle: Trajectory | None = None,
) -> Trajectory | None:
    """The wheel + gyro dead reckoning ([KZ] Eq. 15–17,
    :func:`~vo_doppler.lowcost.dead_reckoning.wheel_gyro_track`) every ``1 / rate_hz`` seconds
    over the time both signals cover, and the VO's when given (in the first vehicle's frame);
    None when that time holds fewer than two such epochs."""
    begin, end = max(speed.t[0], yaw_rate.t[0]), min(speed.t[-1], yaw_rate.t[-1])
    if vo_vehicle is not None:
        begin, end = max(begin, vo_vehicle.t[0]), min(end, vo_vehicle.t[-1])
    t = time_grid(begin, end, 1.0 / rate_hz)
    return wheel_gyro_track(speed, yaw_rate, t) if len(t) > 1 else None


def correct_all(
    table: HeadingTable,
    vo_vehicle: Trajectory | None,
    dr: Trajectory | None,
    antenna: AntennaTrack,
    correction: CorrectionConfig,
    lever_arm_m: tuple[float, float, float] = (0.0, 0.0, 0.0),
    tight_source: HeadingSource | str = HeadingSource.TC,
) -> tuple[dict[Pipeline, Trajectory], np.ndarray]:
    """The VO (``vo_vehicle``) and the dead reckoning (``dr``, :func:`dead_reckoning`), each
    alone and corrected by the conventional and by the tightly coupled heading (vehicle poses,
    ENU; a trajectory that is None gives none of its three), and the epochs of ``table`` whose
    heading corrected the tightly coupled pipelines.

    Every trajectory is turned to the absolute headings of its first seconds
    (:func:`~vo_doppler.fusion.placement.initial_yaw_offset`, from the usable tightly coupled
    headings first) and placed by the antenna track
    (:func:`~vo_doppler.fusion.placement.level_with_yaw`, the antenna ``lever_arm_m`` from the
    vehicle's origin). Only usable tightly coupled headings correct the tightly coupled
    pipelines (``tight_source`` "tc"; "tc+conv" for a table without them, the conventional
    ones: :func:`~vo_doppler.fusion.correction.absolute_heading`)."""
    tight = tight_absolute_heading(table, correction)
    conventional = conventional_absolute_heading(table)
    correcting = (
        tight
        if tight_source == HeadingSource.TC
        else absolute_heading(table, tight_source, correction)
    )
    trajectories: dict[Pipeline, Trajectory] = {}
    names = (
        (vo_vehicle, (Pipeline.VO, Pipeline.VO_GPS_CONV, Pipeline.VO_GPS_TC)),
        (dr, (Pipeline.DR, Pipeline.DR_GPS_CONV, Pipeline.DR_GPS_TC)),
    )
    for trajectory, (alone, with_conventional, with_tight) in names:
        if trajectory is None:
            continue
        turn = initial_yaw_offset(table, tight.valid, trajectory, reference=correction.reference)
        level = level_with_yaw(trajectory, turn, antenna, lever_arm_m)
        trajectories[alone] = level
        trajectories[with_conventional] = correct(level, conventional, correction).vehicle
        trajectories[with_tight] = correct(level, correcting, correction).vehicle
    return trajectories, correcting.valid
