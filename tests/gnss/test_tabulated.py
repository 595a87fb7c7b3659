"""Satellite states from a provider's table: Earth rotation into the reception frame, exact."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.ephemeris import OMEGA_E
from vo_doppler.gnss.tabulated import table_transmit_states
from vo_doppler.model.satellite_table import SatelliteTable


def test_states_are_rotated_by_the_earth_rotation_during_travel():
    position = np.array([[2.0e7, 1.0e7, 1.2e7]])
    velocity = np.array([[100.0, -2500.0, 3000.0]])
    table = SatelliteTable(
        np.array([1000.0]), np.array(["G"]), np.array([5], dtype=np.int16), position, velocity,
        np.array([1e-4]), np.array([2e-12]), np.array([0.07]),
    )  # fmt: skip
    states, travel = table_transmit_states(
        table, ["G", "G", "E"], [5, 5, 5], [1000.0, 1001.0, 1000.0]
    )
    assert states.valid.tolist() == [True, False, False]
    assert travel[0] == 0.07
    angle = OMEGA_E["G"] * 0.07
    rotated = np.array(
        [
            np.cos(angle) * 2.0e7 + np.sin(angle) * 1.0e7,
            -np.sin(angle) * 2.0e7 + np.cos(angle) * 1.0e7,
            1.2e7,
        ]
    )
    np.testing.assert_allclose(states.position[0], rotated, rtol=1e-15)
    assert states.clock_bias_s[0] == 1e-4 and states.clock_drift[0] == 2e-12
    receiver = np.array([6.4e6, 0.0, 0.0])
    states, travel = table_transmit_states(table, "G", 5, 1000.0, receiver)
    geometric = np.linalg.norm(states.position[0] - receiver) / SPEED_OF_LIGHT
    assert travel[0] == pytest.approx(geometric, abs=1e-12)
