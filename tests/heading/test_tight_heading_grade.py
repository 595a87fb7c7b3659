"""The road grade unknown of the tightly coupled heading: v_t = s_t·[cos θ_t, sin θ_t, g].

On a climbing road the vertical velocity g·s_t shows in every Doppler row as −g_up·g·s_t; a
level-road model puts it into θ₀ and the clock drift. Exact synthetic cases: noise-free Doppler
on a known grade, with the grade's prior centred on the truth (exact heading), on zero (the
data outweigh the prior) and without the unknown (biased).
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from vo_doppler.geo import wrap_angle
from vo_doppler.heading.tight_heading import TightHeadingConfig, tight_heading_series
from vo_doppler.sim.doppler_rows import simulate_doppler

AZIMUTH = [30.0, 110.0, 200.0, 280.0, 330.0, 160.0]
ELEVATION = [60.0, 30.0, 45.0, 20.0, 70.0, 15.0]
T = np.arange(0.0, 6.0, 0.05)
GRADE = 0.05
LEVEL = TightHeadingConfig(grade_sigma=0.0)


def _turning(t):
    return 0.7 + 0.3 * t


def _straight(t):
    return 0.7 + 0.0 * t


def _speed(t):
    return 12.0 + 1.5 * np.sin(t)


def _scenario(yaw, n_sat, grade=GRADE, noise_mps=0.0):
    """Doppler rows of a drive climbing at ``grade`` (rise over run): the vertical velocity
    grade·s_t adds −g_up·grade·s_t to every row's range rate."""
    scenario = simulate_doppler(
        T, yaw, _speed, AZIMUTH, ELEVATION, n_sat, rotate=False, noise_mps=noise_mps
    )
    rows = scenario.rows
    climbing = rows.range_rate - rows.los[:, 2] * grade * _speed(rows.t)
    return dataclasses.replace(scenario, rows=dataclasses.replace(rows, range_rate=climbing))


def _errors(scenario, result):
    ok = result.available
    return np.abs(wrap_angle(result.yaw[ok] - scenario.yaw[ok]))


@pytest.mark.parametrize(("yaw", "n_sat"), [(_straight, 4), (_turning, 3), (_turning, 2)])
def test_grade_prior_at_the_truth_gives_the_exact_heading(yaw, n_sat):
    scenario = _scenario(yaw, n_sat)
    args = (scenario.rows, scenario.t_epoch, scenario.speed, scenario.yaw_angle)
    result = tight_heading_series(*args, grade_prior=(GRADE, 0.05))
    assert result.available[scenario.t_epoch >= 2.0].all()
    assert np.max(_errors(scenario, result)) < 1e-7
    level = tight_heading_series(*args, config=LEVEL)
    assert np.degrees(np.max(_errors(scenario, level))) > 0.2


def test_zero_mean_prior_is_outweighed_by_the_data():
    """Four satellites see the vertical: the grade is estimated and the heading is unbiased
    but for the prior's pull, under a hundredth of the level-road model's error (0.24°)."""
    scenario = _scenario(_straight, 4)
    args = (scenario.rows, scenario.t_epoch, scenario.speed, scenario.yaw_angle)
    full = scenario.t_epoch >= 2.0
    result = tight_heading_series(*args)
    level = tight_heading_series(*args, config=LEVEL)
    assert result.available[full].all() and level.available[full].all()
    error = np.abs(wrap_angle(result.yaw - scenario.yaw))[full]
    level_error = np.abs(wrap_angle(level.yaw - scenario.yaw))[full]
    assert np.max(error) < 1e-2 * np.min(level_error)
    assert np.max(error) < np.radians(0.001)


def test_two_satellites_on_a_grade_stay_available_and_within_sigma():
    """Two satellites: the grade is barely observable and the prior holds the window; the
    heading error the prior leaves is inside the σ it reports."""
    scenario = _scenario(_turning, 2)
    result = tight_heading_series(
        scenario.rows, scenario.t_epoch, scenario.speed, scenario.yaw_angle
    )
    full = scenario.t_epoch >= 2.0
    assert result.available[full].all()
    normalised = _errors(scenario, result) / result.sigma[result.available]
    assert np.max(normalised) < 1.0


def test_level_road_heading_unchanged_by_the_grade_unknown():
    """Noise-free level road: the grade estimate is zero and the heading the level model's."""
    scenario = simulate_doppler(T, _turning, _speed, AZIMUTH, ELEVATION, 3, rotate=False)
    args = (scenario.rows, scenario.t_epoch, scenario.speed, scenario.yaw_angle)
    result, level = tight_heading_series(*args), tight_heading_series(*args, config=LEVEL)
    np.testing.assert_array_equal(result.available, level.available)
    assert np.max(np.abs(wrap_angle(result.yaw - level.yaw)[result.available])) < 1e-9
    np.testing.assert_allclose(
        result.clock_drift[result.available], level.clock_drift[level.available], atol=1e-7
    )


def test_noisy_level_road_moves_the_heading_within_sigma():
    """With noise the grade unknown takes up a little of it. Both estimators are unbiased and
    the level model is the efficient one on a level road, so their difference has the variance
    σ² − σ_level² (Hausman): it stays within 4 of those σ over the drive's full windows, and
    the σ with the unknown is the wider."""
    scenario = simulate_doppler(
        T, _turning, _speed, AZIMUTH, ELEVATION, 4, rotate=False, noise_mps=0.05, seed=4
    )
    args = (scenario.rows, scenario.t_epoch, scenario.speed, scenario.yaw_angle)
    result, level = tight_heading_series(*args), tight_heading_series(*args, config=LEVEL)
    both = result.available & level.available & (scenario.t_epoch >= 2.0)
    assert both.sum() == np.count_nonzero(scenario.t_epoch >= 2.0)
    assert np.all(result.sigma[both] > level.sigma[both])
    difference = np.abs(wrap_angle(result.yaw - level.yaw)[both])
    assert np.all(difference < 4.0 * np.sqrt(result.sigma[both] ** 2 - level.sigma[both] ** 2))
