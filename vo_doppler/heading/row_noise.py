"""Doppler noise of a moving receiver, measured from the data: the a-priori σ of each row
(C/N0 and elevation, ``gnss.noise_model`` or the receiver's own) plus a share that grows with
the vehicle's speed, strongest on weak signals.

Why: a reflected or diffracted signal arrives from another direction than the line of sight,
so its Doppler differs from the direct one by v·(e_direct − e_reflected), proportional to the
speed v; the weaker the received signal, the larger the share of such paths in it (a
multipath-dominated channel). On the Hong Kong canyon drive (u-blox M8T, 1 Hz; residuals
against the reference velocity, per-epoch clock removed) rows of 25–30 dB-Hz have a normalised
MAD of 0.08 m/s at standstill and 1.5 m/s above 3 m/s, rows of 35–40 dB-Hz 0.04 and 0.14 m/s:
a C/N0 law alone cannot describe both. The model per row i is

    σ_i² = σ_prior,i² + (k(C/N0_i) · s_i)²,    log₁₀ k(C) = κ₀ + κ₁ · (C − C_ref) / 10 dB,

with s_i the wheel speed at the row's epoch. (κ₀, κ₁) are fitted to the residuals of the
conventional solutions (each divided by √r_i, r_i its redundancy number, so that its variance
is σ_i²; ``gnss.noise_model.normalised_residuals``): the rows of moving epochs are binned by
C/N0, each bin's excess k_b² = (MAD_b² − median σ_prior²) / median s² (robust: half of a
bin may be reflections), and log₁₀ k_b is fitted as a line in C/N0, each bin weighted by its
row count. The tail beyond that σ is heavy (a reflection is a bias, not noise): the tight
heading's robust fit takes it (Student-t weights, :mod:`vo_doppler.heading.tight_heading`).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from vo_doppler.gnss.doppler_noise import MAD_TO_SIGMA

CN0_REFERENCE_DBHZ = 35.0
CN0_BIN_DBHZ = 5.0
MOVING_MPS = 2.0
MIN_BIN_ROWS = 20
DEFAULT_SLOPE = -1.0
"""κ₁ where only one C/N0 bin has data: k falls tenfold per 10 dB, as measured on the Hong Kong
drive (−1.0 between 25 and 40 dB-Hz)."""
SLOPE_RANGE = (-2.0, 0.0)
MAX_K = 1.0
"""k is at most 1 (a reflected path's Doppler error is at most about twice the speed along
the line of sight, and a σ of one speed already weighs a row out)."""


@dataclass(frozen=True)
class RowNoiseModel:
    """σ_i² = σ_prior,i² + (k(C/N0_i)·s_i)² (module docstring): ``k_ref`` = 10^κ₀ (s⁻¹·s, i.e.
    m/s of σ per m/s of speed at ``CN0_REFERENCE_DBHZ``), ``k_slope`` = κ₁ per 10 dB, and how
    many moving rows and C/N0 bins it was fitted on (0: not fitted, k = 0)."""

    k_ref: float = 0.0
    k_slope: float = DEFAULT_SLOPE
    n_rows: int = 0
    n_bins: int = 0

    def speed_coefficient(self, cn0: np.ndarray) -> np.ndarray:
        """k (m/s of σ per m/s of speed) of rows of C/N0 ``cn0`` (dB-Hz; missing: reference)."""
        cn0 = np.nan_to_num(np.asarray(cn0, dtype=float), nan=CN0_REFERENCE_DBHZ)
        k = self.k_ref * 10.0 ** (self.k_slope * (cn0 - CN0_REFERENCE_DBHZ) / 10.0)
        return np.minimum(k, MAX_K)

    def sigma(self, prior_sigma: np.ndarray, cn0: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """σ (m/s) of rows with a-priori σ ``prior_sigma`` at ``speed`` (m/s; NaN: standstill)."""
        moving = self.speed_coefficient(cn0) * np.nan_to_num(np.abs(speed))
        return np.hypot(np.asarray(prior_sigma, dtype=float), moving)

    def to_dict(self) -> dict:
        out = asdict(self)
        out["k_at_25_dbhz"] = float(self.speed_coefficient(np.array([25.0]))[0])
        out["k_at_40_dbhz"] = float(self.speed_coefficient(np.array([40.0]))[0])
        return out


def fit_row_noise(
    residual: np.ndarray, prior_sigma: np.ndarray, cn0: np.ndarray, speed: np.ndarray
) -> RowNoiseModel:
    """The model of the module docstring from normalised residuals (m/s, NaN where unknown),
    the rows' a-priori σ, C/N0 (dB-Hz) and speed (m/s); k = 0 (the a-priori σ alone) where no
    C/N0 bin has ``MIN_BIN_ROWS`` moving rows."""
    residual, prior_sigma, cn0, speed = (
        np.asarray(v, dtype=float) for v in (residual, prior_sigma, cn0, speed)
    )
    usable = np.isfinite(residual) & np.isfinite(cn0) & np.isfinite(speed) & (speed > MOVING_MPS)
    usable &= np.isfinite(prior_sigma)
    bins = np.floor(cn0 / CN0_BIN_DBHZ)
    centres, logs, counts = [], [], []
    for b in np.unique(bins[usable]):
        members = usable & (bins == b)
        if members.sum() < MIN_BIN_ROWS:
            continue
        r = residual[members]
        spread = MAD_TO_SIGMA * np.median(np.abs(r - np.median(r)))
        excess = spread**2 - np.median(prior_sigma[members] ** 2)
        if excess <= 0:
            continue
        k = np.sqrt(excess / np.median(speed[members] ** 2))
        centres.append(np.median(cn0[members]))
        logs.append(np.log10(k))
        counts.append(int(members.sum()))
    if not counts:
        return RowNoiseModel()
    centres, logs, weight = np.array(centres), np.array(logs), np.array(counts, dtype=float)
    x = (centres - CN0_REFERENCE_DBHZ) / 10.0
    slope = DEFAULT_SLOPE
    if len(counts) >= 2 and np.ptp(x) > 0:
        design = np.column_stack([np.ones_like(x), x]) * np.sqrt(weight)[:, None]
        fitted = np.linalg.lstsq(design, logs * np.sqrt(weight), rcond=None)[0][1]
        slope = float(np.clip(fitted, *SLOPE_RANGE))
    intercept = float(np.sum(weight * (logs - slope * x)) / np.sum(weight))
    return RowNoiseModel(10.0**intercept, slope, int(sum(counts)), len(counts))
