"""SensorSeries refuses what every stage would misread: NaN values or times, unsorted or repeated
times, arrays of different lengths or not 1-D (QA round 3, finding 3)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.errors import InputError
from vo_doppler.model.series import SensorSeries

finite = st.floats(-1e3, 1e3, allow_nan=False)
steps = st.lists(st.floats(1e-3, 10.0), min_size=2, max_size=40)


def series_arrays(step_list: list[float], values: st.DataObject) -> tuple[np.ndarray, np.ndarray]:
    t = 100.0 + np.cumsum(step_list)
    value = np.array(values.draw(st.lists(finite, min_size=t.size, max_size=t.size)))
    return t, value


@settings(max_examples=50, deadline=None)
@given(steps, st.data())
def test_a_valid_series_is_kept_as_given_and_shifts_exactly(step_list, data):
    t, value = series_arrays(step_list, data)
    series = SensorSeries(list(t), list(value), "speed", "m/s")
    np.testing.assert_array_equal(series.t, t)
    np.testing.assert_array_equal(series.value, value)
    assert len(series) == t.size
    shifted = series.shifted(-2.5)
    np.testing.assert_array_equal(shifted.t, t - 2.5)
    np.testing.assert_array_equal(shifted.value, value)


@settings(max_examples=50, deadline=None)
@given(steps, st.data(), st.sampled_from([np.nan, np.inf, -np.inf]))
def test_a_non_finite_value_is_refused_naming_its_index(step_list, data, bad):
    t, value = series_arrays(step_list, data)
    k = data.draw(st.integers(0, t.size - 1))
    value[k] = bad
    with pytest.raises(InputError, match=rf"sensor series 'yaw': value\[{k}\] .* is {bad}"):
        SensorSeries(t, value, "yaw")


@settings(max_examples=50, deadline=None)
@given(steps, st.data())
def test_times_out_of_order_or_repeated_are_refused_naming_the_first(step_list, data):
    t, value = series_arrays(step_list, data)
    k = data.draw(st.integers(1, t.size - 1))
    t[k] = t[k - 1] - data.draw(st.sampled_from([0.0, 0.5]))
    with pytest.raises(InputError, match=rf"times must increase strictly, but t\[{k}\]"):
        SensorSeries(t, value)


@pytest.mark.parametrize(
    ("t", "value", "message"),
    [
        ([0.0, 1.0, 2.0], [1.0, 2.0], "3 times but 2 values"),
        ([[0.0, 1.0]], [1.0, 2.0], r"t must be 1-D, not of shape \(1, 2\)"),
        ([0.0, np.nan], [1.0, 2.0], r"t\[1\] is nan"),
    ],
)
def test_malformed_arrays_are_refused(t, value, message):
    with pytest.raises(InputError, match=message):
        SensorSeries(t, value)


def test_an_empty_series_is_allowed():
    assert len(SensorSeries(np.zeros(0), np.zeros(0))) == 0


def test_the_series_keeps_its_own_copy_of_the_checked_arrays():
    t, value = np.array([0.0, 1.0, 2.0]), np.array([1.0, 2.0, 3.0])
    series = SensorSeries(t, value, "speed")
    t[2], value[0] = 0.5, np.nan  # would fail the checks, but after construction
    np.testing.assert_array_equal(series.t, [0.0, 1.0, 2.0])
    np.testing.assert_array_equal(series.value, [1.0, 2.0, 3.0])
    shifted = series.shifted(1.0)
    shifted.value[0] = 7.0
    assert series.value[0] == 1.0
