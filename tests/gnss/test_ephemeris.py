"""Broadcast satellite states against an independent implementation: RTKLIB (pyrtklib binding,
test-only), which parses the navigation file itself and evaluates eph2pos / geph2pos."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.ephemeris import glonass_states, kepler_states, satellite_states
from vo_doppler.io.rinex_nav import read_nav

UNIX_GPS_EPOCH = 315964800
RTKLIB_SYSTEMS = {1: "G", 4: "R", 8: "E", 16: "J", 32: "C"}


@pytest.fixture(scope="module")
def rtklib_nav():
    rtk = pytest.importorskip("pyrtklib")
    path = require_shared("septentrio_static/base.nav")
    obs, nav, sta = rtk.obs_t(), rtk.nav_t(), rtk.sta_t()
    assert rtk.readrnx(str(path), 1, "", obs, nav, sta) == 1
    return rtk, nav, read_nav(path)


def _sat_id(rtk, sat):
    prn = rtk.Arr1Dint(1)
    system = RTKLIB_SYSTEMS[rtk.satsys(sat, prn)]
    return system, prn[0] - (192 if system == "J" else 0)  # RTKLIB numbers QZSS from 193


def _gtime(rtk, t):
    week = int(t // 604800)
    return rtk.gpst2time(week, t - week * 604800)


def _rtk_state(rtk, function, t, eph):
    rs, dts, var = rtk.Arr1Ddouble(6), rtk.Arr1Ddouble(2), rtk.Arr1Ddouble(1)
    function(_gtime(rtk, t), eph, rs, dts, var)
    return np.array([rs[0], rs[1], rs[2]]), dts[0]


def _check(rtk, function, ephs, ours, records, states, offsets, toe_of):
    checked = 0
    for eph in ephs:
        system, prn = _sat_id(rtk, eph.sat)
        toe = toe_of(eph)
        for dt in offsets:
            t = toe + dt
            mine = np.flatnonzero(
                (records.system == system) & (records.prn == prn) & (np.abs(records.toc - toe) < 1)
            )
            if system != "R":
                mine = np.flatnonzero(
                    (records.system == system)
                    & (records.prn == prn)
                    & (np.abs(records["toe"] - toe) < 1)
                    & (records["af0"] == eph.f0)
                )
            assert mine.size >= 1, (system, prn, toe)
            state = states(records, mine[:1], np.array([t]))
            position, clock = _rtk_state(rtk, function, t, eph)
            yield system, prn, state, position, clock
            checked += 1
    assert checked > 10


def test_kepler_against_rtklib(rtklib_nav):
    rtk, nav, ours = rtklib_nav
    ephs = [nav.eph[i] for i in range(nav.n)]
    errors = {}
    for system, _, state, position, clock in _check(
        rtk,
        rtk.eph2pos,
        ephs,
        ours,
        ours.kepler,
        kepler_states,
        (-3600.0, -600.0, 0.0, 900.0, 3600.0),
        lambda e: e.toe.time + e.toe.sec - UNIX_GPS_EPOCH,
    ):
        position_error = np.linalg.norm(state.position[0] - position)
        clock_error = abs(state.clock_bias_s[0] - clock) * SPEED_OF_LIGHT
        errors.setdefault(system, []).append(max(position_error, clock_error))
    assert set(errors) >= {"G", "E", "C", "J"}
    for system, values in errors.items():
        assert max(values) < 0.01, (system, max(values))


def test_glonass_against_rtklib(rtklib_nav):
    rtk, nav, ours = rtklib_nav
    ephs = [nav.geph[i] for i in range(nav.ng)]
    worst = 0.0
    for _, _, state, position, clock in _check(
        rtk,
        rtk.geph2pos,
        ephs,
        ours,
        ours.glonass,
        glonass_states,
        (-900.0, -300.0, 0.0, 450.0, 900.0),
        lambda e: e.toe.time + e.toe.sec - UNIX_GPS_EPOCH,
    ):
        worst = max(worst, np.linalg.norm(state.position[0] - position))
        assert abs(state.clock_bias_s[0] - clock) * SPEED_OF_LIGHT < 0.01
    assert worst < 1.0


def test_velocity_and_drift_are_derivatives_of_position_and_clock():
    path = require_shared("septentrio_static/base.nav")
    nav = read_nav(path)
    t0 = 1403252400.0 + 600.0
    systems = np.concatenate([nav.kepler.system, nav.glonass.system])
    prns = np.concatenate([nav.kepler.prn, nav.glonass.prn])
    here = satellite_states(nav, systems, prns, t0)
    ahead = satellite_states(nav, systems, prns, t0 + 0.5)
    behind = satellite_states(nav, systems, prns, t0 - 0.5)
    ok = here.valid & ahead.valid & behind.valid
    assert ok.sum() > 40
    assert {str(s) for s in systems[ok]} >= {"G", "E", "C", "J", "R"}
    # same record on both sides (no ephemeris switch inside the difference)
    ok &= (ahead.record == behind.record) & (here.record == ahead.record)
    velocity = ahead.position - behind.position
    drift = ahead.clock_bias_s - behind.clock_bias_s
    np.testing.assert_allclose(here.velocity[ok], velocity[ok], atol=2e-4)
    np.testing.assert_allclose(here.clock_drift[ok], drift[ok], atol=1e-14)


def test_unknown_satellite_and_stale_time_are_invalid():
    nav = read_nav(require_shared("septentrio_static/base.nav"))
    states = satellite_states(nav, ["G", "G", "R"], [99, 5, 1], [1403252400.0, 0.0, 0.0])
    assert not states.valid.any()
    assert np.isnan(states.position).all()
