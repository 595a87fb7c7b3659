"""Simulator GNSS: RINEX files read back to the generating values; Doppler against the analytic
and finite-difference range rate; the project's GNSS solvers recover the simulated truth."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from vo_doppler.geo import SPEED_OF_LIGHT, EnuFrame
from vo_doppler.gnss.pipeline import gnss_velocity
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.rinex_write import nav_number, rounded_nav_value, write_nav
from vo_doppler.sim.constellation import (
    KLOBUCHAR,
    REFERENCE_EPOCH,
    broadcast_ephemerides,
    navigation_from_records,
)
from vo_doppler.sim.gnss_observations import GnssSimConfig, range_and_rate
from vo_doppler.sim.urban_canyon import CityConfig, UrbanCanyonConfig, simulate_urban_canyon

T0 = REFERENCE_EPOCH + 2 * 3600.0 + 600.0
FRAME = EnuFrame(np.radians(35.6938), np.radians(139.7034), 77.0)


@pytest.fixture(scope="module")
def open_sky(tmp_path_factory):
    """A 12-s noise-free drive among 1-m 'buildings' (every satellite above the mask seen)."""
    out = tmp_path_factory.mktemp("open_sky")
    config = UrbanCanyonConfig(
        duration_s=12.0,
        seed=5,
        render=False,
        city=CityConfig(height_range_m=(0.5, 1.0)),
        gnss=GnssSimConfig(noise=False),
    )
    return out, simulate_urban_canyon(out, config)


@given(st.floats(min_value=-1e9, max_value=1e9, allow_nan=False))
def test_nav_number_is_19_characters_and_rounds_once(value):
    text = nav_number(value)
    assert len(text) == 19
    rounded = rounded_nav_value(value)
    assert rounded_nav_value(rounded) == rounded
    assert abs(rounded - value) <= 5e-13 * abs(value) or (rounded == 0.0 and abs(value) < 1e-99)


def test_navigation_file_reads_back_to_the_generating_records(tmp_path):
    records = broadcast_ephemerides(T0, T0 + 3 * 3600.0)
    path = tmp_path / "brdc.nav"
    write_nav(path, records, klobuchar=KLOBUCHAR)
    nav = read_nav(path)
    expected = navigation_from_records(records)
    assert nav.problems == ()
    assert len(nav.kepler) == len(records) == 55 * 3
    assert set(nav.kepler.system) == {"G", "E"}
    np.testing.assert_array_equal(nav.kepler.prn, expected.kepler.prn)
    np.testing.assert_array_equal(nav.kepler.toc, expected.kepler.toc)
    for name, values in expected.kepler.params.items():
        np.testing.assert_array_equal(nav.kepler[name], values, err_msg=name)
    np.testing.assert_allclose(nav.klobuchar, KLOBUCHAR, rtol=1e-4)


def test_orbits_are_gps_and_galileo_like():
    records = broadcast_ephemerides(T0, T0)
    sqrt_a = np.array([r.params["sqrt_a"] for r in records])
    incl = np.degrees([r.params["i0"] for r in records])
    gps = np.array([r.system == "G" for r in records])
    assert gps.sum() == 31 and (~gps).sum() == 24
    np.testing.assert_allclose(sqrt_a[gps] ** 2, 26_559_700.0, rtol=1e-9)
    np.testing.assert_allclose(sqrt_a[~gps] ** 2, 29_599_800.0, rtol=1e-9)
    assert np.all(np.abs(incl[gps] - 55.0) < 4.0) and np.all(np.abs(incl[~gps] - 56.0) < 2.0)


@pytest.mark.slow
def test_observation_file_reads_back_to_the_generating_values(open_sky):
    out, sim = open_sky
    gnss = sim.gnss
    obs = read_obs(out / "gnss" / "rover.obs")
    assert obs.problems == ()
    np.testing.assert_allclose(obs.epoch_time, gnss.epoch_time, atol=1e-6)
    expected_sats = gnss.satellite
    for column, code in enumerate(("C1C", "D1C", "S1C")):
        chosen = obs.select(code=code)
        got_epoch = np.round((chosen.time - gnss.epoch_time[0]) * 20.0).astype(int)
        got = sorted(zip(got_epoch, chosen.satellites(), chosen.value, strict=True))
        want_values = gnss.obs_epochs().values[:, column]
        want = sorted(zip(gnss.epoch, expected_sats, want_values, strict=True))
        assert [g[:2] for g in got] == [w[:2] for w in want]
        np.testing.assert_allclose(
            [g[2] for g in got], [w[2] for w in want], rtol=0, atol=5e-4 + 1e-9
        )
    ssi = obs.select(code="D1C").ssi
    assert ssi.min() >= 5 and ssi.max() <= 8


@pytest.mark.slow
def test_doppler_is_minus_range_rate_over_wavelength(open_sky):
    _, sim = open_sky
    gnss = sim.gnss
    np.testing.assert_allclose(gnss.wavelength_m, SPEED_OF_LIGHT / 1575.42e6)
    np.testing.assert_allclose(
        -gnss.doppler_hz * gnss.wavelength_m, gnss.range_rate_true_mps, atol=1e-9
    )


def test_analytic_range_rate_matches_finite_difference_to_a_millimetre_per_second():
    nav = navigation_from_records(broadcast_ephemerides(T0, T0))
    systems = nav.kepler.system
    prns = nav.kepler.prn
    velocity_enu = np.array([9.0, -4.0, 0.3])
    r0 = FRAME.enu_to_ecef(np.array([30.0, -20.0, 1.6]))
    v = velocity_enu @ FRAME.rotation
    t = np.full(len(prns), T0 + 100.0)
    h = 0.25  # exact in float64; a shorter step drowns in the rounding of 1.4e9-s times

    def geometry(dt):
        return range_and_rate(nav, systems, prns, t + dt, np.tile(r0 + v * dt, (len(t), 1)), v)

    centre = geometry(0.0)
    difference = (geometry(h).range_m - geometry(-h).range_m) / (2 * h)
    assert centre.valid.all()
    assert np.max(np.abs(difference - centre.range_rate_mps)) < 1e-3
    first_order = np.einsum("ij,ij->i", centre.los_ecef, -np.tile(v, (len(t), 1)))
    assert np.max(np.abs(centre.range_rate_mps - first_order)) > 100.0  # satellites move


@pytest.mark.slow
def test_doppler_of_an_offset_antenna_is_its_analytic_range_rate_in_a_turn(tmp_path):
    """Antenna 1.5 m ahead of and 0.7 m right of the rear axle: noise-free Doppler equals the
    analytic range rate of that point. Its velocity is the rear axle's (speed along the yaw)
    plus the rate of change of the rotated lever arm R(ψ)·r, differentiated numerically from
    the poses (an independent check of ω × r)."""
    lever = np.array([1.5, -0.7, 1.6])
    config = UrbanCanyonConfig(
        duration_s=12.0,
        seed=5,
        render=False,
        initial_speed_mps=8.0,
        city=CityConfig(height_range_m=(0.5, 1.0)),
        gnss=GnssSimConfig(noise=False),
        antenna_lever_arm_m=tuple(lever),
    )
    sim = simulate_urban_canyon(tmp_path, config)
    gnss = sim.gnss
    t = gnss.t_true[gnss.epoch]
    axle = sim.vehicle(t)
    assert np.max(np.abs(axle.yaw_rate)) > 0.3  # the drive turns

    def offset(times):
        return sim.vehicle(times).T_world_vehicle[:, :3, :3] @ lever

    h = 1e-4
    axle_velocity = axle.speed[:, None] * np.column_stack(
        [np.cos(axle.yaw), np.sin(axle.yaw), np.zeros(len(t))]
    )
    velocity = axle_velocity + (offset(t + h) - offset(t - h)) / (2 * h)
    position = offset(t) + np.column_stack([axle.xy, np.zeros(len(t))])
    nav = navigation_from_records(broadcast_ephemerides(T0, T0 + 12.0))

    def range_rate(velocity_enu):
        geometry = range_and_rate(
            nav,
            gnss.system,
            gnss.prn,
            t,
            sim.frame.enu_to_ecef(position),
            velocity_enu @ sim.frame.rotation,
        )
        clock = SPEED_OF_LIGHT * (gnss.clock.drift[gnss.epoch] - geometry.sat_clock_drift)
        return geometry.range_rate_mps + clock

    measured = -gnss.doppler_hz * gnss.wavelength_m
    assert np.max(np.abs(measured - range_rate(velocity))) < 1e-3
    assert np.max(np.abs(measured - range_rate(axle_velocity))) > 0.2  # ω·|r| ≈ 0.5 × 1.65 m/s
    manifest = yaml.safe_load((tmp_path / "sequence.yaml").read_text())
    assert manifest["gnss"]["antenna_lever_arm_m"] == [1.5, -0.7, 1.6]


@pytest.mark.slow
def test_gnss_solvers_recover_the_simulated_truth(open_sky):
    out, sim = open_sky
    obs = read_obs(out / "gnss" / "rover.obs")
    nav = read_nav(out / "gnss" / "brdc.nav")
    result = gnss_velocity(obs, nav, systems="GE")
    velocity = result.velocity
    assert velocity.valid.all()
    config = sim.config
    truth = sim.vehicle(sim.gnss.t_true)
    v_true = truth.speed[:, None] * np.column_stack([np.cos(truth.yaw), np.sin(truth.yaw)])
    error = np.linalg.norm(velocity.velocity_enu[:, :2] - v_true, axis=1)
    assert np.median(error) < 0.005
    moving = truth.speed > 1.0
    assert np.max(error[moving]) < 0.05
    position = sim.frame.ecef_to_enu(result.spp.position_ecef)
    expected = np.column_stack([truth.xy, np.full(len(truth.t), config.antenna_lever_arm_m[2])])
    assert np.median(np.linalg.norm(position - expected, axis=1)) < 0.05


@pytest.mark.slow
def test_noise_scales_with_cn0(tmp_path):
    config = UrbanCanyonConfig(
        duration_s=6.0, seed=2, render=False, city=CityConfig(height_range_m=(0.5, 1.0))
    )
    noisy = simulate_urban_canyon(tmp_path, config).gnss
    residual = -noisy.doppler_hz * noisy.wavelength_m - noisy.range_rate_true_mps
    scale = 10.0 ** ((45.0 - noisy.cn0_dbhz) / 20.0)
    normalised = residual / (0.03 * scale)
    assert 0.9 < np.std(normalised) < 1.1


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::FutureWarning")
def test_an_independent_reader_agrees(tmp_path):
    """georinex (test-only) reads the written files to the same values."""
    georinex = pytest.importorskip("georinex")
    config = UrbanCanyonConfig(duration_s=1.0, seed=7, render=False)
    sim = simulate_urban_canyon(tmp_path, config)
    obs = georinex.load(tmp_path / "gnss" / "rover.obs")
    gnss = sim.gnss
    for row in range(len(gnss.epoch)):
        sample = obs.sel(time=obs.time[gnss.epoch[row]], sv=gnss.satellite[row])
        assert float(sample["C1C"]) == pytest.approx(gnss.pseudorange_m[row], abs=5e-4)
        assert float(sample["D1C"]) == pytest.approx(gnss.doppler_hz[row], abs=5e-4)
    nav = georinex.load(tmp_path / "gnss" / "brdc.nav")
    mine = read_nav(tmp_path / "gnss" / "brdc.nav")
    for k, sat in enumerate(
        np.char.add(mine.kepler.system, np.char.zfill(mine.kepler.prn.astype(str), 2))
    ):
        record = nav.sel(sv=str(sat)).dropna("time", how="all")
        assert float(record["sqrtA"][0]) == mine.kepler["sqrt_a"][k]
        assert float(record["M0"][0]) == mine.kepler["m0"][k]
        assert float(record["Omega0"][0]) == mine.kepler["omega0"][k]
