"""A velocity solution's derived figures: horizontal speed, √trace σ and course clockwise from
north in [0, 360)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from tests.helpers.velocity import velocity_solution


def test_speed_sigma_and_course_of_each_epoch():
    enu = np.array([[3.0, 4.0, 9.0], [0.0, -2.0, 0.0], [-1.0, 0.0, 0.0], [-1.0, 1.0, 0.0]])
    solution = velocity_solution(np.arange(4.0), enu)
    covariance = np.tile(np.diag([0.04, 0.09, 0.36, 5.0]), (4, 1, 1))
    solution = replace(solution, covariance=covariance)
    np.testing.assert_allclose(solution.speed_mps, [5.0, 2.0, 1.0, np.sqrt(2.0)])
    np.testing.assert_allclose(solution.sigma_mps, np.sqrt(0.49))  # the clock drift left out
    # (3, 4): 36.87° east of north; south 180°; west 270°; north-west 315°
    np.testing.assert_allclose(
        solution.course_deg, [np.degrees(np.arctan2(3, 4)), 180.0, 270.0, 315.0], atol=1e-12
    )
