"""Observations + satellite states (broadcast or precise) → SPP positions and Doppler
velocities (no file I/O)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import StrEnum

import numpy as np

from vo_doppler.bounds import RECEIVER_RADIUS
from vo_doppler.choices import checked, checked_letters
from vo_doppler.errors import InputError
from vo_doppler.gnss.doppler_velocity import (
    DopplerRows,
    doppler_codes,
    doppler_rows,
    solve_velocity,
    solve_with_fitted_noise,
)
from vo_doppler.gnss.moving_noise import MovingNoiseModel, moving_noise_weights
from vo_doppler.gnss.noise_model import NoiseModel, fit_noise_models
from vo_doppler.gnss.phase_rate import carrier_phase_doppler
from vo_doppler.gnss.position_check import doppler_consistency
from vo_doppler.gnss.receiver_track import smoothed_track
from vo_doppler.gnss.satellite_source import StateSource
from vo_doppler.gnss.signals import bands_problem
from vo_doppler.gnss.spp import receiver_positions, solve_spp
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
from vo_doppler.model.observations import Observations
from vo_doppler.model.signals import DEFAULT_SYSTEMS, SatelliteSystem


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
    moving_noise: MovingNoiseModel = field(default_factory=MovingNoiseModel)
    """The rest factor and speed share of the rows' σ (``moving_noise``), applied to every row
    before the final solution."""


class RangeRateSource(StrEnum):
    """Where :func:`gnss_velocity` takes each satellite's range rate from (``gnss velocity
    --range-rate``)."""

    DOPPLER = "doppler"
    """The logged Doppler."""
    PHASE = "phase"
    """The carrier-phase rate (:func:`~vo_doppler.gnss.phase_rate.carrier_phase_doppler`)."""


def check_elevation_mask(value: float, name: str = "elevation_mask_rad") -> float:
    """``value`` if it is an elevation mask in [0, π/2) rad; else an :class:`InputError` naming
    the argument ``name``. A value beyond π/2 is almost surely degrees, and the message says so:
    a mask of 10 rad would otherwise remove every satellite and leave no solution, silently."""
    if not (isinstance(value, (int, float, np.number)) and math.isfinite(value)):
        raise InputError(f"{name} = {value!r}: an elevation mask is a finite number of radians")
    if not 0.0 <= value < math.pi / 2:
        hint = (
            f"; {value:g} looks like degrees: {math.radians(value):.4f} rad is {value:g}°"
            if math.pi / 2 <= value < 90.0
            else ""
        )
        raise InputError(f"{name} = {value:g}: an elevation mask is in [0, π/2) rad{hint}")
    return float(value)


def _check_arguments(
    obs: Observations,
    systems: str,
    elevation_mask_rad: float,
    bands: str | None,
    range_rate: RangeRateSource | str,
    receiver_ecef: np.ndarray | None,
) -> np.ndarray | None:
    """An :class:`InputError` naming the first argument of :func:`gnss_velocity` out of its
    domain (each would leave no valid epoch, without a word); ``receiver_ecef`` as an array."""
    checked_letters(SatelliteSystem, systems, "systems")
    checked(RangeRateSource, range_rate, "range_rate")
    check_elevation_mask(elevation_mask_rad)
    if bands is not None:
        problem = bands_problem(bands)
        if problem:
            raise InputError(f"bands: {problem}")
        if not doppler_codes(obs, systems, bands):
            present = "".join(sorted({c[1] for c in doppler_codes(obs, systems)}))
            raise InputError(
                f"bands = {bands!r}: the file has no Doppler of those bands for the systems "
                f"{systems!r} (it has bands {present or 'none'})",
                obs.header.path,
            )
    if receiver_ecef is None:
        return None
    position = np.asarray(receiver_ecef, dtype=float)
    if position.shape not in ((3,), (obs.epoch_time.size, 3)):
        raise InputError(
            f"receiver_ecef has shape {position.shape}: give one ECEF position (3,) or one per "
            f"epoch ({obs.epoch_time.size}, 3)"
        )
    radius = np.linalg.norm(position.reshape(-1, 3), axis=1)
    bad = np.flatnonzero(RECEIVER_RADIUS.outside(radius))
    if bad.size:
        where = f" at epoch {bad[0]}" if position.ndim == 2 else ""
        raise InputError(
            f"receiver_ecef{where} is {position.reshape(-1, 3)[bad[0]]}, {radius[bad[0]]:.6g} m "
            f"from the Earth's centre: an ECEF position (m) is {RECEIVER_RADIUS.low:.3g} to "
            f"{RECEIVER_RADIUS.high:.3g} m from it"
        )
    return position


def gnss_velocity(
    obs: Observations,
    source: StateSource,
    systems: str = DEFAULT_SYSTEMS,
    elevation_mask_rad: float = np.deg2rad(10.0),
    bands: str | None = None,
    range_rate: RangeRateSource | str = RangeRateSource.DOPPLER,
    receiver_ecef: np.ndarray | None = None,
    reported_sigma: ReportedSigma | None = None,
    fit_noise: bool = False,
    moving_noise: bool = True,
) -> GnssVelocityResult:
    """Per-epoch Doppler velocity. Line-of-sight vectors use ``receiver_ecef`` where given, else
    the SPP fixes smoothed along the Doppler velocities (``receiver_track``: the velocities
    of a first solution with the nearest valid fix, or the RINEX approximate position when SPP
    fails, then the rows and velocities again from the smoothed track);
    ``range_rate`` 'phase' replaces the Doppler by the carrier-phase rate (``phase_rate``);
    ``reported_sigma`` the receiver's σ of the range rates (weights where present);
    ``fit_noise`` re-solves with σ fitted to the residuals (``solve_with_fitted_noise``);
    without it the σ models are still fitted, for the record. Either way, unless
    ``moving_noise`` is False, the rows' σ are then scaled to the receiver's noise at rest and
    given their speed share (:mod:`vo_doppler.gnss.moving_noise`) and the velocity solved
    again.

    Arguments out of their domain (``systems`` other than RINEX system letters, an elevation
    mask outside [0, π/2) rad, band digits that are not digits or absent from the file, a
    receiver position off the Earth, an unknown ``range_rate``) are an :class:`InputError`
    naming the argument.

    Many parameters because it is the GNSS stage's public entry point: after the observations
    and satellite states, each argument is one independent option with its default, passed by
    keyword by ``run.py``, the commands and the tests; gathering them into a configuration is
    issue 32's open work together with those callers."""
    receiver_ecef = _check_arguments(
        obs, systems, elevation_mask_rad, bands, range_rate, receiver_ecef
    )
    spp = solve_spp(obs, source, systems, elevation_mask_rad)
    fallback = receiver_ecef if receiver_ecef is not None else obs.header.approx_position
    position = (
        np.broadcast_to(receiver_ecef, (obs.epoch_time.size, 3))
        if receiver_ecef is not None
        else receiver_positions(spp, fallback)
    )
    measured = carrier_phase_doppler(obs) if range_rate == RangeRateSource.PHASE else obs

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

    if receiver_ecef is None:
        position, rows = _along_track(obs.epoch_time, spp, position, rows_at)
    else:
        rows = rows_at(position)
    if fit_noise:
        velocity, rows, models = solve_with_fitted_noise(rows, obs.epoch_time)
    else:
        velocity = solve_velocity(rows, obs.epoch_time)
        models = fit_noise_models(rows, velocity)
    moving = MovingNoiseModel()
    if moving_noise:
        rows, moving = moving_noise_weights(rows, velocity)
        if not moving.identity:
            velocity = solve_velocity(rows, obs.epoch_time)
    spp = doppler_consistency(spp, velocity)
    return GnssVelocityResult(velocity, rows, spp, np.asarray(position), models, fit_noise, moving)


