"""Ephemeris values on a navigation message's quantisation grid, for the encoders' tests:
rounding known values to each field's least significant bit, and hypothesis strategies of valid
Keplerian ephemerides whose every scaled field is a whole number of its LSB."""

from __future__ import annotations

import numpy as np
from hypothesis import strategies as st


def on_grid(eph: dict[str, float], scales: dict[str, float], names) -> dict[str, float]:
    """``eph`` with each parameter of ``names`` rounded to its LSB in ``scales``."""
    return {
        k: (float(np.round(v / scales[k]) * scales[k]) if k in names else v) for k, v in eph.items()
    }


def grid(scale: float, low: float, high: float):
    """Whole numbers of ``scale`` between ``low`` and ``high``."""
    return st.integers(int(np.ceil(low / scale)), int(np.floor(high / scale))).map(
        lambda n: n * scale
    )


def kepler_strategy(scales: dict[str, float], **specific):
    """Ephemerides with the usual ranges of the fields every Keplerian message has (angles over
    the circle, rates, harmonic corrections, clock drift and its rate, group delays), plus the
    system's own fields ``specific`` (name → strategy)."""
    common = {
        "m0": (-np.pi, np.pi),
        "omega0": (-np.pi, np.pi),
        "omega": (-np.pi, np.pi),
        "idot": (-1e-9, 1e-9),
        "omega_dot": (-1e-8, 1e-8),
        "delta_n": (-1e-8, 1e-8),
        "cuc": (-5e-5, 5e-5),
        "cus": (-5e-5, 5e-5),
        "cic": (-5e-5, 5e-5),
        "cis": (-5e-5, 5e-5),
        "crc": (-1000.0, 1000.0),
        "crs": (-1000.0, 1000.0),
        "af1": (-1e-9, 1e-9),
        "af2": (-1e-17, 1e-17),
        "tgd": (-5e-8, 5e-8),
        "iodc": (-5e-8, 5e-8),
    }
    fields = {name: grid(scales[name], low, high) for name, (low, high) in common.items()}
    return st.fixed_dictionaries(fields | specific)
