"""Kinematic continuity of the conventional Doppler velocity (docs/design.md (2b)).

A vehicle's course is continuous: steering turns the car smoothly, so over half a second the
course follows a parabola in time (the yaw rate and a steady yaw acceleration), while a fault of
one epoch (several satellites reflected at once and fitted by a wrong velocity, which the
chi-square test with one or two degrees of freedom passes) jumps off it. Each valid epoch's
course is tested against a robust parabola through the other valid epochs within
±``half_window_s`` (:mod:`vo_doppler.gnss.windowed_line`, (I1)); a line would be off by the
yaw acceleration times half the mean squared time offset (0.6° at 10 °/s² in ±0.5 s, two σ of
the course at 15 m/s). The speed is not tested: the onset of braking changes the acceleration
within a fraction of a second (a kink the parabola misses by more than the speed's σ), and the
heading stage tests it against the wheel speed. Epochs with fewer than ``min_neighbours`` valid
others in the window (a 1 Hz receiver) are not tested and keep their verdict. A fault that lasts
most of the window is not seen: the heading stage tests the velocity over ±5 s against the
car's gyro and wheel speed (:mod:`vo_doppler.heading.integrity`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vo_doppler.gnss.windowed_line import ConsistencyConfig, consistency_test
from vo_doppler.model.gnss_solutions import VelocitySolution

CONTINUITY = ConsistencyConfig(half_window_s=0.5, min_neighbours=5, degree=2)


def continuity_checked(
    solution: VelocitySolution, config: ConsistencyConfig = CONTINUITY
) -> VelocitySolution:
    """``solution`` with ``valid`` cleared where the course fails the continuity test (module
    docstring) and ``continuity_tested`` set where it could judge; ``verified`` (the epoch's
    own tests) is kept."""
    if not config.enabled or solution.course_sigma_rad is None:
        return solution
    velocity = solution.velocity_enu
    t, valid = solution.t, solution.valid
    course = np.arctan2(velocity[:, 1], velocity[:, 0])
    test = consistency_test(t, course, solution.course_sigma_rad, valid, config, angular=True)
    tested = valid & np.isfinite(test.z)
    return replace(solution, valid=valid & ~test.failed, continuity_tested=tested)
