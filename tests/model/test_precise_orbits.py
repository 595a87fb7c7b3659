"""Precise orbits: the nominal epoch spacing and a clock file attached without changing them."""

from __future__ import annotations

import math

import numpy as np

from vo_doppler.model.precise_orbits import PreciseOrbits, SatelliteClocks


def _orbits(t) -> PreciseOrbits:
    n = len(t)
    return PreciseOrbits(
        t=np.asarray(t, dtype=float),
        sat_id=np.array(["G05"]),
        position=np.zeros((n, 1, 3)),
        clock_s=np.zeros((n, 1)),
    )


def test_the_interval_is_the_median_epoch_spacing():
    assert _orbits([0.0, 900.0, 1800.0, 3600.0, 4500.0]).interval_s == 900.0  # one gap
    assert math.isnan(_orbits([0.0]).interval_s)


def test_clocks_are_attached_to_a_copy():
    orbits = _orbits([0.0, 300.0])
    clocks = SatelliteClocks(np.array([0.0, 30.0]), np.array(["G05"]), np.array([[1e-5], [2e-5]]))
    attached = orbits.with_clocks(clocks)
    assert attached.clocks is clocks and orbits.clocks is None
    np.testing.assert_array_equal(attached.t, orbits.t)
    assert attached.sat_id is orbits.sat_id
