"""Wavelengths of RINEX observables per row, and the codes and bands the GNSS stage takes.

The carrier frequencies themselves (``FREQUENCIES_HZ``, ``GLONASS_FDMA``,
:func:`carrier_frequency`) are interface facts kept in :mod:`vo_doppler.model.signals`, where
the readers find them too; they are imported here under the same names.
"""

from __future__ import annotations

import numpy as np

from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.model.signals import (  # noqa: F401 (this module's public names)
    FREQUENCIES_HZ,
    GLONASS_FDMA,
    MHZ,
    carrier_frequency,
)


def wavelengths(
    system: np.ndarray,
    prn: np.ndarray,
    code: str,
    glonass_channels: dict[int, int],
    rinex_version: float = 3.04,
) -> np.ndarray:
    """Wavelength (m) per row for one observable code; NaN where the frequency is unknown."""
    out = np.full(np.shape(prn), np.nan)
    for s in np.unique(system):
        rows = system == s
        if s == "R":
            for p in np.unique(prn[rows]):
                f = carrier_frequency("R", code, glonass_channels.get(int(p)), rinex_version)
                out[rows & (prn == p)] = np.nan if f is None else SPEED_OF_LIGHT / f
        else:
            f = carrier_frequency(str(s), code, None, rinex_version)
            out[rows] = np.nan if f is None else SPEED_OF_LIGHT / f
    return out


def strength_code(doppler_code: str) -> str:
    """The signal-strength observable of the same signal: 'D1C' → 'S1C', 'D1' → 'S1'."""
    return "S" + doppler_code[1:]


def bands_problem(bands: str) -> str | None:
    """Why ``bands`` is not a string of RINEX band digits 1-9 (e.g. "1" or "15"), or None."""
    if not isinstance(bands, str) or not bands or set(bands) - set("123456789"):
        return f"expected RINEX band digits 1-9, e.g. 1 or 15, got {bands!r}"
    return None
