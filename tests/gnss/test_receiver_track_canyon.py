"""The receiver track in a lasting street canyon (issue 29): where no fix anchors it, it is held
within what the lines of sight allow instead of carrying a velocity on for kilometres; and
without Doppler velocities it is the fixes as they are (issue 30: it was a LinAlgError)."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import REPO_ROOT
from tests.gnss.test_receiver_track import LAT, LON, ORIGIN, covariance, drive
from tests.helpers.precise_text import sp3_text
from vo_doppler.cli import main
from vo_doppler.geo import EnuFrame, ecef_to_enu_rotation
from vo_doppler.gnss.pipeline import gnss_velocity
from vo_doppler.gnss.receiver_track import TrackConfig, receiver_track, smoothed_track
from vo_doppler.gnss.satellite_source import satellite_source
from vo_doppler.io.obs_rows import observations_from_rows
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_write import write_nav
from vo_doppler.model.gpstime import calendar_to_gps_seconds
from vo_doppler.sim.constellation import KLOBUCHAR, broadcast_ephemerides
from vo_doppler.sim.gnss_observations import CODES, Boxes, GnssSimConfig, simulate_gnss

GPS_MIN_RANGE_M = 20_200e3
SATELLITE_SPEED_MPS = 3_900.0
LOS_LIMIT_MPS = 0.1
"""The largest range-rate error a position error may cause: |δr|·v_s,⊥/ρ (a GPS satellite at
zenith, moving across the line of sight at full speed), 0.1 m/s at |δr| = 518 m."""

RADIUS_M, SPEED_MPS = 150.0, 8.0
CANYON_S = 60.0


def los_error_mps(position_error_m: np.ndarray) -> np.ndarray:
    return position_error_m * SATELLITE_SPEED_MPS / GPS_MIN_RANGE_M


def circling(seconds: float, rate_hz: float = 1.0):
    """Times, ECEF positions and velocities of a car circling at 8 m/s (radius 150 m): a car
    that stays within 300 m of where the canyon began, however long it lasts."""
    return drive(seconds, RADIUS_M, SPEED_MPS, rate_hz)


def canyon_inputs(seconds: float, rng: np.random.Generator):
    """Fixes (5 m noise, σ 7 m) only before ``CANYON_S``; Doppler velocities (0.05 m/s noise)."""
    t, truth, velocity = circling(seconds)
    fixes = truth + rng.normal(0.0, 5.0, truth.shape)
    fixes[t >= CANYON_S] = np.nan
    measured = velocity + rng.normal(0.0, 0.05, velocity.shape)
    return t, truth, fixes, np.full(t.size, 7.0), measured


def error_m(position: np.ndarray, truth: np.ndarray) -> np.ndarray:
    return np.linalg.norm(position - truth, axis=1)


def test_a_two_satellite_canyon_holds_the_track_instead_of_carrying_the_last_velocity_on():
    """Two satellites for 24 min: neither a fix nor a velocity after 60 s. The track carried
    the last velocity on in a straight line (9 km off after 20 min: lines of sight 1.8 m/s
    off); now it holds the last trusted position and its σ grows with the distance the car
    can have covered."""
    t, truth, fixes, sigma, velocity = canyon_inputs(1500.0, np.random.default_rng(4))
    known = t < CANYON_S
    track = receiver_track(t, fixes, sigma, velocity, covariance(t.size, 0.05), known)
    error = error_m(track.position_ecef, truth)
    assert np.max(error[known]) < 3.0
    held = track.held
    start = np.flatnonzero(held)[0]
    assert CANYON_S < t[start] < CANYON_S + 30.0 and held[start:].all()
    assert np.all(track.position_ecef[held] == track.position_ecef[start - 1])
    assert error[start - 1] < 50.0
    assert np.max(error[held]) < 2.0 * RADIUS_M + error[start - 1] + 1.0
    assert np.max(los_error_mps(error)) < LOS_LIMIT_MPS
    straight_on = truth[known][-1] + (t - t[known][-1])[:, None] * velocity[known][-1]
    assert np.min(error_m(track.position_ecef, straight_on)[t > 1200.0]) > 8_000.0
    assert np.all(error[held] <= track.sigma_m[held])
    assert np.all(np.diff(track.sigma_m[held]) > 0.0)
    assert np.all(track.sigma_m[~held] <= 250.0)


def test_a_biased_velocity_is_integrated_only_while_its_drift_stays_within_the_bound():
    """Doppler velocities all along, from a 4-satellite canyon: biased by 0.4 m/s east, within
    their σ of 0.5 m/s. Integrated for 30 min they put the track 0.7 km off (0.13 m/s); the
    drift a bias as large as the σ gives, Σ δ (T3), ends the integration near 250 m and the
    track is held from there."""
    t, truth, fixes, sigma, velocity = canyon_inputs(1800.0, np.random.default_rng(5))
    east = ecef_to_enu_rotation(LAT, LON)[0]
    velocity = velocity + 0.4 * east
    known = np.ones(t.size, dtype=bool)
    track = receiver_track(t, fixes, sigma, velocity, covariance(t.size, 0.5), known)
    error = error_m(track.position_ecef, truth)
    assert np.max(los_error_mps(error)) < LOS_LIMIT_MPS
    start = np.flatnonzero(track.held)[0]
    assert 200.0 < t[start] < 900.0
    assert track.held[start:].all()
    assert 200.0 < track.sigma_m[start - 1] <= 250.0
    unbounded = TrackConfig(trusted_sigma_m=np.inf)
    integrated = smoothed_track(
        t, fixes, sigma, velocity, covariance(t.size, 0.5), known, unbounded
    )
    assert np.max(los_error_mps(error_m(integrated, truth))) > 0.12


def test_fixes_after_the_canyon_take_the_track_back_and_regular_fixes_hold_nothing():
    """A 10-min canyon between two stretches of fixes: held inside, on the fixes after it. A
    drive with a fix at every epoch holds nothing and keeps the smoother's positions."""
    rng = np.random.default_rng(6)
    t, truth, fixes, sigma, velocity = canyon_inputs(900.0, rng)
    after = t >= CANYON_S + 600.0
    fixes[after] = truth[after] + rng.normal(0.0, 5.0, truth[after].shape)
    known = (t < CANYON_S) | after
    track = receiver_track(t, fixes, sigma, velocity, covariance(t.size, 0.05), known)
    error = error_m(track.position_ecef, truth)
    assert np.max(error[after]) < 3.0 and not track.held[after].any()
    assert track.held[(t > CANYON_S + 60.0) & (t < CANYON_S + 540.0)].all()
    assert np.max(los_error_mps(error)) < LOS_LIMIT_MPS
    regular = circling(120.0, rate_hz=20.0)
    fixes = regular[1] + rng.normal(0.0, 10.0, regular[1].shape)
    args = (regular[0], fixes, np.full(fixes.shape[0], 14.0), regular[2])
    known = np.ones(fixes.shape[0], bool)
    track = receiver_track(*args, covariance(fixes.shape[0], 0.05), known)
    assert not track.held.any()
    unbounded = TrackConfig(trusted_sigma_m=np.inf)
    smoothed = smoothed_track(*args, covariance(fixes.shape[0], 0.05), known, unbounded)
    np.testing.assert_array_equal(track.position_ecef, smoothed)
    assert np.max(track.sigma_m) < 20.0
    assert np.max(error_m(track.position_ecef, regular[1])) < 3.0


