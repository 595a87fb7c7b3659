"""The heading stage fed by the GNSS stage: its Doppler rows (turned from ECEF into the ENU
frame at each row's receiver, :meth:`~vo_doppler.model.doppler.DopplerRows.in_enu`) and its
conventional velocities; and an emulated street canyon for testing the heading on open-sky
recordings."""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from vo_doppler.checks import check_vehicle_overlap, check_yaw_rate_unit, heading_warnings
from vo_doppler.geo import EnuFrame
from vo_doppler.gnss.doppler_velocity import doppler_rows, solve_velocity
from vo_doppler.gnss.moving_noise import moving_noise_weights
from vo_doppler.gnss.satellite_source import StateSource
from vo_doppler.gnss.spp import receiver_positions, solve_spp
from vo_doppler.heading.conventional import ConventionalVelocity
from vo_doppler.heading.integrity import integrity_rate_warning
from vo_doppler.heading.pipeline import HeadingPipelineConfig, heading_pipeline
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.gnss_solutions import VelocitySolution
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.observations import Observations
from vo_doppler.model.signals import DEFAULT_SYSTEMS
from vo_doppler.model.vehicle_signals import VehicleSignals

log = logging.getLogger(__name__)


def keep_highest_satellites(
    rows: DopplerRows, n_keep: int, after_t: float = -np.inf
) -> DopplerRows:
    """Emulate an urban canyon: from ``after_t`` on, keep only the ``n_keep`` satellites of
    highest elevation at each epoch (the open sky of a street canyon is overhead)."""
    names = rows.sat_id
    keep = np.ones(len(rows), dtype=bool)
    for epoch in np.unique(rows.epoch[rows.t >= after_t]):
        members = np.flatnonzero((rows.epoch == epoch) & (rows.t >= after_t))
        best: dict[str, float] = {}
        for i in members:
            best[names[i]] = max(best.get(names[i], -np.inf), rows.elevation[i])
        chosen = sorted(best, key=best.get, reverse=True)[:n_keep]
        keep[members] = np.isin(names[members], chosen)
    return rows.select(keep)


def emulated_canyon(
    obs: Observations,
    nav: StateSource,
    n_keep: int,
    after_t: float,
    systems: str = DEFAULT_SYSTEMS,
    elevation_mask_rad: float = np.radians(10.0),
    reported_sigma: ReportedSigma | None = None,
) -> tuple[DopplerRows, VelocitySolution]:
    """Doppler rows and conventional velocities as a receiver in a street canyon would have them
    from ``after_t`` on: only the ``n_keep`` highest satellites, and line-of-sight vectors from
    the last single-point fix before ``after_t`` (the header's approximate position if none)."""
    spp = solve_spp(obs, nav, systems, elevation_mask_rad)
    open_sky = replace(spp, valid=spp.valid & (spp.t < after_t))
    positions = receiver_positions(open_sky, obs.header.approx_position)
    rows = doppler_rows(
        obs,
        nav,
        positions,
        systems,
        elevation_mask_rad=elevation_mask_rad,
        reported_sigma=reported_sigma,
    )
    rows = keep_highest_satellites(rows, n_keep, after_t)
    first = solve_velocity(rows, obs.epoch_time)
    rows, model = moving_noise_weights(rows, first)
    return rows, first if model.identity else solve_velocity(rows, obs.epoch_time)


def heading_from_gnss(
    epoch_time: np.ndarray,
    rows: DopplerRows,
    velocity: VelocitySolution,
    vehicle: VehicleSignals,
    enu: EnuFrame,
    config: HeadingPipelineConfig,
    antenna_lever_arm_m: Sequence[float] = (0.0, 0.0, 0.0),
) -> HeadingTable:
    """The heading stage ([TK18] sec. 3.3–3.5) from the GNSS stage's Doppler rows and
    conventional velocities: what ``run``, ``heading`` and the benchmarks all call. The table
    carries the conventional solution's speed σ (scaled as the heading's, design (I1)) and
    HDOP on its valid epochs. ``vehicle``: the wheel speed, yaw rate and, where recorded, the
    road grade prior's accelerometer (:func:`~vo_doppler.heading.pipeline.heading_pipeline`).

    The vehicle signals are checked (:mod:`vo_doppler.checks`; their ``source`` names them in
    the messages): a yaw rate too large for a car (deg/s read as rad/s) before the work, and one
    turning against the GNSS Doppler course after it, raise :class:`InputError`; the clock,
    the coverage of the GNSS epochs, the calibrated wheel scale and gyro bias give warnings,
    logged and kept in the table's ``warnings`` (the residual clock offset in
    ``clock_residual_offset_s``). Vehicle signals whose times miss the GNSS epochs raise
    before the work too (:func:`~vo_doppler.checks.check_vehicle_overlap`)."""
    wheel_speed, yaw_rate, source = vehicle.wheel_speed, vehicle.yaw_rate, vehicle.source
    check_vehicle_overlap(wheel_speed, yaw_rate, epoch_time, source)
    check_yaw_rate_unit(yaw_rate, wheel_speed, source)
    table = heading_pipeline(
        epoch_time,
        rows.in_enu(),
        ConventionalVelocity.from_solution(velocity, enu),
        vehicle,
        config,
        antenna_lever_arm_m,
    )
    table = replace(table, hdop_conv=np.where(table.conv_valid, velocity.dop[:, 2], np.nan))
    estimate, warnings = heading_warnings(
        table,
        velocity,
        wheel_speed,
        yaw_rate,
        source,
        scale_calibrated=config.fixed_wheel_scale is None,
        bias_calibrated=config.fixed_gyro_bias_rad_s is None,
    )
    warnings += [w for w in [integrity_rate_warning(epoch_time, config.integrity)] if w]
    for warning in table.warnings + warnings:
        log.warning("%s", warning)
    return replace(
        table, warnings=table.warnings + warnings, clock_residual_offset_s=estimate.residual_s
    )
