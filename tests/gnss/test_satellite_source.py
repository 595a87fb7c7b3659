"""One satellite-state protocol: broadcast ephemerides tabulated every 15 min as precise
orbits (clocks without the relativistic term, as IGS products are) give the same states and
the same Doppler velocities as the broadcast path itself."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.doppler_velocity import doppler_rows, solve_velocity
from vo_doppler.gnss.ephemeris import satellite_states
from vo_doppler.gnss.satellite_source import (
    BroadcastSource,
    PreciseSource,
    satellite_source,
)
from vo_doppler.gnss.spp import receiver_positions, solve_spp
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.model.precise_orbits import PreciseOrbits

T0 = 1403252400.0  # 2024-06-24 08:20:00 GPST, the Septentrio file
SATS = ["G05", "G06", "G07", "G11", "G13", "G20", "E04", "E10", "E12", "C23", "C25"]


@pytest.fixture(scope="module")
def nav():
    return read_nav(require_shared("septentrio_static/base.nav"))


def tabulated(nav, sats=None, span_s=2.0 * 3600.0) -> PreciseOrbits:
    """The broadcast states every 15 min over ±``span_s``, written as an SP3 would hold them
    (default: every GPS and Galileo satellite of the navigation file)."""
    if sats is None:
        kepler = nav.kepler
        chosen = np.isin(kepler.system, ["G", "E"])
        pairs = zip(kepler.system[chosen], kepler.prn[chosen], strict=True)
        sats = sorted({f"{s}{p:02d}" for s, p in pairs})
    t = T0 + np.arange(-span_s, span_s + 1.0, 900.0)
    system = np.array([s[0] for s in sats])
    prn = np.array([int(s[1:]) for s in sats])
    states = satellite_states(nav, system[None, :], prn[None, :], t[:, None])
    position = states.position.reshape(t.size, len(sats), 3)
    velocity = states.velocity.reshape(t.size, len(sats), 3)
    relativity = -2.0 * np.einsum("eni,eni->en", position, velocity) / SPEED_OF_LIGHT**2
    clock = states.clock_bias_s.reshape(t.size, len(sats)) - relativity
    return PreciseOrbits(t, np.array(sats), position, clock)


def test_sources_from_model_types(nav):
    orbits = tabulated(nav)
    assert isinstance(satellite_source(nav), BroadcastSource)
    assert isinstance(satellite_source(orbits), PreciseSource)
    source = PreciseSource(orbits, n_points=8)
    assert satellite_source(source) is source
    assert satellite_source(orbits).klobuchar is None
    assert satellite_source(nav).klobuchar is not None


def test_precise_states_reproduce_the_broadcast_orbit(nav):
    orbits = tabulated(nav, SATS)
    rng = np.random.default_rng(3)
    t = T0 + rng.uniform(-1800.0, 1800.0, 200)
    sat = rng.choice(SATS, 200)
    system = np.array([s[0] for s in sat])
    prn = np.array([int(s[1:]) for s in sat])
    broadcast = satellite_states(nav, system, prn, t)
    precise = PreciseSource(orbits).states(system, prn, t)
    assert precise.valid.all() and broadcast.valid.all()
    # the broadcast orbit jumps by centimetres where it switches records (every 1–3 h); the
    # polynomial smooths over them: measured 6 cm at most, 0.2 mm median
    difference = np.linalg.norm(precise.position - broadcast.position, axis=1)
    assert difference.max() < 0.1 and np.median(difference) < 0.005
    assert np.abs(precise.velocity - broadcast.velocity).max() < 1e-3
    # the clock is linear between nodes (the broadcast one is quadratic): ≤ 0.1 ns, 1e-13 s/s
    assert np.abs(precise.clock_bias_s - broadcast.clock_bias_s).max() < 1e-10
    drift_error = SPEED_OF_LIGHT * np.abs(precise.clock_drift - broadcast.clock_drift)
    assert drift_error.max() < 1e-3  # m/s


@pytest.mark.slow
def test_same_doppler_velocity_from_either_source(nav):
    obs = read_obs(require_shared("septentrio_static/rover.obs"))
    orbits = tabulated(nav)
    position = receiver_positions(solve_spp(obs, nav, "GE"), obs.header.approx_position)
    solutions = []
    for source in (nav, orbits):
        rows = doppler_rows(obs, source, position, "GE")
        solutions.append(solve_velocity(rows, obs.epoch_time))
    broadcast, precise = solutions
    both = broadcast.valid & precise.valid
    assert both.mean() > 0.95
    assert np.abs(broadcast.velocity_ecef[both] - precise.velocity_ecef[both]).max() < 2e-3
    # and the static antenna stays static: median speed of a few cm/s from either source
    assert np.median(precise.speed_mps[precise.valid]) < 0.05
    spp = solve_spp(obs, orbits, "GE")
    # no broadcast group delay or Klobuchar ionosphere with precise products: metres apart
    difference = np.linalg.norm(spp.position_ecef - position, axis=1)
    assert np.median(difference[spp.valid]) < 15.0
