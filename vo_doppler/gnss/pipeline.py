"""Observations + satellite states (broadcast or precise) → SPP positions and Doppler
velocities (no file I/O)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.gnss.doppler_velocity import DopplerRows, doppler_velocity
from vo_doppler.gnss.phase_rate import carrier_phase_doppler
from vo_doppler.gnss.satellite_source import StateSource
from vo_doppler.gnss.spp import receiver_positions, solve_spp
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
from vo_doppler.model.observations import Observations


@dataclass(frozen=True)
class GnssVelocityResult:
    """Velocity solution, the Doppler rows it used, the SPP fixes and the positions used."""

    velocity: VelocitySolution
    rows: DopplerRows
    spp: SppSolution
    receiver_ecef: np.ndarray


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
    """Per-epoch Doppler velocity. Line-of-sight vectors use the SPP fix of each epoch (or the
    nearest one, or ``receiver_ecef`` / the RINEX approximate position when SPP fails);
    ``range_rate`` 'phase' replaces the Doppler by the carrier-phase rate (``phase_rate``);
    ``reported_sigma`` the receiver's σ of the range rates (weights where present);
    ``fit_noise`` re-solves with σ fitted to the residuals (``doppler_noise``)."""
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
    velocity, rows = doppler_velocity(
        measured,
        source,
        position,
        systems=systems,
        bands=bands,
        elevation_mask_rad=elevation_mask_rad,
        reported_sigma=reported_sigma,
        fit_noise=fit_noise,
    )
    return GnssVelocityResult(velocity, rows, spp, np.asarray(position))
