"""The antenna track: a moving car where it was at each epoch despite a bad fix, the fallbacks
without fixes, and what placed the heights, in words."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tests.helpers.velocity import velocity_solution
from vo_doppler.fusion.antenna_track import antenna_track
from vo_doppler.geo import EnuFrame
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution

ENU = EnuFrame(np.radians(37.7), np.radians(-122.5), 30.0)


def _gnss_solutions(t, fixes_enu, fix_sigma_m, velocity_enu, velocity_sigma_mps):
    """SPP and Doppler solutions (ECEF) from ENU fixes (NaN rows: no fix) and velocities."""
    n = len(t)
    fixes = ENU.enu_to_ecef(fixes_enu)
    valid = np.all(np.isfinite(fixes), axis=1)
    spp = SppSolution(
        t, fixes, {"G": np.zeros(n)}, np.full(n, 8), np.ones(n), np.full(n, 2.0), valid, 0,
        horizontal_sigma_m=np.full(n, np.sqrt(2.0) * fix_sigma_m),
    )  # fmt: skip
    velocity = VelocitySolution(
        t, velocity_enu @ ENU.rotation, velocity_enu, np.zeros(n),
        np.tile(np.eye(4) * velocity_sigma_mps**2, (n, 1, 1)), np.ones((n, 5)), np.full(n, 8),
        np.full(n, 8), np.zeros(n, dtype=int), np.zeros(n), np.ones(n, dtype=bool),
        untestable=np.zeros(n, dtype=bool),
    )  # fmt: skip
    return spp, velocity


def test_the_antenna_track_puts_a_moving_car_where_it_was_at_each_epoch_despite_a_bad_fix():
    """A car at a constant 20.6 m/s with fixes of σ 2 m per horizontal axis (4 m up) and exact
    Doppler velocities (σ 0.02 m/s): the track at the first epoch is the fixes carried back, a
    robust mean of N = 99 good fixes: σ/√(0.95 N) (the Cauchy weights' 95 % efficiency),
    0.21 m per horizontal axis and 0.41 m up, within 4 σ. The first fix, 200 m off, would move
    a plain mean by 2 m; the old median of the first 5 s of fixes lay 51.5 m ahead."""
    rng = np.random.default_rng(7)
    t = 1000.0 + np.arange(100) * 0.1
    velocity = np.tile([20.0, 5.0, 0.2], (t.size, 1))
    truth = np.array([30.0, -40.0, 12.0]) + (t - t[0])[:, None] * velocity[0]
    noise = rng.normal(size=truth.shape) * [2.0, 2.0, 4.0]
    fixes = truth + noise
    fixes[0, 0] += 200.0
    spp, doppler = _gnss_solutions(t, fixes, 2.0, velocity, 0.02)
    track = antenna_track(spp, doppler, None, ENU)
    np.testing.assert_array_equal(track.t, t)
    bound = 4.0 / np.sqrt(0.95 * 99) * np.array([2.0, 2.0, 4.0])
    assert np.all(np.abs(track.position[0] - truth[0]) < bound)
    assert np.all(np.abs(track.position - truth) < bound)


def test_the_antenna_track_falls_back_to_one_fix_then_the_approximate_position(caplog):
    t = np.arange(5.0)
    fixes = np.full((5, 3), np.nan)
    fixes[2] = [10.0, 20.0, 3.0]
    spp, doppler = _gnss_solutions(t, fixes, 2.0, np.zeros((5, 3)), 0.02)
    one = antenna_track(spp, doppler, None, ENU)
    np.testing.assert_array_equal(one.t, [2.0])
    np.testing.assert_allclose(one.position, [[10.0, 20.0, 3.0]], atol=1e-6)
    spp, doppler = _gnss_solutions(t, np.full((5, 3), np.nan), 2.0, np.zeros((5, 3)), 0.02)
    approx = ENU.enu_to_ecef(np.array([-5.0, 7.0, 1.0]))
    with caplog.at_level("WARNING"):
        header = antenna_track(spp, doppler, approx, ENU)
        origin = antenna_track(spp, doppler, None, ENU)
    assert header.t.size == 0 and origin.t.size == 0
    np.testing.assert_allclose(header.position, [[-5.0, 7.0, 1.0]], atol=1e-6)
    np.testing.assert_array_equal(origin.position, np.zeros((1, 3)))
    assert "RINEX approximate position" in caplog.text and "at the origin" in caplog.text


def test_the_antenna_track_says_what_placed_the_heights():
    t = np.arange(10.0)
    position = np.tile(EnuFrame(0.6, 2.4, 50.0).origin_ecef, (10, 1))
    spp = SppSolution(t, position, {}, np.full(10, 8), t, t, np.ones(10, bool), 0)
    velocity = velocity_solution(t, np.zeros((10, 3)))
    frame = EnuFrame(0.6, 2.4, 0.0)
    poor = replace(spp, horizontal_sigma_m=np.ones(10), vertical_sigma_m=np.full(10, 9.0))
    assert "the sequence origin" in antenna_track(poor, velocity, None, frame).height_source
    sigma = np.where(t < 4, 3.0, 9.0)
    good = replace(poor, vertical_sigma_m=sigma)
    track = antenna_track(good, velocity, None, frame)
    assert track.height_source.startswith("the valid fixes with a vertical σ of at most 5 m (4 of")
    np.testing.assert_array_equal(track.height_rows, np.arange(4))
