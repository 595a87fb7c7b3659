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
from vo_doppler.heading.conventional import ConventionalVelocity
from vo_doppler.heading.pipeline import HeadingPipelineConfig, heading_pipeline
from vo_doppler.heading.tight_heading import TightHeadingConfig, tight_heading_series
from vo_doppler.io.heading_csv import read_heading_csv, write_heading_csv
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.sim.doppler_rows import simulate_doppler

NO_REJECTION = TightHeadingConfig(outlier_passes=0)
SNOOPING = TightHeadingConfig(outlier_passes=4, max_window_s=2.0)
"""Data snooping (an option since the robust fit became the default), on fixed windows."""


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
    config = config or SNOOPING
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
    window = SNOOPING.window_s
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
    # detected, but any of the three rows could carry it: nothing is rejected. Its satellite
    # test is significant (a bias, not a lone blunder): no heading, no robust fallback.
    scenario = simulate_doppler(np.array([0.0]), straight, speed, AZIMUTH, ELEVATION, 3)
    clean = _solve(scenario)
    assert clean.available[0] and clean.verifiable[0] and clean.n_rejected[0] == 0
    for bias in ([0.0, 0.5, 0.0], [0.0, 0.0, 0.5]):
        biased = _solve(scenario, with_bias(scenario.rows, np.array(bias)))
        assert biased.inconsistent[0] and not biased.available[0] and not biased.fallback[0]
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
    result = _solve(
        scenario,
        config=TightHeadingConfig(
            outlier_passes=4, window_s=0.01, max_window_s=0.01, outlier_alpha=alpha
        ),
    )
    alarms = np.mean(result.inconsistent | (result.n_rejected > 0))
    assert 0.6 * alpha / 2 < alarms < 1.4 * alpha / 2  # measured 0.0223 of 4000 windows
    assert np.mean(result.n_rejected > 0) < alpha / 10
    default = _solve(
        scenario, config=TightHeadingConfig(outlier_passes=4, window_s=0.01, max_window_s=0.01)
    )
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
        ConventionalVelocity(velocity, np.zeros(len(t), bool)),
        VehicleSignals(
            SensorSeries(t, scenario.speed), SensorSeries(t, np.gradient(scenario.yaw, t))
        ),
        HeadingPipelineConfig(tight=SNOOPING),
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


def _with_noise(scenario, white_mps, correlated_mps=0.0, time_constant_s=20.0, seed=7):
    """The scenario's rows plus white noise and, per satellite, a Gauss–Markov error of
    stationary σ ``correlated_mps`` and time constant ``time_constant_s`` (nearly constant over
    a window): what real Doppler looks like; the weights still say 5 cm/s."""
    rng = np.random.default_rng(seed)
    rows = scenario.rows
    t = scenario.t_epoch
    decay = np.exp(-np.diff(t, prepend=t[0]) / time_constant_s)
    drive = rng.normal(0.0, 1.0, (len(t), len(AZIMUTH))) * np.sqrt(1.0 - decay**2)[:, None]
    slow = np.zeros_like(drive)
    slow[0] = rng.normal(0.0, 1.0, len(AZIMUTH))
    for k in range(1, len(t)):
        slow[k] = decay[k] * slow[k - 1] + drive[k]
    epoch = np.searchsorted(t, rows.t)
    sat = np.char.replace(rows.sat_id.astype(str), "G", "").astype(int) - 1
    error = white_mps * rng.normal(0.0, 1.0, len(rows)) + correlated_mps * slow[epoch, sat]
    return with_bias(rows, error)


def test_noise_three_times_the_a_priori_sigma_keeps_the_false_alarm_rate():
    """2 s windows of six satellites at 20 Hz, white noise 15 cm/s where the weights say
    5 cm/s: σ₀ is estimated from the data (≈ 3), so clean windows are not flagged (α = 0.001
    per window; overlapping windows share rows, so alarms would come in runs)."""
    scenario = _noisy_drive(120.0)
    result = _solve(scenario, _with_noise(scenario, 0.15))
    tested = scenario.t_epoch >= SNOOPING.window_s
    flagged = result.inconsistent | (result.n_rejected > 0)
    assert np.mean(flagged[tested]) <= 0.005  # measured 0.0 (seeds 7 and 8)
    assert result.available[tested].all()


