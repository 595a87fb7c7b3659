"""Adapter: the GNSS package's Doppler rows (ECEF) → heading rows (local ENU at the receiver).

Both use the same range-rate convention (ṙ = G·(v_s − v) + ρ − ρ_s, G receiver → satellite),
so only the frame changes: each row's vectors are rotated into the ENU frame at the receiver
position used for that row. Weights are 1/σ² from the GNSS package's C/N0–elevation model.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import fields, replace

import numpy as np

from vo_doppler.geo import EnuFrame, ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.gnss.doppler_velocity import DopplerRows as GnssDopplerRows
from vo_doppler.gnss.doppler_velocity import VelocitySolution, doppler_rows, solve_velocity
from vo_doppler.gnss.spp import receiver_positions, solve_spp
from vo_doppler.heading.conventional import velocity_heading_sigma
from vo_doppler.heading.pipeline import HeadingPipelineConfig, heading_pipeline
from vo_doppler.heading.rows import DopplerRows
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.observations import Observations
from vo_doppler.model.series import SensorSeries


def satellite_names(rows: GnssDopplerRows) -> np.ndarray:
    """'G05'-style names of the rows' satellites."""
    return np.array([f"{s}{int(p):02d}" for s, p in zip(rows.system, rows.prn, strict=True)])


def heading_rows(rows: GnssDopplerRows) -> DopplerRows:
    """ENU heading rows from GNSS Doppler rows (per-row receiver position → ENU rotation)."""
    n = len(rows)
    if n == 0:
        empty = np.zeros((0, 3))
        return DopplerRows(np.zeros(0), empty, empty, np.zeros(0), np.zeros(0), np.zeros(0), [])
    positions, inverse = np.unique(rows.receiver_ecef, axis=0, return_inverse=True)
    lat, lon, _ = ecef_to_geodetic(positions)
    rotations = np.stack(
        [
            ecef_to_enu_rotation(a, b)
            for a, b in zip(np.atleast_1d(lat), np.atleast_1d(lon), strict=True)
        ]
    )
    return DopplerRows.from_ecef(
        rows.t,
        rows.los,
        rows.sat_vel,
        rows.sat_clock_drift_mps,
        rows.range_rate_mps,
        1.0 / rows.sigma() ** 2,
        satellite_names(rows),
        rotations[inverse.reshape(-1)],
    )


def select_rows(rows: GnssDopplerRows, keep: np.ndarray) -> GnssDopplerRows:
    """The rows where ``keep`` is True (every per-row array filtered, counts unchanged)."""
    n = len(rows)
    changes = {
        f.name: getattr(rows, f.name)[keep]
        for f in fields(rows)
        if isinstance(getattr(rows, f.name), np.ndarray) and getattr(rows, f.name).shape[:1] == (n,)
    }
    return replace(rows, **changes)


def keep_highest_satellites(
    rows: GnssDopplerRows, n_keep: int, after_t: float = -np.inf
) -> GnssDopplerRows:
    """Emulate an urban canyon: from ``after_t`` on, keep only the ``n_keep`` satellites of
    highest elevation at each epoch (the open sky of a street canyon is overhead)."""
    names = satellite_names(rows)
    keep = np.ones(len(rows), dtype=bool)
    for epoch in np.unique(rows.epoch[rows.t >= after_t]):
        members = np.flatnonzero((rows.epoch == epoch) & (rows.t >= after_t))
        best: dict[str, float] = {}
        for i in members:
            best[names[i]] = max(best.get(names[i], -np.inf), rows.elevation[i])
        chosen = sorted(best, key=best.get, reverse=True)[:n_keep]
        keep[members] = np.isin(names[members], chosen)
    return select_rows(rows, keep)


def emulated_canyon(
    obs: Observations,
    nav: Navigation,
    n_keep: int,
    after_t: float,
    systems: str = "GREJC",
    elevation_mask_rad: float = np.radians(10.0),
) -> tuple[GnssDopplerRows, VelocitySolution]:
    """Doppler rows and conventional velocities as a receiver in a street canyon would have them
    from ``after_t`` on: only the ``n_keep`` highest satellites, and line-of-sight vectors from
    the last single-point fix before ``after_t`` (the header's approximate position if none)."""
    spp = solve_spp(obs, nav, systems, elevation_mask_rad)
    open_sky = replace(spp, valid=spp.valid & (spp.t < after_t))
    positions = receiver_positions(open_sky, obs.header.approx_position)
    rows = doppler_rows(obs, nav, positions, systems, elevation_mask_rad=elevation_mask_rad)
    rows = keep_highest_satellites(rows, n_keep, after_t)
    return rows, solve_velocity(rows, obs.epoch_time)


def conventional_heading_sigma(velocity: VelocitySolution, enu: EnuFrame) -> np.ndarray:
    """Standard deviation (rad) of each epoch's conventional heading, from its Doppler velocity
    covariance turned into the ENU frame ``enu``
    (:func:`~vo_doppler.heading.conventional.velocity_heading_sigma`)."""
    return velocity_heading_sigma(velocity.velocity_enu, velocity.covariance, enu.rotation)


def heading_from_gnss(
    epoch_time: np.ndarray,
    rows: GnssDopplerRows,
    velocity: VelocitySolution,
    wheel_speed: SensorSeries,
    yaw_rate: SensorSeries,
    enu: EnuFrame,
    config: HeadingPipelineConfig,
    antenna_lever_arm_m: Sequence[float] = (0.0, 0.0, 0.0),
) -> HeadingTable:
    """The heading stage ([TK18] sec. 3.3–3.5) from the GNSS stage's Doppler rows and
    conventional velocities: what ``run``, ``heading`` and the benchmarks all call."""
    return heading_pipeline(
        epoch_time,
        heading_rows(rows),
        velocity.velocity_enu,
        velocity.valid,
        wheel_speed,
        yaw_rate,
        config,
        conventional_sigma_mps=velocity.sigma_mps,
        conventional_yaw_sigma=conventional_heading_sigma(velocity, enu),
        antenna_lever_arm_m=antenna_lever_arm_m,
    )
