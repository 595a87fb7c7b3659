"""Tightly coupled time-series heading (sec. 3.5) and conventional heading (sec. 3.2)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.geo import EnuFrame, wrap_angle
from vo_doppler.heading.conventional import heading_from_velocity
from vo_doppler.heading.tight_heading import TightHeadingConfig, tight_heading_series
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.sim.doppler_rows import simulate_doppler

AZIMUTH = [30.0, 110.0, 200.0, 280.0, 330.0, 160.0]
ELEVATION = [60.0, 30.0, 45.0, 20.0, 70.0, 15.0]
T = np.arange(0.0, 6.0, 0.05)


def straight(t):
    return 0.7 + 0.0 * t


def turning(t):
    return 0.7 + 0.3 * t


def sharp_turn(t):
    return 0.7 + 0.8 * t


def constant_speed(t):
    return 10.0 + 0.0 * t


def _solve(yaw, n_sat, rotate=False, t=T, config=None):
    scenario = simulate_doppler(t, yaw, constant_speed, AZIMUTH, ELEVATION, n_sat, rotate=rotate)
    result = tight_heading_series(
        scenario.rows,
        scenario.t_epoch,
        scenario.speed,
        scenario.yaw_angle,
        config or TightHeadingConfig(),
    )
    return scenario, result


def _max_error(scenario, result):
    return np.max(np.abs(wrap_angle(result.yaw[result.available] - scenario.yaw[result.available])))


@pytest.mark.parametrize(
    ("yaw", "n_sat", "rotate"),
    [
        (straight, 3, False),  # three satellites: one epoch already suffices
        (turning, 2, False),  # two satellites: the turn separates the two mirror solutions
        (sharp_turn, 1, False),  # one satellite: observable only through the turn
        (straight, 1, True),  # one satellite per epoch, a different one each epoch
        (straight, 2, True),
    ],
)
def test_noise_free_windows_give_exact_heading(yaw, n_sat, rotate):
    scenario, result = _solve(yaw, n_sat, rotate)
    after_first_window = scenario.t_epoch >= 2.0
    assert np.all(result.available[after_first_window])
    assert _max_error(scenario, result) < 1e-6
    np.testing.assert_allclose(
        result.clock_drift[result.available], scenario.clock_drift[result.available], atol=1e-6
    )
    # ρ_t = ρ₀ − α·(t − t_k): the simulated drift grows at +0.3 m/s², so α = −0.3.
    window_has_span = result.available & (scenario.t_epoch > 0.0)
    np.testing.assert_allclose(result.clock_drift_rate[window_has_span], -0.3, atol=1e-5)


@pytest.mark.parametrize(("n_sat", "flag"), [(1, "unobservable"), (2, "ambiguous")])
def test_unobservable_straight_line_is_unavailable(n_sat, flag):
    _, result = _solve(straight, n_sat)
    assert not result.available.any()
    assert np.all(np.isnan(result.yaw)) and np.all(np.isnan(result.sigma))
    assert not result.reliable.any()
    if flag == "ambiguous":
        assert result.ambiguous[1:].all()
    else:
        assert not result.ambiguous.any()


def test_three_observations_needed():
    one_epoch = np.array([0.0])
    for n_sat, expected in [(2, False), (3, True)]:
        _, result = _solve(straight, n_sat, t=one_epoch)
        assert result.available[0] == expected
        assert result.n_obs[0] == n_sat
        if expected:
            assert abs(wrap_angle(result.yaw[0] - 0.7)) < 1e-9


def test_ambiguity_resolved_by_the_gyro_propagated_prior():
    # Turning for 3 s (observable with two satellites), then straight (ambiguous).
    def turn_then_straight(t):
        return 0.2 + 0.3 * np.minimum(t, 3.0)

    scenario, result = _solve(turn_then_straight, 2, t=np.arange(0.0, 12.0, 0.05))
    late = scenario.t_epoch > 8.0
    assert result.ambiguous[late].all()
    assert result.available[late].all()
    assert _max_error(scenario, result) < 1e-6


@pytest.mark.parametrize(
    ("rate_hz", "curve_rad_s", "ambiguous"),
    [(20.0, 0.001, True), (20.0, 0.003, False), (1.0, 0.003, True), (1.0, 0.02, False)],
)
def test_roots_apart_by_less_than_the_noise_stay_ambiguous(rate_hz, curve_rad_s, ambiguous):
    # Two satellites on a gentle curve, noise-free: the true root fits exactly (s² at its
    # floor), the mirror root by a gap that only a sharper curve makes larger than the noise.
    # Judged by the window's own s² alone, any gap at all looked decisive.
    def curve(t):
        return 0.7 + curve_rad_s * t

    t = np.arange(0.0, 12.0, 1.0 / rate_hz)
    scenario, result = _solve(curve, 2, t=t)
    late = scenario.t_epoch >= 2.0
    if ambiguous:
        assert result.ambiguous[late].all()
        assert not result.available.any()
    else:
        assert result.available[late].all() and not result.ambiguous[late].any()
        assert _max_error(scenario, result) < 1e-6


def test_noisy_heading_sigma_and_reliability():
    scenario = simulate_doppler(
        np.arange(0.0, 40.0, 0.05),
        lambda t: 0.7 + 0.2 * np.sin(0.5 * t),
        lambda t: 12.0 + 0.0 * t,
        AZIMUTH,
        ELEVATION,
        3,
        noise_mps=0.05,
        seed=4,
    )
    result = tight_heading_series(
        scenario.rows, scenario.t_epoch, scenario.speed, scenario.yaw_angle
    )
    error = wrap_angle(result.yaw - scenario.yaw)[result.available]
    assert result.available.mean() > 0.99 and result.reliable.mean() > 0.95
    normalised = error / result.sigma[result.available]
    assert 0.5 < np.std(normalised) < 2.0  # σ from the covariance matches the scatter
    assert np.degrees(np.median(np.abs(error))) < 0.2


def test_outlier_is_down_weighted():
    scenario = simulate_doppler(T, turning, constant_speed, AZIMUTH, ELEVATION, 4, rotate=False)
    rows = scenario.rows
    bad = rows.range_rate.copy()
    bad[len(bad) // 2] += 5.0  # one gross Doppler error
    corrupted = DopplerRows(
        rows.t, rows.los, rows.sat_velocity, rows.sat_clock_drift, bad, rows.weight, rows.sat_id
    )
    robust = tight_heading_series(corrupted, scenario.t_epoch, scenario.speed, scenario.yaw_angle)
    plain = tight_heading_series(
        corrupted,
        scenario.t_epoch,
        scenario.speed,
        scenario.yaw_angle,
        TightHeadingConfig(robust_passes=0, outlier_passes=0),  # neither Huber nor rejection
    )
    affected = np.abs(scenario.t_epoch - T[len(T) // 2]) < 1.9
    robust_error = np.max(np.abs(wrap_angle(robust.yaw - scenario.yaw)[affected]))
    plain_error = np.max(np.abs(wrap_angle(plain.yaw - scenario.yaw)[affected]))
    assert robust_error < plain_error / 5


def test_inconsistent_gyro_is_flagged_unreliable():
    scenario, _ = _solve(turning, 3, rotate=False)
    wrong_gyro = scenario.yaw_angle * 0.0  # the gyro misses the turn
    level = tight_heading_series(
        scenario.rows,
        scenario.t_epoch,
        scenario.speed,
        wrong_gyro,
        TightHeadingConfig(grade_sigma=0.0),
    )
    assert level.available.mean() > 0.9
    assert level.reliable.mean() < 0.1
    # With the road grade unknown, three satellites leave the short windows of the first
    # second little redundancy: their σ is wide enough to pass the gate. Once the window and
    # the reliability history are full, the wrong gyro is caught at every epoch.
    result = tight_heading_series(scenario.rows, scenario.t_epoch, scenario.speed, wrong_gyro)
    assert result.available.mean() > 0.9
    assert not result.reliable[scenario.t_epoch >= 3.0].any()


def test_ecef_rows_equal_enu_rows():
    scenario, result = _solve(turning, 3)
    frame = EnuFrame(np.radians(34.6), np.radians(135.5), 50.0)
    rot = frame.rotation
    rows = scenario.rows
    ecef = DopplerRows(
        rows.t,
        rows.los @ rot,
        rows.sat_velocity @ rot,
        rows.sat_clock_drift,
        rows.range_rate,
        rows.weight,
        rows.sat_id,
        frame="ecef",
        receiver_ecef=np.tile(frame.origin_ecef, (len(rows), 1)),
    )
    enu = ecef.in_enu()
    assert enu.frame == "enu"
    again = tight_heading_series(enu, scenario.t_epoch, scenario.speed, scenario.yaw_angle)
    np.testing.assert_allclose(again.yaw, result.yaw, atol=1e-9, equal_nan=True)


def test_no_heading_at_standstill():
    scenario, _ = _solve(straight, 3)
    stopped = tight_heading_series(
        scenario.rows, scenario.t_epoch, np.zeros_like(scenario.speed), scenario.yaw_angle
    )
    assert not stopped.available.any()


@settings(max_examples=30, deadline=None)
@given(
    yaw0=st.floats(-np.pi, np.pi),
    rate=st.floats(-0.5, 0.5),
    speed=st.floats(2.0, 30.0),
)
def test_heading_recovered_for_any_start_heading(yaw0, rate, speed):
    scenario = simulate_doppler(
        np.arange(0.0, 2.0, 0.1),
        lambda t: yaw0 + rate * t,
        lambda t: speed + 0 * t,
        AZIMUTH,
        ELEVATION,
        3,
        rotate=False,
    )
    result = tight_heading_series(
        scenario.rows, scenario.t_epoch, scenario.speed, scenario.yaw_angle
    )
    assert result.available.all()
    assert _max_error(scenario, result) < 1e-6


def test_conventional_heading_from_velocity():
    v = np.array([[1.0, 0.0, 0.0], [0.0, 2.0, 0.3], [0.0, -3.0, 0.0], [0.1, 0.1, 5.0]])
    yaw, ok = heading_from_velocity(v)
    np.testing.assert_allclose(yaw[:3], [0.0, np.pi / 2, -np.pi / 2])
    assert ok.tolist() == [True, True, True, False]
    yaw, ok = heading_from_velocity(v, valid=np.array([True, True, False, True]))
    np.testing.assert_allclose(yaw[:2], [0.0, np.pi / 2])
    assert ok.tolist() == [True, True, False, False] and np.isnan(yaw[2:]).all()


def test_no_epochs_no_rows_and_unmatched_rows_are_unavailable():
    scenario, _ = _solve(turning, 3)
    nothing = tight_heading_series(scenario.rows, np.zeros(0), np.zeros(0), np.zeros(0))
    assert len(nothing.yaw) == 0
    empty = scenario.rows.select(np.zeros(len(scenario.rows), dtype=bool))
    result = tight_heading_series(empty, scenario.t_epoch, scenario.speed, scenario.yaw_angle)
    assert not result.available.any() and np.all(result.n_obs == 0)
    shifted = tight_heading_series(
        scenario.rows, scenario.t_epoch + 0.01, scenario.speed, scenario.yaw_angle
    )
    assert not shifted.available.any()
    with pytest.raises(ValueError, match="strictly increasing"):
        tight_heading_series(
            scenario.rows, scenario.t_epoch[::-1], scenario.speed, scenario.yaw_angle
        )
