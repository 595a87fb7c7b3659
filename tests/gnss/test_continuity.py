"""Kinematic continuity of the conventional Doppler velocity (design (2b))."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.velocity import velocity_solution
from vo_doppler.checks import continuity_warning
from vo_doppler.gnss.continuity import continuity_checked
from vo_doppler.model.gnss_solutions import VelocitySolution

SPEED_MPS = 15.0
COURSE_SIGMA = np.radians(0.3)
SPEED_SIGMA = 0.05


def _solution(rate_hz: float, seed: int = 1) -> tuple[VelocitySolution, np.ndarray]:
    """A car at 15 m/s weaving (yaw acceleration up to 10 °/s²) and accelerating, its velocity
    noisy at exactly the stated σ; also the true course."""
    t = np.arange(0.0, 120.0, 1.0 / rate_hz)
    course = np.radians(30.0) * np.sin(2.0 * np.pi * t / 10.5)  # peak 10.3 °/s²
    speed = SPEED_MPS + 2.0 * np.sin(2.0 * np.pi * t / 20.0)
    rng = np.random.default_rng(seed)
    noisy_course = course + rng.normal(0.0, COURSE_SIGMA, t.size)
    noisy_speed = speed + rng.normal(0.0, SPEED_SIGMA, t.size)
    enu = np.column_stack(
        [noisy_speed * np.cos(noisy_course), noisy_speed * np.sin(noisy_course), np.zeros(t.size)]
    )
    n = t.size
    solution = velocity_solution(
        t,
        enu,
        verified=np.ones(n, dtype=bool),
        speed_sigma_mps=np.full(n, SPEED_SIGMA),
        course_sigma_rad=np.full(n, COURSE_SIGMA),
    )
    return solution, course


def _turned(solution: VelocitySolution, epoch: int, angle_rad: float) -> VelocitySolution:
    enu = solution.velocity_enu.copy()
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    enu[epoch, :2] = [c * enu[epoch, 0] - s * enu[epoch, 1], s * enu[epoch, 0] + c * enu[epoch, 1]]
    return VelocitySolution(**{**solution.__dict__, "velocity_enu": enu})


def test_one_epoch_off_course_fails_and_a_weaving_drive_passes():
    solution, _ = _solution(10.0)
    checked = continuity_checked(solution)
    # honest σ, a weaving drive: false alarms near the test's 0.001
    assert (~checked.valid).mean() < 0.004
    faulty = continuity_checked(_turned(solution, 600, np.radians(2.4)))  # 8σ off course
    assert not faulty.valid[600]
    assert faulty.verified[600]
    np.testing.assert_array_equal(faulty.valid[590:600], checked.valid[590:600])


def test_the_speed_is_not_tested_braking_onsets_are_kinks():
    solution, _ = _solution(10.0, seed=2)
    enu = solution.velocity_enu.copy()
    t = solution.t
    speed = np.hypot(enu[:, 0], enu[:, 1])
    braking = -2.5 * np.clip(t - 60.0, 0.0, 3.0)  # 0 → −2.5 m/s² → 0 at once
    enu[:, :2] *= ((speed + braking) / speed)[:, None]
    kinked = VelocitySolution(**{**solution.__dict__, "velocity_enu": enu})
    np.testing.assert_array_equal(
        continuity_checked(kinked).valid, continuity_checked(solution).valid
    )


def test_a_one_hertz_receiver_is_not_tested():
    solution, _ = _solution(1.0)
    faulty = continuity_checked(_turned(solution, 60, np.radians(5.0)))
    np.testing.assert_array_equal(faulty.valid, solution.valid)


def test_invalid_epochs_stay_invalid_and_are_not_neighbours():
    solution, _ = _solution(10.0, seed=3)
    valid = solution.valid.copy()
    valid[100:110] = False
    enu = solution.velocity_enu.copy()
    enu[100:110, :2] *= -1.0  # reversed, but not valid: must not pull the neighbours' lines
    given = VelocitySolution(**{**solution.__dict__, "velocity_enu": enu, "valid": valid})
    checked = continuity_checked(given)
    assert not checked.valid[100:110].any()
    assert checked.valid[90:100].all() and checked.valid[110:120].all()


@pytest.mark.parametrize(
    "rate_hz, decides", [(1.0, False), (5.0, False), (10.0, True), (20.0, True)]
)
def test_the_test_decides_where_half_a_second_holds_five_neighbours_and_says_so_elsewhere(
    rate_hz, decides
):
    """±0.5 s holds 0 (1 Hz), 4 (5 Hz), 10 (10 Hz) or 20 (20 Hz) other epochs; the parabola
    needs 5. Where it cannot decide, the epoch 8σ off course keeps its verdict, untested, and
    the warning says so."""
    solution, _ = _solution(rate_hz, seed=4)
    k = int(np.argmin(np.abs(solution.t - 60.0)))
    faulty = continuity_checked(_turned(solution, k, np.radians(2.4)))
    assert bool(faulty.valid[k]) is not decides
    tested = faulty.continuity_tested.mean()
    assert tested > 0.99 if decides else tested == 0.0
    warning = continuity_warning(faulty)
    assert (warning is None) is decides
    if not decides:
        assert f"the epochs are {1.0 / rate_hz:.2g} s apart" in warning
