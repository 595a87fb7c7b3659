"""Fixes checked against their Doppler-carried neighbours: a reflection episode that moves
every fix of 20 s together (its own residuals pass) is found; honest fixes keep λ = 1."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tests.helpers.velocity import velocity_solution
from vo_doppler.geo import EnuFrame
from vo_doppler.gnss.position_check import doppler_consistency
from vo_doppler.model.gnss_solutions import SppSolution

FRAME = EnuFrame(np.radians(22.3), np.radians(114.18), 5.0)


def _drive(seed: int = 0, bias: np.ndarray | None = None):
    """A 1 Hz, 300-s drive turning at 10 m/s; fixes with σ_h 3 m (2.1 per axis), σ_u 8 m,
    exact Doppler velocities with σ 0.1 m/s; ``bias`` (N, 3) ENU added to the fixes."""
    rng = np.random.default_rng(seed)
    t = 1.0e9 + np.arange(300.0)
    heading = 0.01 * (t - t[0])
    velocity = np.column_stack([10 * np.cos(heading), 10 * np.sin(heading), np.zeros(t.size)])
    truth = np.concatenate([[np.zeros(3)], np.cumsum(0.5 * (velocity[1:] + velocity[:-1]), 0)])
    sigma = np.array([3.0 / np.sqrt(2.0), 3.0 / np.sqrt(2.0), 8.0])
    fix = truth + sigma * rng.standard_normal(truth.shape)
    if bias is not None:
        fix = fix + bias
    rotation = FRAME.rotation
    n = t.size
    spp = SppSolution(
        t,
        FRAME.enu_to_ecef(fix),
        {},
        np.full(n, 10),
        np.full(n, 2.0),
        np.full(n, 2.0),
        np.ones(n, dtype=bool),
        0,
        verified=np.ones(n, dtype=bool),
        horizontal_sigma_m=np.full(n, 3.0),
        vertical_sigma_m=np.full(n, 8.0),
        horizontal_protection_m=np.full(n, 10.0),
        vertical_protection_m=np.full(n, 20.0),
    )
    covariance = np.zeros((n, 4, 4))
    covariance[:, :3, :3] = 0.01 * np.eye(3)
    doppler = replace(velocity_solution(t, velocity @ rotation), covariance=covariance)
    return spp, doppler, truth


def test_honest_fixes_stay_valid_with_their_sigma():
    spp, velocity, _ = _drive()
    checked = doppler_consistency(spp, velocity)
    assert checked.consistency_tested.all()
    assert checked.valid.mean() > 0.99
    scale_h, scale_u = checked.consistency_scale
    assert 1.0 <= scale_h < 1.1 and 1.0 <= scale_u < 1.1
    np.testing.assert_allclose(checked.horizontal_protection_m, 10.0 * scale_h)


def test_a_reflection_episode_of_twenty_seconds_is_not_valid():
    """Fixes 100 m high and 30 m east for 20 s (a stop under a canyon's reflections, as on the
    Hong Kong drive): each passes its own test (verified) and was valid before the check."""
    bias = np.zeros((300, 3))
    episode = slice(100, 120)
    bias[episode] = [30.0, 0.0, 100.0]
    spp, velocity, _ = _drive(seed=1, bias=bias)
    assert spp.valid[episode].all()  # the old verdict: the epoch's own test alone
    checked = doppler_consistency(spp, velocity)
    assert not checked.valid[episode].any()
    assert checked.verified[episode].all()
    outside = np.r_[0:100, 120:300]
    assert checked.valid[outside].mean() > 0.98


def test_the_check_does_not_depend_on_the_time_origin():
    spp, velocity, _ = _drive(seed=2)
    shifted = doppler_consistency(
        replace(spp, t=spp.t - 1.0e9), replace(velocity, t=velocity.t - 1.0e9)
    )
    checked = doppler_consistency(spp, velocity)
    np.testing.assert_array_equal(shifted.valid, checked.valid)
    np.testing.assert_allclose(shifted.horizontal_sigma_m, checked.horizontal_sigma_m)
