"""Phase-rate Doppler: exact on quadratic ranges, arcs broken by LLI and Doppler disagreement."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_shared
from tests.gnss.test_doppler_velocity import T0
from vo_doppler.gnss.doppler_velocity import doppler_velocity
from vo_doppler.gnss.phase_rate import carrier_phase_doppler
from vo_doppler.gnss.spp import receiver_positions, solve_spp
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.model.observations import Observations, ObsHeader

CODES = ("L1C", "D1C", "S1C")


def _obs(phase: np.ndarray, doppler: np.ndarray, lli: np.ndarray, t: np.ndarray) -> Observations:
    n = t.size
    header = ObsHeader(None, 3.04, "G", "", "", None, 1.0, {"G": CODES}, {}, "GPS", 18, "", 0)
    return Observations(
        header=header,
        time=np.concatenate([t, t, t]),
        system=np.full(3 * n, "G", dtype="U1"),
        prn=np.full(3 * n, 7, dtype=np.int16),
        code=np.repeat(np.arange(3, dtype=np.int16), n),
        codes=CODES,
        value=np.concatenate([phase, doppler, np.full(n, 44.0)]),
        lli=np.concatenate([lli, np.full(2 * n, -1)]).astype(np.int8),
        ssi=np.full(3 * n, 7, dtype=np.int8),
        epoch_time=t,
        epoch_flag=np.zeros(n, dtype=np.int8),
    )


def _doppler_of(obs: Observations) -> dict[float, float]:
    rows = obs.mask(code="D1C")
    return dict(zip(obs.time[rows].tolist(), obs.value[rows].tolist(), strict=True))


def test_quadratic_phase_gives_exact_rate():
    t = T0 + np.array([0.0, 1.0, 2.0, 3.0, 5.0, 5.5, 6.0])
    tau = t - T0
    phase = 1.0e6 - 2500.0 * tau + 1.25 * tau**2
    truth = 2500.0 - 2.5 * tau
    result = _doppler_of(carrier_phase_doppler(_obs(phase, truth + 0.5, np.zeros(7), t)))
    # ends and the 2 s gap (3 → 5) have no central difference
    assert sorted(result) == [T0 + 1, T0 + 2, T0 + 5.5]
    for time, value in result.items():
        assert value == pytest.approx(truth[tau == time - T0][0], abs=1e-7)


def test_loss_of_lock_and_disagreement_break_the_arc():
    t = T0 + np.arange(8.0)
    tau = t - T0
    phase = -1000.0 * tau
    doppler = np.full(8, 1000.0)
    doppler[5] = 1010.0  # disagrees by 10 Hz: an unflagged slip
    lli = np.zeros(8)
    lli[3] = 1  # loss of lock between epochs 2 and 3
    result = _doppler_of(carrier_phase_doppler(_obs(phase, doppler, lli, t)))
    assert sorted(result) == [T0 + 1, T0 + 4, T0 + 6]
    assert all(v == pytest.approx(1000.0) for v in result.values())


@pytest.mark.shared_data
def test_yamatogawa_standstill_with_phase_rate():
    obs = read_obs(require_shared("yamatogawa_ublox_walk/yamatogawa_rover.obs"))
    nav = read_nav(require_shared("yamatogawa_ublox_walk/brdc0060.10n"))
    position = receiver_positions(solve_spp(obs, nav, "G"), obs.header.approx_position)
    solution, _ = doppler_velocity(carrier_phase_doppler(obs), nav, position, systems="G")
    t = solution.t - solution.t[0]
    speed = solution.speed_mps
    assert np.nanmedian(speed[t < 60]) <= 0.05
    walking = speed[t > 70]
    assert 0.4 <= np.nanmedian(walking) <= 2.0
    assert np.nanpercentile(walking, 95) <= 2.0
    assert solution.valid.sum() >= obs.epoch_time.size - 3
