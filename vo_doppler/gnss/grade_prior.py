"""The road's grade as a prior on a land vehicle's vertical velocity (docs/design.md (2a)).

A car climbs no steeper than its road: its vertical velocity is the grade times its horizontal
speed s. As a pseudo-observation of the velocity: v_u = 0 with σ_g = √((g·s)² + f²), g the
grade's σ (``GRADE_SIGMA``, 10 %: the 3σ bound is a 30 % grade, steeper than public roads) and
f a floor for suspension, a walker's gait or a phone in a hand (``VERTICAL_FLOOR_MPS``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.gnss.lsq import Constraint

GRADE_SIGMA = 0.1
"""σ of a land vehicle's vertical over its horizontal speed: a road's grade of 10 %."""
VERTICAL_FLOOR_MPS = 0.1
"""σ of the vertical velocity at any speed."""
GRADE_SPEED_CAP_MPS = 70.0
"""The speed beyond which the prior stops widening (a car's top speed): a wild first solution
must not free the vertical."""


@dataclass(frozen=True)
class GradePrior:
    """The prior at one epoch: ``up`` the local vertical (ECEF unit vector) and its σ (m/s)."""

    up: np.ndarray
    sigma: float

    @property
    def constraint(self) -> Constraint:
        """The prior as one row of a velocity + clock-drift problem (unknowns [v, b])."""
        return Constraint(np.append(self.up, 0.0)[None, :], np.zeros(1), np.array([self.sigma]))


def grade_prior(rotation: np.ndarray, velocity_ecef: np.ndarray) -> GradePrior:
    """The prior at a receiver whose ECEF → ENU rotation is ``rotation``, for a vehicle moving
    at ``velocity_ecef`` (its horizontal speed, capped at ``GRADE_SPEED_CAP_MPS``; NaN: 0)."""
    enu = rotation @ np.asarray(velocity_ecef, dtype=float)
    speed = min(float(np.nan_to_num(np.hypot(enu[0], enu[1]))), GRADE_SPEED_CAP_MPS)
    return GradePrior(rotation[2].copy(), float(np.hypot(GRADE_SIGMA * speed, VERTICAL_FLOOR_MPS)))
