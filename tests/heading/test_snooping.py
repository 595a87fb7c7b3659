"""Reflected (NLOS) Doppler rows inside the tightly coupled heading: data snooping rejects them
(vo_doppler.heading.snooping), flags what cannot be checked, and keeps clean rows.

A reflection on a vertical facade with unit normal n (pointing back towards the street) adds
the rate of the extra path 2·d·|G·n| to the range rate: −2·(v·m)·|G·n| with m = −n the unit
vector from the antenna towards the facade (the simulator's model, vo_doppler.sim).
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.heading.test_tight_heading import AZIMUTH, ELEVATION, T, sharp_turn, straight, turning
from tests.heading.test_tight_heading import constant_speed as speed
from vo_doppler.geo import wrap_angle
from vo_doppler.heading.pipeline import heading_pipeline
from vo_doppler.heading.tight_heading import TightHeadingConfig, tight_heading_series
from vo_doppler.io.heading_csv import read_heading_csv, write_heading_csv
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.series import SensorSeries
from vo_doppler.sim.doppler_rows import simulate_doppler

NO_REJECTION = TightHeadingConfig(outlier_passes=0)


def facade_excess_rate(scenario, facade_normal):
    """Range-rate excess of every row if it were reflected by a facade with that normal."""
    epoch = np.searchsorted(scenario.t_epoch, scenario.rows.t)
    yaw = scenario.yaw[epoch]
    velocity = scenario.speed[epoch, None] * np.stack(
        [np.cos(yaw), np.sin(yaw), np.zeros_like(yaw)], axis=1
    )
    towards_facade = -np.asarray(facade_normal, dtype=float)
    return -2.0 * (velocity @ towards_facade) * np.abs(scenario.rows.los @ facade_normal)


def with_bias(rows: DopplerRows, bias: np.ndarray) -> DopplerRows:
    return DopplerRows(
        rows.t,
        rows.los,
        rows.sat_velocity,
        rows.sat_clock_drift,
        rows.range_rate + bias,
        rows.weight,
        rows.sat_id,
    )


def _solve(scenario, rows=None, config=None):
    rows = scenario.rows if rows is None else rows
    config = config or TightHeadingConfig()
    return tight_heading_series(rows, scenario.t_epoch, scenario.speed, scenario.yaw_angle, config)


def _error(scenario, result):
    return np.abs(wrap_angle(result.yaw - scenario.yaw))


# A facade ahead and to the left of a car heading 0.7 rad: its normal points back at the car.
FACADE_NORMAL = np.array([np.cos(0.7 + 2.5), np.sin(0.7 + 2.5), 0.0])


def test_one_reflected_row_among_six_is_rejected_and_the_heading_exact():
    scenario = simulate_doppler(np.array([0.0]), straight, speed, AZIMUTH, ELEVATION, 6)
    excess = facade_excess_rate(scenario, FACADE_NORMAL)
    reflected = np.arange(len(scenario.rows)) == 2
    assert abs(excess[2]) > 1.0  # metres per second: a real reflection, not noise
    rows = with_bias(scenario.rows, np.where(reflected, excess, 0.0))
    result = _solve(scenario, rows)
    assert result.available[0] and result.verifiable[0] and not result.inconsistent[0]
    assert result.n_rejected[0] == 1
    assert _error(scenario, result)[0] < 1e-9  # the right row went: the fit is exact again
    kept = _solve(scenario, rows, NO_REJECTION)
    assert kept.n_rejected[0] == 0
    assert _error(scenario, kept)[0] > 1e-3  # the row does corrupt the heading when kept


@pytest.mark.parametrize(("yaw", "tolerance"), [(straight, 1e-9), (turning, 1e-4)])
def test_reflection_over_part_of_the_drive_is_rejected_window_by_window(yaw, tolerance):
    """Satellite 3 is reflected from 2.5 s to 4 s: a constant excess on the straight road, a
    ramp in the turn (the excess follows v·m), starting and stopping inside windows."""
    scenario = simulate_doppler(T, yaw, speed, AZIMUTH, ELEVATION, 6, rotate=False)
    rows = scenario.rows
    reflected = (rows.sat_id == "G03") & (rows.t >= 2.5) & (rows.t < 4.0)
    bias = np.where(reflected, facade_excess_rate(scenario, FACADE_NORMAL), 0.0)
    result = _solve(scenario, with_bias(rows, bias))
    window = TightHeadingConfig().window_s
    in_window = np.array(
        [np.count_nonzero(reflected & (rows.t > t - window) & (rows.t <= t)) for t in T]
    )
    touched = in_window > 0
    assert result.available.all() and not result.inconsistent.any()
    assert np.all(result.n_rejected[touched] >= 1)
    assert np.all(result.n_rejected[~touched] == 0)
    error = np.max(_error(scenario, result))
    assert error < tolerance
    # Kept, the rows move the heading (the Huber weights alone only damp them).
    kept = _solve(scenario, with_bias(rows, bias), NO_REJECTION)
    assert np.nanmax(_error(scenario, kept)) > max(10 * error, tolerance)
    # σ reflects the rejection: fewer rows, and room for one more undetected bias.
    clean = _solve(scenario)
    assert np.all(result.sigma[touched] > clean.sigma[touched])
    np.testing.assert_allclose(result.sigma[~touched], clean.sigma[~touched], rtol=1e-9)


def test_minimal_rows_are_flagged_not_rejected():
    # One epoch, three satellites: unknowns θ₀ and ρ₀, one redundant row. A 0.5 m/s bias is
    # detected, but any of the three rows could carry it: nothing is rejected, no heading.
    scenario = simulate_doppler(np.array([0.0]), straight, speed, AZIMUTH, ELEVATION, 3)
    clean = _solve(scenario)
    assert clean.available[0] and clean.verifiable[0] and clean.n_rejected[0] == 0
    biased = _solve(scenario, with_bias(scenario.rows, np.array([0.0, 0.5, 0.0])))
    assert biased.inconsistent[0] and not biased.available[0]
    assert biased.n_rejected[0] == 0
    # One satellite through a turn: a bias on it is indistinguishable from the clock drift,
    # so the heading is available but unverifiable (and, here, unharmed).
    single = simulate_doppler(T, sharp_turn, speed, AZIMUTH, ELEVATION, 1, rotate=False)
    late = single.t_epoch >= 2.0
    reflected = with_bias(single.rows, np.full(len(single.rows), 1.5))
    result = _solve(single, reflected)
    assert result.available[late].all()
    assert not result.verifiable.any()
    assert not result.n_rejected.any()
    assert np.max(_error(single, result)[late]) < 1e-6


def _noisy_drive(duration_s):
    """Six satellites, 20 Hz, Doppler noise exactly as the weights say (5 cm/s), seed fixed."""
    return simulate_doppler(
        np.arange(0.0, duration_s, 0.05),
        lambda t: 0.7 + 0.2 * np.sin(0.5 * t),
        lambda t: 12.0 + 0.0 * t,
        AZIMUTH,
        ELEVATION,
        6,
        noise_mps=0.05,
        seed=3,
    )


def test_noise_only_rows_are_kept():
    scenario = _noisy_drive(60.0)
    result = _solve(scenario)
    assert not result.n_rejected.any()
    assert not result.inconsistent.any()
    assert result.available.all() and result.verifiable.all()


def test_false_alarm_rate_is_near_the_nominal_level():
    """Single-epoch windows (independent tests), six satellites with exactly modelled noise.
    In a one-epoch window each satellite is one row, so the satellite and row families (α/2
    each, Bonferroni within) test the same hypotheses: the window false-alarm rate is ≈ α/2.
    A false alarm is seldom attributed clearly enough to reject a row (odds 100:1)."""
    scenario = _noisy_drive(200.0)
    alpha = 0.05
    result = _solve(scenario, config=TightHeadingConfig(window_s=0.01, outlier_alpha=alpha))
    alarms = np.mean(result.inconsistent | (result.n_rejected > 0))
    assert 0.6 * alpha / 2 < alarms < 1.4 * alpha / 2  # measured 0.0223 of 4000 windows
    assert np.mean(result.n_rejected > 0) < alpha / 10
    default = _solve(scenario, config=TightHeadingConfig(window_s=0.01))
    assert np.mean(default.inconsistent | (default.n_rejected > 0)) < 0.002  # 0.0005; α 0.001


def test_pipeline_reports_rejected_rows_in_the_heading_csv(tmp_path):
    scenario = simulate_doppler(T, turning, speed, AZIMUTH, ELEVATION, 6, rotate=False)
    rows = scenario.rows
    reflected = (rows.sat_id == "G03") & (rows.t >= 2.5) & (rows.t < 4.0)
    bias = np.where(reflected, facade_excess_rate(scenario, FACADE_NORMAL), 0.0)
    t = scenario.t_epoch
    velocity = np.zeros((len(t), 3))
    table = heading_pipeline(
        t,
        with_bias(rows, bias),
        velocity,
        np.zeros(len(t), bool),
        SensorSeries(t, scenario.speed),
        SensorSeries(t, np.gradient(scenario.yaw, t)),
    )
    assert table.rejected_rows.sum() > 0 and table.rejected_rows[t < 2.5].sum() == 0
    write_heading_csv(tmp_path / "heading.csv", table)
    again = read_heading_csv(tmp_path / "heading.csv")
    np.testing.assert_array_equal(again.rejected_rows, table.rejected_rows)
    np.testing.assert_array_equal(again.tc_verifiable, table.tc_verifiable)
    # A file written before the columns existed still reads (as zeros / False).
    lines = (tmp_path / "heading.csv").read_text().splitlines()
    old = [",".join(line.split(",")[:10]) for line in lines]
    (tmp_path / "old.csv").write_text("\n".join(old) + "\n")
    legacy = read_heading_csv(tmp_path / "old.csv")
    assert not legacy.rejected_rows.any() and not legacy.tc_verifiable.any()
    np.testing.assert_array_equal(legacy.tc_available, table.tc_available)
