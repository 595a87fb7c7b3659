"""Doppler velocity: exact synthetic inversion, availability rules, real recordings."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.geo import SPEED_OF_LIGHT, ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.gnss.doppler_velocity import (
    doppler_rows,
    doppler_velocity,
    solve_velocity,
    vertical_velocity_plausible,
)
from vo_doppler.gnss.satellite_source import transmit_states
from vo_doppler.gnss.signals import wavelengths
from vo_doppler.gnss.spp import receiver_positions, solve_spp
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.model.observations import Observations, ObsHeader

RECEIVER = np.array([-3817680.9841, 3562840.0688, 3650158.4543])
T0 = 1403252400.0  # 2024-06-24 08:20:00 GPST
ENU_TO_ECEF = ecef_to_enu_rotation(*(float(a) for a in ecef_to_geodetic(RECEIVER)[:2])).T
VELOCITY = ENU_TO_ECEF @ np.array([-3.2, 8.5, 0.3])  # a car at 9.1 m/s up a 3.3 % grade
DRIFT_MPS = -135.0
SATELLITES = {"G": (5, 6, 7, 11, 13, 20), "E": (4, 10, 12), "R": (1, 3, 11), "C": (23, 25, 32)}
CODES = {"G": ("D1C", "D2W", "D5Q"), "E": ("D1C", "D7Q"), "R": ("D1C", "D2C"), "C": ("D2I",)}
GLONASS_CHANNELS = {1: 1, 3: 5, 11: 0}


@pytest.fixture(scope="module")
def nav():
    return read_nav(require_shared("septentrio_static/base.nav"))


def _synthetic_obs(nav, n_epochs=3, satellites=SATELLITES, velocity=VELOCITY) -> Observations:
    """Noise-free Doppler of a receiver at RECEIVER moving at ``velocity`` (ECEF) with clock
    drift."""
    codes = sorted({c for cs in CODES.values() for c in cs})
    rows = {k: [] for k in ("time", "system", "prn", "code", "value")}
    for k in range(n_epochs):
        t = T0 + k
        for system, prns in satellites.items():
            prn = np.array(prns)
            states, _ = transmit_states(nav, system, prn, t, receiver_ecef=RECEIVER)
            e = states.position - RECEIVER
            e /= np.linalg.norm(e, axis=1, keepdims=True)
            rate = (
                np.einsum("ij,ij->i", e, states.velocity - velocity)
                + DRIFT_MPS
                - SPEED_OF_LIGHT * states.clock_drift
            )
            for code in CODES[system]:
                lam = wavelengths(np.full(prn.size, system), prn, code, GLONASS_CHANNELS)
                rows["time"].extend([t] * prn.size)
                rows["system"].extend([system] * prn.size)
                rows["prn"].extend(prns)
                rows["code"].extend([codes.index(code)] * prn.size)
                rows["value"].extend(np.nan_to_num(-rate / lam, nan=1234.0))  # no ephemeris
    header = ObsHeader(
        path=None,
        version=3.04,
        system="M",
        marker_name="",
        receiver_type="",
        approx_position=RECEIVER,
        interval=1.0,
        obs_types={s: CODES[s] for s in satellites},
        glonass_channels=GLONASS_CHANNELS,
        time_system="GPS",
        leap_seconds=18,
        signal_strength_unit="",
        n_lines=0,
    )
    n = len(rows["time"])
    return Observations(
        header=header,
        time=np.array(rows["time"]),
        system=np.array(rows["system"], dtype="U1"),
        prn=np.array(rows["prn"], dtype=np.int16),
        code=np.array(rows["code"], dtype=np.int16),
        codes=tuple(codes),
        value=np.array(rows["value"]),
        lli=np.full(n, -1, dtype=np.int8),
        ssi=np.full(n, -1, dtype=np.int8),
        epoch_time=T0 + np.arange(n_epochs, dtype=float),
        epoch_flag=np.zeros(n_epochs, dtype=np.int8),
    )


def test_exact_synthetic_doppler_is_inverted(nav):
    obs = _synthetic_obs(nav)
    solution, rows = doppler_velocity(obs, nav, RECEIVER, systems="GREC", elevation_mask_rad=-1.0)
    assert solution.valid.all()
    np.testing.assert_allclose(solution.velocity_ecef, np.tile(VELOCITY, (3, 1)), atol=1e-6)
    np.testing.assert_allclose(solution.clock_drift_mps, DRIFT_MPS, atol=1e-6)
    assert np.all(solution.n_excluded == 0)
    assert np.all(solution.residual_rms_mps < 1e-6)
    assert rows.n_no_ephemeris == 0
    assert np.all(solution.n_sat == 15)
    assert set(np.unique(rows.code)) == {"D1C", "D2W", "D5Q", "D7Q", "D2C", "D2I"}
    # the row model stated in DopplerRows: range_rate = los·(sat_vel − v) + b − sat drift
    model = (
        np.einsum("ij,ij->i", rows.los, rows.sat_velocity - VELOCITY)
        + DRIFT_MPS
        - rows.sat_clock_drift
    )
    np.testing.assert_allclose(rows.range_rate, model, atol=1e-6)
    np.testing.assert_allclose(solution.speed_mps, np.hypot(3.2, 8.5), atol=1e-6)  # not 0.3 up


@pytest.mark.parametrize(
    "up_mps, plausible",
    [(0.0, True), (2.7, True), (-2.7, True), (2.8, False), (-11.2, False)],
)
def test_a_car_does_not_climb_steeper_than_its_road(nav, up_mps, plausible):
    """At 9.1 m/s with σ 0.1·speed + 0.1 m/s the gate is 3·0.914 = 2.74 m/s (a 30 % grade): a
    velocity solved exactly that climbs or falls beyond it is not valid."""
    velocity = ENU_TO_ECEF @ np.array([-3.2, 8.5, up_mps])
    obs = _synthetic_obs(nav, n_epochs=1, velocity=velocity)
    solution, _ = doppler_velocity(obs, nav, RECEIVER, systems="GREC", elevation_mask_rad=-1.0)
    np.testing.assert_allclose(solution.velocity_enu[0], [-3.2, 8.5, up_mps], atol=1e-6)
    assert bool(solution.valid[0]) == plausible == bool(solution.verified[0])


def test_the_vertical_gate_widens_with_speed_and_with_the_solutions_own_sigma():
    still = np.zeros((3, 3))
    assert vertical_velocity_plausible(np.array([0.0, 0.0, 0.29]), still)
    assert not vertical_velocity_plausible(np.array([0.0, 0.0, 0.31]), still)
    gate = 3.0 * np.hypot(3.0, 0.1)  # at 30 m/s
    assert vertical_velocity_plausible(np.array([30.0, 0.0, gate - 0.01]), still)
    assert not vertical_velocity_plausible(np.array([30.0, 0.0, gate + 0.01]), still)
    uncertain = np.diag([0.0, 0.0, 4.0])
    assert vertical_velocity_plausible(np.array([0.0, 0.0, 5.9]), uncertain)
    assert not vertical_velocity_plausible(np.array([0.0, 0.0, 6.1]), uncertain)


def test_one_faulty_satellite_is_excluded(nav):
    obs = _synthetic_obs(nav, n_epochs=1)
    value = obs.value.copy()
    rng = np.random.default_rng(1)
    value += rng.normal(0.0, 0.01, value.size)  # about 2 mm/s of noise
    bad = (obs.system == "G") & (obs.prn == 20)  # elevation 50°
    value[bad] += 30.0  # 30 Hz ≈ 6 m/s on one satellite
    faulty = Observations(**{**obs.__dict__, "value": value})
    solution, _ = doppler_velocity(faulty, nav, RECEIVER, systems="GREC")
    assert solution.n_excluded[0] == 3
    np.testing.assert_allclose(solution.velocity_ecef[0], VELOCITY, atol=0.05)


def test_fewer_than_four_satellites_is_unavailable(nav):
    obs = _synthetic_obs(nav, n_epochs=2, satellites={"G": (5, 6, 7)})
    solution, rows = doppler_velocity(obs, nav, RECEIVER, systems="G", elevation_mask_rad=-1.0)
    assert len(rows) == 2 * 3 * 3
    assert not solution.valid.any()
    assert np.isnan(solution.velocity_enu).all()
    assert np.all(solution.n_sat == 3)


def test_satellites_without_ephemeris_are_skipped_and_counted(nav):
    satellites = {"G": (5, 6, 7, 11, 13, 20, 31), "R": (2,)}  # no G31, R02 unhealthy
    obs = _synthetic_obs(nav, n_epochs=2, satellites=satellites)
    rows = doppler_rows(obs, nav, RECEIVER, "GR", elevation_mask_rad=-1.0)
    assert rows.n_no_ephemeris == 2 * 3 + 2 * 2
    assert any(m.startswith("G31") for m in rows.missing)
    assert any(m.startswith("R02") for m in rows.missing)
    solution = solve_velocity(rows, obs.epoch_time)
    np.testing.assert_allclose(solution.velocity_ecef, np.tile(VELOCITY, (2, 1)), atol=1e-6)


def test_a_mask_above_every_satellite_says_so(nav, caplog):
    obs = _synthetic_obs(nav, n_epochs=2)
    highest = np.degrees(
        np.max(doppler_rows(obs, nav, RECEIVER, elevation_mask_rad=-1.0).elevation)
    )
    with caplog.at_level("WARNING"):
        rows = doppler_rows(obs, nav, RECEIVER, elevation_mask_rad=np.radians(89.0))
    assert len(rows.t) == 0 and rows.n_below_mask > 0
    assert (
        f"every Doppler row lies below the elevation mask of 89.0° (the highest satellite at "
        f"{highest:.1f}°): no row is left"
    ) in caplog.text


@pytest.fixture(scope="module")
def septentrio():
    obs = read_obs(require_shared("septentrio_static/rover.obs"))
    nav = read_nav(require_shared("septentrio_static/base.nav"))
    spp = solve_spp(obs, nav, "GREC")
    return obs, nav, receiver_positions(spp, obs.header.approx_position)


@pytest.mark.slow
@pytest.mark.shared_data
@pytest.mark.parametrize("systems", ["GREJC", "G"])
def test_static_septentrio_speed(septentrio, systems):
    obs, nav, position = septentrio
    solution, _ = doppler_velocity(obs, nav, position, systems=systems)
    speed = solution.speed_mps
    assert solution.valid.all()
    assert np.median(speed) <= 0.02
    assert np.percentile(speed, 95) <= 0.05


@pytest.mark.shared_data
def test_yamatogawa_walk_speeds():
    obs = read_obs(require_shared("yamatogawa_ublox_walk/yamatogawa_rover.obs"))
    nav = read_nav(require_shared("yamatogawa_ublox_walk/brdc0060.10n"))
    position = receiver_positions(solve_spp(obs, nav, "G"), obs.header.approx_position)
    solution, _ = doppler_velocity(obs, nav, position, systems="G")
    t = solution.t - solution.t[0]
    speed = solution.speed_mps
    # Three noisy epochs (residual RMS 0.12-0.32 m/s, 2-3 times their neighbours') climb or
    # fall at 0.6-1.1 m/s while walking at 0.8 m/s: not valid, by the vertical test alone.
    invalid = ~solution.valid
    assert np.count_nonzero(invalid) == 3 and solution.n_sat[invalid].min() >= 5
    assert np.all(np.abs(solution.velocity_enu[invalid, 2]) > 0.6)
    walking = speed[t > 70]
    assert 0.4 <= np.median(walking) <= 2.0
    assert np.percentile(walking, 90) <= 2.0
    # raw u-blox Doppler noise (≈0.2 m/s per satellite) keeps the standstill median near 0.12 m/s
    assert np.median(speed[t < 55]) <= 0.15


def test_the_horizontal_protection_grows_as_satellites_are_lost(nav):
    """Fifteen satellites all over the sky control each other: one undetected bias (on all three
    signals of a satellite) moves the velocity by decimetres per second; with five the same
    test protects far less, with four not at all."""
    protection = {}
    for name, satellites in {
        "fifteen": SATELLITES,
        "five": {"G": (5, 6, 7, 11, 13)},
        "four": {"G": (5, 6, 7, 11)},
    }.items():
        obs = _synthetic_obs(nav, n_epochs=1, satellites=satellites)
        solution, _ = doppler_velocity(obs, nav, RECEIVER, systems="GREC", elevation_mask_rad=-1.0)
        protection[name] = solution.horizontal_protection_mps[0]
    assert 0.0 < protection["fifteen"] < 0.5
    assert protection["five"] > 10.0 * protection["fifteen"]
    assert np.isinf(protection["four"])
