"""A recording with every time moved by the same amount: what the time-origin property tests
(issue 30) compare a run with.

Broadcast orbits are tied to the GPS week (the right ascension of the orbit's node counts from
the week's start, ``toe_sow``), so a shift that keeps the satellites where they were is a whole
number of weeks: :data:`WEEKS_NEAR_1E9_S` is the nearest to the issue's 10⁹ s. Precise orbits,
vehicle signals, images and the ground truth have no such tie."""

from __future__ import annotations

from dataclasses import replace

from vo_doppler.model.navigation import Navigation, NavRecords
from vo_doppler.model.observations import Observations
from vo_doppler.model.precise_orbits import PreciseOrbits
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.trajectory import Trajectory

SECONDS_PER_WEEK = 604_800.0
WEEKS_NEAR_1E9_S = round(1e9 / SECONDS_PER_WEEK) * SECONDS_PER_WEEK
"""1,653 GPS weeks: 999,734,400 s."""


def _records(records: NavRecords, dt: float) -> NavRecords:
    params = dict(records.params)
    if "toe" in params:
        params["toe"] = params["toe"] + dt
    return replace(records, toc=records.toc + dt, params=params)


def shifted_navigation(nav: Navigation | PreciseOrbits, dt: float) -> Navigation | PreciseOrbits:
    """Broadcast records (toc, full toe) or precise orbit and clock epochs ``dt`` later."""
    if isinstance(nav, PreciseOrbits):
        clocks = None if nav.clocks is None else replace(nav.clocks, t=nav.clocks.t + dt)
        return replace(nav, t=nav.t + dt, clocks=clocks)
    return replace(nav, kepler=_records(nav.kepler, dt), glonass=_records(nav.glonass, dt))


def shifted_observations(obs: Observations, dt: float) -> Observations:
    return replace(obs, time=obs.time + dt, epoch_time=obs.epoch_time + dt)


def shifted_trajectory(trajectory: Trajectory, dt: float) -> Trajectory:
    return Trajectory(trajectory.t + dt, trajectory.positions, trajectory.orientations)


def shifted_sequence(sequence: Sequence, dt: float) -> Sequence:
    """``sequence`` with every time ``dt`` seconds later: GNSS epochs and orbits, images,
    vehicle signals, reported Doppler σ and ground truth."""
    optional = {
        "observations": (sequence.observations, shifted_observations),
        "navigation": (sequence.navigation, shifted_navigation),
        "truth": (sequence.truth, shifted_trajectory),
        "forward_acceleration": (sequence.forward_acceleration, lambda s, d: s.shifted(d)),
        "doppler_sigma": (
            sequence.doppler_sigma,
            lambda s, d: replace(s, t=s.t + d),
        ),
    }
    return replace(
        sequence,
        image_times=sequence.image_times + dt,
        yaw_rate=sequence.yaw_rate.shifted(dt),
        wheel_speed=sequence.wheel_speed.shifted(dt),
        **{
            name: None if item is None else shift(item, dt)
            for name, (item, shift) in optional.items()
        },
    )
