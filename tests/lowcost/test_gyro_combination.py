"""Two-gyro combination and the choice of k ([KZ] Eq. 7): exact cases."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.lowcost.gyro_combination import (
    choose_k,
    combine_rates,
    k_by_sweep,
    k_closed_form,
    k_inverse_variance,
)


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
