"""A recording's satellite states: precise orbits with their clock file, or the merged broadcast
navigation files; the combinations that make no sense are refused by name."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.precise_text import clock_text, sp3_text
from vo_doppler.errors import InputError
from vo_doppler.io.rinex_write import write_nav
from vo_doppler.io.satellite_states import read_satellite_states, state_problems
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.precise_orbits import PreciseOrbits
from vo_doppler.sim.constellation import broadcast_ephemerides

T0 = 1_400_000_000.0
SATS = ["G05", "G07"]


def _orbit_files(folder):
    t = T0 + np.arange(3) * 900.0
    position = np.full((3, 2, 3), 2.0e7)
    clock = np.full((3, 2), 1e-5)
    orbits, clocks = folder / "x.sp3", folder / "x.clk"
    orbits.write_text(sp3_text(t, SATS, position, clock))
    bias = np.array([[2e-5, 3e-5]] * 3)
    clocks.write_text(clock_text(t, SATS, bias))
    return orbits, clocks


def test_precise_orbits_come_with_their_clock_file_attached(tmp_path):
    orbits, clocks = _orbit_files(tmp_path)
    alone = read_satellite_states(orbits=orbits)
    assert isinstance(alone, PreciseOrbits) and alone.clocks is None
    assert list(alone.sat_id) == SATS and alone.interval_s == 900.0
    both = read_satellite_states(nav=[tmp_path / "ignored.nav"], orbits=orbits, clocks=clocks)
    assert isinstance(both, PreciseOrbits)
    np.testing.assert_allclose(both.clocks.bias_s, [[2e-5, 3e-5]] * 3, rtol=1e-12)
    np.testing.assert_array_equal(both.position, alone.position)
    assert state_problems(both) == ()


def test_navigation_files_are_merged(tmp_path):
    records = broadcast_ephemerides(T0, T0 + 600.0, "GE")
    gps = [r for r in records if r.system == "G"]
    galileo = [r for r in records if r.system == "E"]
    write_nav(tmp_path / "g.nav", gps)
    write_nav(tmp_path / "e.nav", galileo)
    navigation = read_satellite_states(nav=[tmp_path / "g.nav", tmp_path / "e.nav"])
    assert isinstance(navigation, Navigation)
    assert sorted(set(navigation.kepler.system)) == ["E", "G"]
    assert len(navigation.kepler) == len(gps) + len(galileo)
    assert state_problems(navigation) == navigation.problems == ()


def test_a_clock_file_without_orbits_or_no_states_at_all_are_refused(tmp_path):
    _, clocks = _orbit_files(tmp_path)
    with pytest.raises(InputError, match=r"x\.clk: a clock file needs precise orbits \(SP3\)"):
        read_satellite_states(nav=[tmp_path / "a.nav"], clocks=clocks)
    with pytest.raises(InputError, match=r"^no satellite states: give navigation files or precise"):
        read_satellite_states()
    with pytest.raises(InputError, match=r"^no satellite states"):
        read_satellite_states(nav=[])


def test_the_problems_of_a_navigation_file_are_its_skipped_records():
    navigation = Navigation(None, None, problems=("a.nav:12: record skipped",))
    assert state_problems(navigation) == ("a.nav:12: record skipped",)
