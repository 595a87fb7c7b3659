"""A pseudorange noise model estimated from the data: σ of each pseudorange as a function of
C/N0 and elevation, one per receiver signal (system and pseudorange code), fitted to the
residuals of a first single-point solution.

Model and fit: those of the Doppler noise (``noise_model``): log₁₀ σ = a − b·(C/N0 − 45)/20 +
c·log₁₀(1/sin el), (a, b, c) the least-squares fit of log₁₀ of the robust σ (normalised MAD)
of the residuals binned by C/N0 and elevation, each residual first divided by √r_i, r_i its
redundancy number in its epoch's weighted design (a least-squares residual has variance
r_i σ_i²). The code-tracking loop's thermal noise follows the same (C/N0)^(−1/2) law as the
frequency-lock loop's (Kaplan & Hegarty, "Understanding GPS/GNSS", 3rd ed., sec. 8.7), with
multipath and diffraction making weak signals noisier still (a free slope). A signal without
two C/N0 bins (no signal strength in the file, or one strength throughout) keeps the a-priori
law ``SIGMA_PRIOR_M``/sin el scaled by the normalised MAD of its residuals in units of it.

The residuals include the rows the fault exclusion removed, so a receiver whose weak signals
are often reflected gets their σ large; the normalised MAD is unmoved by up to half the rows
being reflections, whose biases the chi-square test and its exclusion must then take.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.gnss.noise_model import MIN_BIN_ROWS, MIN_ELEVATION_RAD, fit_sigma_law, sigma_law
from vo_doppler.robust import nmad

SIGMA_PRIOR_M = 3.0
"""σ (m) of a zenith pseudorange before any fit (a GPS C/A code receiver's, multipath included)."""
FLOOR_M = 0.3
"""No pseudorange is trusted beyond 0.3 m (a code loop's noise at strong signals, one fit from
a few very quiet rows could otherwise claim centimetres)."""
SCALE_RANGE = (0.1, 30.0)
"""The fallback's scale of the a-priori law is kept inside this range."""
MIN_SCALE_ROWS = 30
"""Fewer residuals fit no scale: the signal keeps the a-priori law."""


@dataclass(frozen=True)
class PseudorangeNoiseModel:
    """σ(C/N0, elevation) of one receiver signal's pseudoranges (module docstring): ``law`` =
    (10^a, b, c), 10^a the σ (m) at 45 dB-Hz and zenith; ``ranges`` the C/N0 (dB-Hz) and
    elevation (rad) ranges of the data it was fitted on (queries are clamped to them); how many
    rows and bins; ``cn0_fitted`` False for the scaled a-priori law (b = 0, c = 1)."""

    system: str
    code: str
    law: tuple[float, float, float]
    ranges: tuple[tuple[float, float], tuple[float, float]]
    n_rows: int
    n_bins: int
    cn0_fitted: bool = True

    def sigma(self, cn0: np.ndarray, elevation: np.ndarray) -> np.ndarray:
        """σ (m) of pseudoranges of this signal; a missing C/N0 reads as the reference."""
        return sigma_law(self.law, self.ranges, cn0, elevation, FLOOR_M)


def prior_sigma(elevation: np.ndarray) -> np.ndarray:
    """The a-priori σ (m): ``SIGMA_PRIOR_M`` / sin(elevation), elevation at least 5°."""
    return SIGMA_PRIOR_M / np.sin(np.maximum(elevation, MIN_ELEVATION_RAD))


def fit_pseudorange_noise(
    residual: np.ndarray,
    system: np.ndarray,
    code: np.ndarray,
    cn0: np.ndarray,
    elevation: np.ndarray,
    min_bin_rows: int = MIN_BIN_ROWS,
) -> dict[tuple[str, str], PseudorangeNoiseModel]:
    """One model per (system, code) from normalised residuals (m, NaN where unknown) and the
    rows' C/N0 (dB-Hz) and elevation (rad); signals with fewer than ``MIN_SCALE_ROWS``
    residuals get none (the a-priori law)."""
    known = np.isfinite(residual) & np.isfinite(elevation)
    models = {}
    for s, c in sorted({(str(a), str(b)) for a, b in zip(system, code, strict=True)}):
        members = known & (system == s) & (code == c)
        strong = members & np.isfinite(cn0)
        law = fit_sigma_law(residual[strong], cn0[strong], elevation[strong], min_bin_rows)
        if law is not None:  # (σ_ref, b, c, C/N0 range, elevation range, bins)
            models[(s, c)] = PseudorangeNoiseModel(
                s, c, law[:3], (law[3], law[4]), int(strong.sum()), law[5]
            )
        elif members.sum() >= MIN_SCALE_ROWS:
            ratio = residual[members] / prior_sigma(elevation[members])
            scale = float(np.clip(nmad(ratio, centre=False), *SCALE_RANGE))
            models[(s, c)] = PseudorangeNoiseModel(
                s,
                c,
                (scale * SIGMA_PRIOR_M, 0.0, 1.0),
                ((-np.inf, np.inf), (MIN_ELEVATION_RAD, np.pi / 2)),
                int(members.sum()),
                0,
                cn0_fitted=False,
            )
    return models
