"""The one time-series toolkit: exact integrals, samples and the edge rules."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.model.timeseries import (
    cumulative_integral,
    hold,
    increments,
    integral_at,
    sample,
    time_grid,
    travelled_distance,
)

T = np.array([0.0, 1.0, 2.0])
V = np.array([0.0, 2.0, 2.0])
QUERY = np.array([-1.0, 0.5, 1.0, 2.0, 3.0])


def test_integrate_yaw_rate_is_exact_for_linear_rates():
    t = np.linspace(0.0, 10.0, 101)
    yaw = cumulative_integral(t, 0.2 * t, initial=1.0)
    np.testing.assert_allclose(yaw, 1.0 + 0.1 * t**2, atol=1e-12)
    np.testing.assert_allclose(
        increments(t, 0.2 * t, t[::10], outside="hold"), np.diff(0.1 * t[::10] ** 2)
    )


def test_sample_is_nan_outside_unless_held():
    np.testing.assert_allclose(sample(T, V, QUERY), [np.nan, 1.0, 2.0, 2.0, np.nan])
    np.testing.assert_allclose(sample(T, V, QUERY, outside="hold"), [0.0, 1.0, 2.0, 2.0, 2.0])


def test_hold_takes_the_last_sample_at_or_before():
    np.testing.assert_allclose(hold(T, V, QUERY), [np.nan, 0.0, 2.0, 2.0, np.nan])
    np.testing.assert_allclose(hold(T, V, QUERY, outside="hold"), [0.0, 0.0, 2.0, 2.0, 2.0])


def test_the_three_edge_rules_of_an_integral():
    np.testing.assert_allclose(integral_at(T, V, QUERY), [np.nan, 0.5, 1.0, 3.0, np.nan])
    np.testing.assert_allclose(integral_at(T, V, QUERY, outside="hold"), [0.0, 0.5, 1.0, 3.0, 3.0])
    np.testing.assert_allclose(
        travelled_distance(T, V, QUERY, outside="extend"), [0.0, 0.5, 1.0, 3.0, 5.0]
    )


def test_empty_records_and_unknown_rules():
    assert np.isnan(sample(np.zeros(0), np.zeros(0), [1.0])).all()
    assert np.isnan(integral_at(np.zeros(0), np.zeros(0), [1.0])).all()
    with pytest.raises(ValueError, match=r"^outside='extend': use one of nan, hold$"):
        sample(T, V, QUERY, outside="extend")
    with pytest.raises(ValueError, match=r"^outside='zero': use one of nan, hold, extend$"):
        integral_at(T, V, QUERY, outside="zero")
    with pytest.raises(ValueError, match="3 times but 2 values"):
        cumulative_integral(T, V[:2])


@settings(max_examples=50, deadline=None)
@given(
    st.lists(st.floats(0.01, 10.0), min_size=2, max_size=30),
    st.lists(st.floats(-5.0, 5.0), min_size=30, max_size=30),
)
def test_increments_sum_to_the_whole_integral(steps, values):
    t = np.cumsum(steps)
    rate = np.array(values[: len(t)])
    total = cumulative_integral(t, rate)[-1]
    assert np.sum(increments(t, rate, t)) == pytest.approx(total, abs=1e-9)


@pytest.mark.parametrize("origin", [0.0, 1425953400.0, 2425687800.0])
def test_a_time_grid_is_the_same_at_any_time_origin(origin):
    """``begin + k·step`` at every origin, as many times as ``np.arange`` gives; np.arange's own
    grid at 2.4e9 s drifts by 1.8e-4 s over 760 steps (issue 30)."""
    grid = time_grid(origin + 0.013, origin + 38.0, 0.05)
    assert grid.size == np.arange(0.013, 38.0, 0.05).size == 760
    np.testing.assert_allclose(grid - origin, 0.013 + 0.05 * np.arange(760), rtol=0, atol=1e-6)
    assert time_grid(origin + 5.0, origin + 5.0, 0.05).size == 0
    assert time_grid(origin + 5.0, origin + 4.0, 0.05).size == 0