def _along_track(epoch_time, spp, position, rows_at):
    """Positions and Doppler rows again from the SPP fixes smoothed along the velocities of a
    first pass (the rows at ``position``; :func:`~vo_doppler.gnss.receiver_track.smoothed_track`
    with the epochs whose velocity is valid or untestable), or the first pass's when no track
    can be made. ``rows_at``: the rows at given positions. The first rows are let go before
    the second are made (about 200 bytes a row, 40 MiB on a 30-min drive at 20 Hz)."""
    rows = rows_at(position)
    first = solve_velocity(rows, epoch_time)
    known = first.valid | first.untestable
    track = smoothed_track(
        epoch_time,
        spp.position_ecef,
        spp.horizontal_sigma_m,
        first.velocity_ecef,
        first.covariance,
        known,
    )
    if track is None:
        return position, rows
    del rows
    return track, rows_at(track, log_missing=False)  # the first pass logged them


def gnss_position(
    obs: Observations,
    source: StateSource,
    systems: str = DEFAULT_SYSTEMS,
    elevation_mask_rad: float = np.deg2rad(10.0),
) -> SppSolution:
    """Single-point fixes (:func:`~vo_doppler.gnss.spp.solve_spp`: fitted pseudorange σ,
    chi-square test, protection levels) checked against each other along the Doppler
    velocities of :func:`gnss_velocity` where the file has Doppler of ``systems``
    (:mod:`~vo_doppler.gnss.position_check`: a fix inconsistent with its neighbours is not
    valid, the σ scaled to the scatter); without Doppler, the fixes' own tests alone."""
    checked_letters(SatelliteSystem, systems, "systems")
    check_elevation_mask(elevation_mask_rad)
    if not doppler_codes(obs, systems):
        return solve_spp(obs, source, systems, elevation_mask_rad)
    return gnss_velocity(obs, source, systems, elevation_mask_rad).spp
