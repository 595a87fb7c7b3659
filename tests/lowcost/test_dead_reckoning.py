"""Dead reckoning ([KZ] Eq. 15–17): exact cases."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.lowcost.dead_reckoning import (
    dead_reckon,
)
from vo_doppler.lowcost.drift import closed_loop_gap


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(0.0, 30.0), min_size=1, max_size=50),
    st.floats(-np.pi, np.pi),
)
def test_dead_reckoning_with_zero_rate_is_a_straight_line(steps, yaw0):
    steps = np.asarray(steps)
    t = np.arange(len(steps) + 1, dtype=float)
    dr = dead_reckon(t, steps, np.zeros(len(steps)), yaw0, start=(3.0, -2.0))
    distance = np.concatenate([[0.0], np.cumsum(steps)])
    np.testing.assert_allclose(dr.east, 3.0 + distance * np.cos(yaw0), atol=1e-9)
    np.testing.assert_allclose(dr.north, -2.0 + distance * np.sin(yaw0), atol=1e-9)
    np.testing.assert_allclose(np.cos(dr.yaw), np.cos(yaw0), atol=1e-12)


def test_dead_reckoning_yaw_convention_and_closed_polygon():
    dr = dead_reckon(np.arange(2.0), [1.0], [0.0], yaw0=np.pi / 2)
    assert dr.east[-1] == pytest.approx(0.0, abs=1e-12) and dr.north[-1] == pytest.approx(1.0)
    # A positive (CCW) yaw rate turns left: from east, a quarter turn ends heading north.
    n = 36
    radius = 50.0
    chord = 2 * radius * np.sin(np.pi / n)
    dr = dead_reckon(np.arange(n + 1.0), np.full(n, chord), np.full(n, 2 * np.pi / n), 0.0)
    assert dr.north[n // 4] > 0 and dr.east[n // 4] == pytest.approx(radius, abs=1e-9)
    gap = closed_loop_gap(dr.east, dr.north)
    assert gap.gap_m < 1e-9 and gap.length_m == pytest.approx(n * chord)
    assert dr.yaw[-1] == pytest.approx(0.0, abs=1e-9)
