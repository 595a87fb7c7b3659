"""The static Pixel 7 Pro of the GSDC fixture comes out at rest from its own Doppler, with the
satellite states of device_gnss.csv (no navigation file) through gnss.tabulated."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.lsq import weighted_lsq
from vo_doppler.gnss.signals import wavelengths
from vo_doppler.gnss.tabulated import table_transmit_states
from vo_doppler.io.gsdc import read_device_gnss


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
