"""Observations + satellite states (broadcast or precise) → SPP positions and Doppler
velocities (no file I/O)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.gnss.doppler_velocity import (
    DopplerRows,
    doppler_rows,
    solve_velocity,
    solve_with_fitted_noise,
)
from vo_doppler.gnss.noise_model import NoiseModel, fit_noise_models
from vo_doppler.gnss.phase_rate import carrier_phase_doppler
from vo_doppler.gnss.receiver_track import smoothed_track
from vo_doppler.gnss.satellite_source import StateSource
from vo_doppler.gnss.spp import receiver_positions, solve_spp
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
from vo_doppler.model.observations import Observations


@dataclass(frozen=True)
class GnssVelocityResult:
    """Velocity solution, the Doppler rows it used, the SPP fixes, the positions used and the
    Doppler noise models fitted per signal (``noise_model``)."""

    velocity: VelocitySolution
    rows: DopplerRows
    spp: SppSolution
    receiver_ecef: np.ndarray
    noise_models: dict[tuple[str, str], NoiseModel]
    noise_fitted: bool
    """True when the rows' σ are the fitted ones; else the models are fitted for the record
    (one pass on the residuals of the solution as weighted) and not applied."""


RANGE_RATE_SOURCES = ("doppler", "phase")


def gnss_velocity(
    obs: Observations,
    source: StateSource,
    systems: str = "GREJC",
    elevation_mask_rad: float = np.deg2rad(10.0),
    bands: str | None = None,
    range_rate: str = "doppler",
    receiver_ecef: np.ndarray | None = None,
    reported_sigma: ReportedSigma | None = None,
    fit_noise: bool = False,
) -> GnssVelocityResult:
    """Per-epoch Doppler velocity. Line-of-sight vectors use ``receiver_ecef`` where given, else
    the SPP fixes smoothed along the Doppler velocities (``receiver_track``: the velocities
    of a first solution with the nearest valid fix, or the RINEX approximate position when SPP
    fails, then the rows and velocities again from the smoothed track);
    ``range_rate`` 'phase' replaces the Doppler by the carrier-phase rate (``phase_rate``);
    ``reported_sigma`` the receiver's σ of the range rates (weights where present);
    ``fit_noise`` re-solves with σ fitted to the residuals (``solve_with_fitted_noise``);
    without it the σ models are still fitted, for the record."""
    if range_rate not in RANGE_RATE_SOURCES:
        raise ValueError(f"range_rate must be one of {RANGE_RATE_SOURCES}")
    spp = solve_spp(obs, source, systems, elevation_mask_rad)
    fallback = receiver_ecef if receiver_ecef is not None else obs.header.approx_position
    position = (
        np.broadcast_to(receiver_ecef, (obs.epoch_time.size, 3))
        if receiver_ecef is not None
        else receiver_positions(spp, fallback)
    )
    measured = carrier_phase_doppler(obs) if range_rate == "phase" else obs

    def rows_at(position, log_missing=True):
        return doppler_rows(
            measured,
            source,
            position,
            systems=systems,
            bands=bands,
            elevation_mask_rad=elevation_mask_rad,
            reported_sigma=reported_sigma,
            log_missing=log_missing,
        )

    rows = rows_at(position)
    if receiver_ecef is None:
        first = solve_velocity(rows, obs.epoch_time)
        known = first.valid | first.untestable
        track = smoothed_track(
            obs.epoch_time,
            spp.position_ecef,
            spp.horizontal_sigma_m,
            first.velocity_ecef,
            first.covariance,
            known,
        )
        if track is not None:
            position = track
            rows = rows_at(position, log_missing=False)  # the first pass logged them
    if fit_noise:
        velocity, rows, models = solve_with_fitted_noise(rows, obs.epoch_time)
    else:
        velocity = solve_velocity(rows, obs.epoch_time)
        models = fit_noise_models(rows, velocity)
    return GnssVelocityResult(velocity, rows, spp, np.asarray(position), models, fit_noise)
