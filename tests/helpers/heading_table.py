"""A heading table of plain values for tests that need one but not its content."""

from __future__ import annotations

import numpy as np

from vo_doppler.model.heading import HeadingTable


def plain_heading_table(t: np.ndarray, **columns) -> HeadingTable:
    """Every epoch of ``t``: both headings 0 and valid, σ 0.5°, reliable, 60 Doppler rows of 3
    satellites, no gyro bias, wheel scale 1; ``columns`` replace any of these."""
    n = len(t)
    values = {
        "yaw_tc": np.zeros(n),
        "sigma_tc": np.full(n, np.radians(0.5)),
        "tc_reliable": np.ones(n, bool),
        "n_obs_window": np.full(n, 60),
        "n_sat_epoch": np.full(n, 3),
        "yaw_conv": np.zeros(n),
        "conv_valid": np.ones(n, bool),
        "gyro_bias": np.zeros(n),
        "wheel_scale": np.ones(n),
    }
    return HeadingTable(t=np.asarray(t, dtype=float), **{**values, **columns})
