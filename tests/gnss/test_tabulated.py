"""Satellite states from a provider's table: Earth-rotation into the reception frame, exact on a
synthetic case; on the real GSDC fixture the phone (static) comes out at rest from its Doppler."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.ephemeris import OMEGA_E
from vo_doppler.gnss.lsq import weighted_lsq
from vo_doppler.gnss.signals import wavelengths
from vo_doppler.gnss.tabulated import table_transmit_states
from vo_doppler.io.gsdc import read_device_gnss
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


@pytest.mark.shared_data
def test_static_phone_doppler_velocity_from_gsdc_states_is_near_zero():
    recording = read_device_gnss(require_shared("android_pixel7pro/device_gnss.csv"))
    obs = recording.observations
    rows = obs.select(code="D1C")
    lam = np.full(len(rows), np.nan)
    for system in np.unique(rows.system):
        at = rows.system == system
        lam[at] = wavelengths(rows.system[at], rows.prn[at], "D1C", obs.header.glonass_channels)
    epoch = np.searchsorted(obs.epoch_time, rows.time)
    receiver = recording.receiver_ecef[epoch]
    states, _ = table_transmit_states(
        recording.satellites, rows.system, rows.prn, rows.time, receiver
    )
    los = states.position - receiver
    los /= np.linalg.norm(los, axis=1, keepdims=True)
    # ρ̇ − e·v_s + c·δṫ_s = −e·v + b  (doppler_velocity module), ρ̇ = −λ·D
    y = (
        -lam * rows.value
        - np.einsum("ij,ij->i", los, states.velocity)
        + SPEED_OF_LIGHT * states.clock_drift
    )
    speeds, rms = [], []
    for k in range(obs.epoch_time.size):
        r = (epoch == k) & states.valid & np.isfinite(lam)
        assert r.sum() >= 15
        H = np.hstack([-los[r], np.ones((r.sum(), 1))])
        x, _, residuals = weighted_lsq(H, y[r], np.ones(r.sum()))
        speeds.append(np.linalg.norm(x[:3]))
        rms.append(np.sqrt(np.mean(residuals**2)))
    assert np.median(speeds) < 0.1
    assert max(speeds) < 0.3
    assert np.median(rms) < 0.06
