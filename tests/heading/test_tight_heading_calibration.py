"""A causal calibration that changes within a window: each window uses its newest epoch's."""

from __future__ import annotations

import numpy as np

from vo_doppler.geo import wrap_angle
from vo_doppler.heading.tight_heading import TightHeadingConfig, tight_heading_series
from vo_doppler.sim.doppler_rows import simulate_doppler

AZIMUTH = [30.0, 110.0, 200.0, 280.0, 330.0]
ELEVATION = [60.0, 30.0, 45.0, 20.0, 70.0]
T = np.arange(0.0, 8.0, 0.05)
TRUE_SCALE = 0.98
TRUE_BIAS = 0.01  # rad/s
SETTLED_S = 3.0


def test_windows_take_the_calibration_of_their_newest_epoch():
    scenario = simulate_doppler(
        T, lambda t: 0.7 + 0.3 * t, lambda t: 10.0 + 0.0 * t, AZIMUTH, ELEVATION, 4
    )
    raw_speed = scenario.speed / TRUE_SCALE
    raw_angle = scenario.yaw_angle + TRUE_BIAS * (T - T[0])
    settled = T >= SETTLED_S
    scale = np.where(settled, TRUE_SCALE, 1.05)  # the prior's, then the truth
    bias = np.where(settled, TRUE_BIAS, 0.0)
    bias_integral = np.concatenate([[0.0], np.cumsum(bias[:-1] * np.diff(T))])
    speed, yaw_angle = scale * raw_speed, raw_angle - bias_integral
    config = TightHeadingConfig(grade_sigma=0.0)

    def heading_error(calibration):
        result = tight_heading_series(
            scenario.rows, T, speed, yaw_angle, config, calibration=calibration
        )
        late = result.available & settled
        return np.abs(wrap_angle(result.yaw[late] - scenario.yaw[late]))

    exact = heading_error((scale, bias, bias_integral))
    mixed = heading_error(None)
    assert exact.size == settled.sum() and np.max(exact) < 1e-6
    # the rows before 3 s still carry the prior's 5 %: windows lost or off
    assert mixed.size < exact.size and np.max(mixed) > 1e-3