@pytest.mark.parametrize("velocity", ["none known", "all NaN"])
def test_without_doppler_velocities_the_fixes_are_taken_as_they_are(velocity):
    """No velocity (no Doppler row, or none solved) and no fix at the first epoch: the
    tridiagonal system was singular ('1th leading minor not positive definite'). Now the
    fixes as they are, held between them."""
    t, truth, _ = circling(20.0)
    fixes = truth + np.random.default_rng(7).normal(0.0, 5.0, truth.shape)
    fixed = np.arange(t.size) % 3 == 1
    fixes[~fixed] = np.nan
    velocities = np.full_like(truth, np.nan) if velocity == "all NaN" else truth * 0.0
    known = np.full(t.size, velocity == "all NaN")
    track = receiver_track(
        t, fixes, np.full(t.size, 7.0), velocities, covariance(t.size, 1.0), known
    )
    np.testing.assert_allclose(track.position_ecef[fixed], fixes[fixed], atol=1e-6)
    neighbour = np.flatnonzero(fixed)[np.clip(np.arange(t.size) // 3, 0, fixed.sum() - 1)]
    np.testing.assert_allclose(track.position_ecef, fixes[neighbour], atol=1e-6)
    assert np.array_equal(track.held, ~fixed)
    assert np.all(np.isfinite(track.sigma_m))


def test_a_fix_without_sigma_is_no_fix():
    t, truth, velocity = circling(20.0)
    sigma = np.full(t.size, 7.0)
    sigma[:-2] = np.nan
    track = receiver_track(
        t, truth, sigma, velocity, covariance(t.size, 0.05), np.ones(t.size, bool)
    )
    np.testing.assert_allclose(track.position_ecef, truth, atol=0.05)
    sigma[-2] = np.nan
    assert (
        receiver_track(t, truth, sigma, velocity, covariance(t.size, 0.05), np.ones(t.size, bool))
        is None
    )


SAMPLE_GNSS = REPO_ROOT / "sample_sequences" / "urban_canyon_small" / "gnss"


def _glonass_without_channels(tmp_path: Path) -> tuple[Path, Path]:
    """The sample's Galileo rows renamed GLONASS (no GLONASS SLOT / FRQ # record) and precise
    orbits of those satellites (SP3 carries no frequency channel): SPP solves epochs, every
    Doppler row is dropped."""
    text = (SAMPLE_GNSS / "rover.obs").read_text()
    obs = tmp_path / "glonass.obs"
    obs.write_text(re.sub(r"(?m)^E(\d\d)", r"R\1", text.replace("E    3 C1C", "R    3 C1C")))
    source = satellite_source(read_nav(SAMPLE_GNSS / "brdc.nav"))
    t = float(calendar_to_gps_seconds(2025, 3, 14, 2, 10, 0)) - 2700.0 + 300.0 * np.arange(20)
    prns = [2, 3, 4, 10, 19, 21]
    position = np.zeros((t.size, len(prns), 3))
    clock = np.zeros((t.size, len(prns)))
    for j, prn in enumerate(prns):
        states = source.states(np.full(t.size, "E"), np.full(t.size, prn), t)
        position[:, j], clock[:, j] = states.position, states.clock_bias_s
    orbits = tmp_path / "glonass.sp3"
    orbits.write_text(sp3_text(t, [f"R{prn:02d}" for prn in prns], position, clock))
    return obs, orbits


def test_glonass_that_cannot_be_solved_is_an_input_error_not_an_internal_one(tmp_path, capsys):
    """Issue 30: ``gnss velocity --systems R`` on GLONASS rows without a frequency channel
    exited 3 (LinAlgError in receiver_track); now exit 1 saying no epoch could be solved,
    nothing written."""
    obs, orbits = _glonass_without_channels(tmp_path)
    out = tmp_path / "vel.csv"
    argv = ["gnss", "velocity", str(obs), "--orbits", str(orbits), "--systems", "R"]
    assert main([*argv, "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "no epoch could be solved" in err and "internal error" not in err
    assert not out.exists() and not out.with_suffix(".png").exists()


@pytest.mark.slow
def test_the_gnss_stage_in_a_simulated_two_satellite_canyon(tmp_path):
    """Through ``gnss_velocity``: a simulated 1 Hz drive circling at 8 m/s, two satellites
    (the highest) after 60 s for 21 min. The lines of sight's receiver positions were 9 km off
    at the end (1.8 m/s); now within the circle's diameter."""
    t0 = float(calendar_to_gps_seconds(2025, 3, 14, 2, 0, 0))
    seconds = 1260.0
    write_nav(tmp_path / "sim.nav", broadcast_ephemerides(t0, t0 + seconds, "GE"), 18, KLOBUCHAR)
    nav = read_nav(tmp_path / "sim.nav")
    frame = EnuFrame.from_ecef(ORIGIN)

    def motion(t):
        angle = SPEED_MPS * (t - t0) / RADIUS_M
        enu = RADIUS_M * np.stack([np.sin(angle), 1.0 - np.cos(angle), 0.0 * angle], axis=1)
        return enu, SPEED_MPS * np.stack([np.cos(angle), np.sin(angle), 0.0 * angle], axis=1)

    epochs = t0 + np.arange(0.0, seconds, 1.0)
    empty = Boxes(np.zeros((0, 3)), np.zeros((0, 3)))
    config = GnssSimConfig(rate_hz=1.0)
    sim = simulate_gnss(nav, frame, epochs, motion, empty, config, np.random.default_rng(8))
    keep = sim.epoch_time[sim.epoch] < t0 + CANYON_S
    for k in np.unique(sim.epoch[~keep]):
        rows = np.flatnonzero(sim.epoch == k)
        keep[rows[np.argsort(-sim.elevation[rows])[:2]]] = True
    rows = np.flatnonzero(keep)
    values = np.column_stack([sim.pseudorange_m, sim.doppler_hz, sim.cn0_dbhz])[rows]
    obs = observations_from_rows(
        tmp_path / "canyon.obs",
        "SIM",
        np.repeat(sim.epoch_time[sim.epoch[rows]], len(CODES)),
        np.repeat(sim.system[rows], len(CODES)),
        np.repeat(sim.prn[rows], len(CODES)),
        np.tile(np.array(CODES), rows.size),
        values.reshape(-1),
    )
    result = gnss_velocity(obs, nav, "GE")
    error = error_m(result.receiver_ecef, frame.enu_to_ecef(motion(sim.t_true)[0]))
    canyon = epochs >= t0 + CANYON_S
    assert result.spp.valid[canyon].sum() == 0
    assert np.max(error[~canyon]) < 3.0
    assert np.max(error[canyon]) < 2.0 * RADIUS_M + 50.0
    assert np.max(los_error_mps(error)) < LOS_LIMIT_MPS
