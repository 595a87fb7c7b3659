"""A conventional velocity solution built from ENU velocities, for tests of what consumes it."""

from __future__ import annotations

import numpy as np

from vo_doppler.model.gnss_solutions import VelocitySolution


def velocity_solution(
    t: np.ndarray, enu: np.ndarray, valid: np.ndarray | None = None, **extra
) -> VelocitySolution:
    """Eight satellites per epoch, no covariance or DOP; ``enu`` also stands for the ECEF
    velocity; ``valid`` defaults to every epoch; ``extra`` sets the optional fields."""
    n = t.size
    return VelocitySolution(
        t=t,
        velocity_ecef=enu,
        velocity_enu=enu,
        clock_drift_mps=np.zeros(n),
        covariance=np.full((n, 4, 4), np.nan),
        dop=np.full((n, 5), np.nan),
        n_sat=np.full(n, 8),
        n_obs=np.full(n, 8),
        n_excluded=np.zeros(n, dtype=int),
        residual_rms_mps=np.full(n, 0.05),
        valid=np.ones(n, dtype=bool) if valid is None else valid,
        **extra,
    )