@pytest.fixture(scope="module")
def correlated_drive():
    """2 s windows of six satellites at 20 Hz: white noise 5 cm/s (as the weights say) plus a
    per-satellite error of 10 cm/s that drifts with a 20 s time constant."""
    scenario = _noisy_drive(120.0)
    return scenario, _with_noise(scenario, 0.05, correlated_mps=0.1)


def test_window_constant_satellite_errors_are_noise_not_reflections(correlated_drive):
    """Over a window each satellite's slow error looks like a bias; 40 rows of 5 cm/s white
    noise would reveal 0.03 m/s of it. Its share κ is estimated from the data (about 2 where
    the white noise is 1), so the satellite tests keep their false-alarm rate: clean windows
    are not repaired (the a-priori model alone flags nearly every window)."""
    scenario, rows = correlated_drive
    result = _solve(scenario, rows)
    tested = scenario.t_epoch >= SNOOPING.window_s
    flagged = result.inconsistent | (result.n_rejected > 0)
    assert np.mean(flagged[tested]) < 0.01  # α = 0.001 per window; measured 0.0
    assert result.available[tested].all()
    error = np.degrees(_error(scenario, result)[tested])
    assert np.median(error) < 0.5


@pytest.mark.slow
def test_reflection_is_still_rejected_amid_correlated_noise(correlated_drive):
    scenario, rows = correlated_drive
    reflected = (rows.sat_id == "G03") & (rows.t >= 60.0) & (rows.t < 61.5)
    bias = np.where(reflected, facade_excess_rate(scenario, FACADE_NORMAL), 0.0)
    assert np.min(np.abs(bias[reflected])) > 1.0
    result = _solve(scenario, with_bias(rows, bias))
    t = scenario.t_epoch
    window = SNOOPING.window_s
    touched = (t >= 60.0) & (t < 61.5 + window)
    assert np.mean(result.n_rejected[touched] > 0) > 0.95
    assert result.available[touched].mean() > 0.95
    # Against the same drive without the reflection: rejecting it restores the heading
    # (measured 0.03°), keeping it moves it (0.25°).
    clean = _solve(scenario, rows)
    kept = _solve(scenario, with_bias(rows, bias), NO_REJECTION)
    repaired = np.abs(wrap_angle(result.yaw - clean.yaw))[touched]
    moved = np.abs(wrap_angle(kept.yaw - clean.yaw))[touched]
    assert np.max(repaired) < 0.2 * np.max(moved)


def test_blunders_beyond_the_rejection_passes_fall_back_to_the_robust_fit():
    """One 2 m/s blunder row on each of five satellites of one window: four rejection passes
    name four of them, the fifth leaves the window inconsistent. The fault is a row's, so the
    Huber fit (which damps a lone row) gives the heading, with σ widened, not verifiable."""
    scenario = _noisy_drive(4.0)
    rows = _with_noise(scenario, 0.05)
    end = len(scenario.t_epoch) - 1
    at = np.flatnonzero(rows.t == scenario.t_epoch[end - 3])
    blunder = np.zeros(len(rows))
    blunder[at[:5]] = 2.0
    result = _solve(scenario, with_bias(rows, blunder))
    clean = _solve(scenario, rows)
    assert result.inconsistent[end] and result.fallback[end]
    assert result.available[end] and not result.verifiable[end]
    assert np.isfinite(result.yaw[end])
    assert result.sigma[end] > 2.0 * clean.sigma[end]
    assert _error(scenario, result)[end] < 3.0 * result.sigma[end]
    assert not clean.fallback.any()


def test_chi2_isf_1_is_scipy_stats_chi2_isf():
    from scipy.stats import chi2

    from vo_doppler.heading.snooping import chi2_isf_1

    q = np.array([1e-6, 0.001 / 14, 0.0005, 0.01, 0.25, 0.9])
    assert np.array_equal(chi2_isf_1(q), chi2.isf(q, 1))
    assert chi2_isf_1(0.001) == chi2.isf(0.001, 1)
