"""Exact cases for the low-cost path-mapping maths (Eq. 5–17), with known answers."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.errors import InputError
from vo_doppler.geo import EARTH_MEAN_RADIUS_M
from vo_doppler.lowcost.dead_reckoning import (
    dead_reckon,
    track_yaw,
)
from vo_doppler.lowcost.drift import closed_loop_gap, drift_rate_deg_per_min, heading_error
from vo_doppler.lowcost.gps_reconstruction import (
    equirectangular_distance,
    haversine_distance,
    reconstruct_track,
    select_fixes,
    step_lengths,
)
from vo_doppler.lowcost.gyro_combination import (
    choose_k,
    combine_rates,
    k_by_sweep,
    k_closed_form,
    k_inverse_variance,
)
from vo_doppler.lowcost.rate_alignment import align_rates
from vo_doppler.lowcost.series import clean_series
from vo_doppler.lowcost.static_bias import (
    allan_deviation,
    detect_standstill,
    remove_bias,
    static_bias,
)
from vo_doppler.lowcost.threshold_filter import threshold_filter
from vo_doppler.model.timeseries import cumulative_integral, increments

M_PER_RAD = EARTH_MEAN_RADIUS_M


def test_combination_end_points_and_average():
    w1, w2 = np.array([1.0, 2.0, -3.0]), np.array([5.0, -1.0, 0.5])
    np.testing.assert_array_equal(combine_rates(w1, w2, 0.0), w1)
    np.testing.assert_array_equal(combine_rates(w1, w2, 2.0), w2)
    np.testing.assert_allclose(combine_rates(w1, w2, 1.0), (w1 + w2) / 2)
    with pytest.raises(ValueError):
        combine_rates(w1, w2, 2.01)


def test_k_choices_on_constant_biases():
    t = np.arange(0.0, 100.0, 0.01)
    w1 = np.full(t.shape, 0.003)
    w2 = np.full(t.shape, -0.001)
    closed = k_closed_form(w1, w2)
    assert closed.k == pytest.approx(1.5) and not closed.clipped
    assert np.mean(combine_rates(w1, w2, closed.k)) == pytest.approx(0.0, abs=1e-15)
    sweep, grid, final = k_by_sweep(t, w1, w2)
    assert sweep.k == pytest.approx(1.5)
    assert len(grid) == 201 and grid[0] == 0.0 and grid[-1] == 2.0
    assert abs(final[150]) < 1e-12 and final[0] == pytest.approx(0.003 * (t[-1] - t[0]))


def test_closed_form_k_clipped_when_biases_share_a_sign():
    choice = k_closed_form(np.full(10, 0.002), np.full(10, 0.001))
    assert choice.clipped and choice.k == 2.0 and "share a sign" in choice.note


def test_inverse_variance_k():
    rng = np.random.default_rng(0)
    w1 = rng.normal(0, 1.0, 200_000)
    w2 = rng.normal(0, 2.0, 200_000)
    assert k_inverse_variance(w1, w2).k == pytest.approx(0.4, abs=0.01)
    choices = choose_k(np.arange(len(w1)) * 0.01, w1, w2)
    assert [c.method for c in choices.as_list()] == ["sweep", "closed form", "inverse variance"]


def test_static_bias_is_the_interval_mean():
    t = np.arange(0.0, 10.0, 0.5)
    rate = t * 2.0
    bias = static_bias(t, rate, 2.0, 4.0)
    assert bias.eps0 == pytest.approx(6.0) and bias.n == 5
    np.testing.assert_allclose(remove_bias(rate, bias.eps0), rate - 6.0)
    with pytest.raises(InputError, match="no rate samples"):
        static_bias(t, rate, 20.0, 30.0)


def test_allan_deviation_white_noise_slope_and_minimum():
    rng = np.random.default_rng(1)
    fs, n_white, k_walk = 100.0, 0.002, 2e-5
    white = rng.normal(0, n_white * np.sqrt(fs), 60_000)
    adev = allan_deviation(white, fs)
    small = adev.taus < 5
    # White rate noise: ADEV(τ) = N / √τ.
    np.testing.assert_allclose(adev.adev[small] * np.sqrt(adev.taus[small]), n_white, rtol=0.1)
    walk = np.cumsum(rng.normal(0, k_walk / np.sqrt(fs), 60_000))
    tau_min = allan_deviation(white + walk, fs).tau_at_minimum
    expected = np.sqrt(3.0) * n_white / k_walk
    assert expected / 2.5 < tau_min < expected * 2.5


def test_detect_standstill_intervals():
    t = np.arange(0.0, 30.0, 1.0)
    speed = np.where((t < 10) | ((t >= 20) & (t < 23)), 0.0, 5.0)
    assert detect_standstill(t, speed, 0.2, 5.0) == [(0.0, 9.0)]
    assert detect_standstill(t, speed, 0.2, 2.0) == [(0.0, 9.0), (20.0, 22.0)]


def test_threshold_filter():
    out = threshold_filter(np.array([0.1, -0.1, 0.3, -0.5, 0.2]), 0.2)
    np.testing.assert_array_equal(out, [0.0, 0.0, 0.3, -0.5, 0.2])
    with pytest.raises(ValueError):
        threshold_filter(np.zeros(2), -1.0)


def test_distances_one_degree_of_latitude_and_agreement():
    one_degree = np.radians(1.0)
    assert equirectangular_distance(0.0, 0.0, one_degree, 0.0) == pytest.approx(
        M_PER_RAD * one_degree
    )
    assert haversine_distance(0.0, 0.0, one_degree, 0.0) == pytest.approx(M_PER_RAD * one_degree)
    lat = np.radians(35.0)
    d_eq = equirectangular_distance(lat, 0.0, lat + 1e-5, 1e-5)
    d_hv = haversine_distance(lat, 0.0, lat + 1e-5, 1e-5)
    assert d_eq == pytest.approx(d_hv, rel=1e-6)
    with pytest.raises(ValueError):
        step_lengths(np.zeros(2), np.zeros(2), "vincenty")


def _east_line(metres):
    """Latitudes/longitudes on the equator at the given east offsets (m)."""
    metres = np.asarray(metres, dtype=float)
    return np.zeros_like(metres), metres / M_PER_RAD


def test_select_fixes_every_mth_and_cluster():
    lat, lon = _east_line([0, 1, 2, 3.5, 4, 10, 11, 11.5, 12, 20])
    np.testing.assert_array_equal(select_fixes(lat, lon, 1, 3.0), [0, 3, 5, 9])
    np.testing.assert_array_equal(select_fixes(lat, lon, 2, 3.0), [0, 4, 6, 9])
    np.testing.assert_array_equal(select_fixes(lat, lon, 1, 3.0, np.array([1])), [0, 1, 4, 5, 9])
    np.testing.assert_array_equal(select_fixes(lat, lon, 1, 0.0), np.arange(10))


def test_reconstruction_interpolates_linearly_between_kept_fixes():
    t = np.arange(5.0)
    lat, lon = _east_line([0, 1, 10, 2, 20])
    track = reconstruct_track(t, lat, lon, downsample=2, cluster_m=3.0)
    np.testing.assert_array_equal(track.kept, [0, 2, 4])
    east = track.lon * M_PER_RAD
    np.testing.assert_allclose(east, [0, 5, 10, 15, 20], atol=1e-9)
    np.testing.assert_allclose(track.step_lengths(), 5.0, rtol=1e-9)
    with pytest.raises(InputError, match="strictly increasing"):
        reconstruct_track(np.array([0.0, 0.0]), lat[:2], lon[:2])


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(-50, 50), min_size=1, max_size=40),
    st.integers(1, 5),
    st.floats(0.0, 10.0),
)
def test_reconstruction_returns_one_point_per_original_time(offsets, m, cluster):
    t = np.cumsum(np.ones(len(offsets)))
    lat = np.radians(10.0) + np.asarray(offsets) / M_PER_RAD
    lon = np.radians(179.9999) + np.cumsum(offsets) / M_PER_RAD
    track = reconstruct_track(t, lat, lon, m, cluster)
    assert len(track.t) == len(t) and np.all(track.t == t)
    assert track.kept[0] == 0 and track.kept[-1] == len(t) - 1
    assert np.all(np.diff(track.kept) > 0)
    np.testing.assert_allclose(track.lat[track.kept], lat[track.kept], atol=1e-12)
    assert np.all(np.isfinite(track.lat)) and np.all(np.abs(track.lon) <= np.pi)


def test_integrate_yaw_rate_is_exact_for_linear_rates():
    t = np.linspace(0.0, 10.0, 101)
    yaw = cumulative_integral(t, 0.2 * t, initial=1.0)
    np.testing.assert_allclose(yaw, 1.0 + 0.1 * t**2, atol=1e-12)
    np.testing.assert_allclose(
        increments(t, 0.2 * t, t[::10], outside="hold"), np.diff(0.1 * t[::10] ** 2)
    )


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(0.0, 30.0), min_size=1, max_size=50),
    st.floats(-np.pi, np.pi),
)
def test_dead_reckoning_with_zero_rate_is_a_straight_line(steps, yaw0):
    steps = np.asarray(steps)
    t = np.arange(len(steps) + 1, dtype=float)
    dr = dead_reckon(t, steps, np.zeros(len(steps)), yaw0, start=(3.0, -2.0))
    distance = np.concatenate([[0.0], np.cumsum(steps)])
    np.testing.assert_allclose(dr.east, 3.0 + distance * np.cos(yaw0), atol=1e-9)
    np.testing.assert_allclose(dr.north, -2.0 + distance * np.sin(yaw0), atol=1e-9)
    np.testing.assert_allclose(np.cos(dr.yaw), np.cos(yaw0), atol=1e-12)


def test_dead_reckoning_yaw_convention_and_closed_polygon():
    dr = dead_reckon(np.arange(2.0), [1.0], [0.0], yaw0=np.pi / 2)
    assert dr.east[-1] == pytest.approx(0.0, abs=1e-12) and dr.north[-1] == pytest.approx(1.0)
    # A positive (CCW) yaw rate turns left: from east, a quarter turn ends heading north.
    n = 36
    radius = 50.0
    chord = 2 * radius * np.sin(np.pi / n)
    dr = dead_reckon(np.arange(n + 1.0), np.full(n, chord), np.full(n, 2 * np.pi / n), 0.0)
    assert dr.north[n // 4] > 0 and dr.east[n // 4] == pytest.approx(radius, abs=1e-9)
    gap = closed_loop_gap(dr.east, dr.north)
    assert gap.gap_m < 1e-9 and gap.length_m == pytest.approx(n * chord)
    assert dr.yaw[-1] == pytest.approx(0.0, abs=1e-9)


def test_track_yaw_and_heading_error_unwrapping():
    yaw = track_yaw(np.array([0.0, 1.0, 1.0, 1.0]), np.array([0.0, 0.0, 5.0, 5.1]))
    np.testing.assert_allclose(yaw[:2], [0.0, np.pi / 2])
    assert np.isnan(yaw[2]) and np.isnan(yaw[3])
    t = np.arange(0.0, 600.0, 1.0)
    error = heading_error(np.radians(t), np.zeros_like(t))
    np.testing.assert_allclose(error, np.radians(t), atol=1e-9)
    assert drift_rate_deg_per_min(t, error) == pytest.approx(60.0)
    assert drift_rate_deg_per_min(t, error, window_s=10.0) == pytest.approx(60.0)


def test_clean_series_counts_bad_samples():
    t = np.array([0.0, 1.0, 1.0, np.nan, 3.0, 2.0, 100.0])
    v = np.array([0.0, 1.0, 9.0, 1.0, 3.0, 2.0, np.nan])
    t2, v2, report = clean_series(t, v, "x")
    np.testing.assert_array_equal(t2, [0.0, 1.0, 2.0, 3.0])
    np.testing.assert_array_equal(v2, [0.0, 1.0, 2.0, 3.0])
    assert (report.n_non_finite, report.n_duplicate_times, report.n_unordered) == (2, 1, 1)
    t3, _, report = clean_series(np.array([0.0, 1, 2, 30, 31]), np.zeros(5), "gappy")
    assert report.n_gaps == 1 and report.longest_gap_s == 28.0 and len(t3) == 5


def test_align_rates_different_rates_and_overlap():
    t1 = np.arange(0.0, 10.0, 0.01)
    t2 = np.arange(1.0, 12.0, 0.02)
    aligned = align_rates(t1, 0.5 * t1, t2, 3.0 - 0.25 * t2)
    assert aligned.t[0] == pytest.approx(1.0) and aligned.t[-1] == pytest.approx(9.99)
    np.testing.assert_allclose(aligned.omega2, 3.0 - 0.25 * aligned.t, atol=1e-12)
    assert aligned.report1.rate_hz == pytest.approx(100.0)
    assert aligned.report2.rate_hz == pytest.approx(50.0)
    with pytest.raises(InputError, match="do not overlap"):
        align_rates(t1, t1, t1 + 100.0, t1)
