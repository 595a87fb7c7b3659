"""Doppler noise of a receiver at rest and in motion, measured from the data: the a-priori σ
of each row (C/N0 and elevation, or the receiver's own σ) scaled to what a receiver at rest
shows, plus a share that grows with the speed, strongest on weak signals.

Why: a reflected or diffracted signal arrives from another direction than the line of sight,
so its Doppler differs from the direct one by v·(e_direct − e_reflected), proportional to the
speed v; the weaker the received signal, the larger the share of such paths in it. On the Hong
Kong canyon drive (u-blox M8T, 1 Hz; residuals against the reference velocity, per-epoch clock
removed) rows of 25–30 dB-Hz have a normalised MAD of 0.08 m/s at standstill and 1.5 m/s above
3 m/s, rows of 35–40 dB-Hz 0.04 and 0.14 m/s: a C/N0 law alone cannot describe both; at rest
the a-priori model is four times too large (residuals over the model's σ: MAD 0.28 at rest on
that drive and on the u-blox F9P standing in the same street), which hides the faulty rows from
the chi-square test. The model per row i is

    σ_i² = (f · σ_prior,i)² + (k(C/N0_i) · s_i)²,    log₁₀ k(C) = κ₀ + κ₁ · (C − C_ref) / 10 dB,

with s_i the horizontal speed of the row's epoch (a first solution's). f and (κ₀, κ₁) are fitted
to the residuals of the conventional solutions, each divided by √r_i (r_i its redundancy
number, so that its variance is σ_i²; ``noise_model.normalised_residuals``): f is the
normalised MAD of r_i / σ_prior,i over the rows of epochs at rest; the rows of moving epochs
(any motion: a walker's gait noise enters k as a car's multipath does; fitted on the car's
speeds alone, the Yamatogawa walker kept f·σ_prior and got rows four times too confident)
are binned by C/N0, each bin's excess k_b² = (MAD_b² − median (f·σ_prior)²) / median s²
(robust: half of a bin may be reflections), and log₁₀ k_b is fitted as a line in C/N0, each bin
weighted by its row count. The tail beyond that σ is heavy (a reflection is a bias, not noise):
the chi-square exclusion and the tight heading's robust fit take it.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace

import numpy as np

from vo_doppler.gnss.noise_model import normalised_residuals
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.gnss_solutions import VelocitySolution
from vo_doppler.robust import nmad

CN0_REFERENCE_DBHZ = 35.0
CN0_BIN_DBHZ = 5.0
AT_REST_MPS = 0.5
MIN_BIN_ROWS = 20
MIN_REST_ROWS = 50
MIN_MOVING_ROWS = 100
"""Fewer moving rows fit no speed share: the moving rows then keep their a-priori σ (22 rows
of a walker's first steps gave k 0.64 at 35 dB-Hz, three times a car's in a street canyon)."""
DEFAULT_SLOPE = -1.0
"""κ₁ where only one C/N0 bin has data: k falls tenfold per 10 dB, the slope fitted on the Hong Kong
drive (docs/benchmarks.md, "The GNSS velocity's settings")."""
SLOPE_RANGE = (-2.0, 0.0)
FACTOR_RANGE = (0.1, 10.0)
MAX_K = 1.0
"""k is at most 1 (a reflected path's Doppler error is at most about twice the speed along
the line of sight, and a σ of one speed already weighs a row out)."""


@dataclass(frozen=True)
class MovingNoiseModel:
    """σ_i² = (f·σ_prior,i)² + (k(C/N0_i)·s_i)² (module docstring): ``rest_factor`` = f,
    ``k_ref`` = 10^κ₀ (m/s of σ per m/s of speed at ``CN0_REFERENCE_DBHZ``), ``k_slope`` = κ₁
    per 10 dB, and how many rows at rest, moving rows and C/N0 bins they were fitted on (none:
    f = 1, k = 0, the a-priori σ)."""

    rest_factor: float = 1.0
    k_ref: float = 0.0
    k_slope: float = DEFAULT_SLOPE
    n_rest_rows: int = 0
    n_moving_rows: int = 0
    n_bins: int = 0

    @property
    def identity(self) -> bool:
        """The a-priori σ unchanged (nothing fitted, or fitted to no change)."""
        return self.rest_factor == 1.0 and self.k_ref == 0.0

    def speed_coefficient(self, cn0: np.ndarray) -> np.ndarray:
        """k (m/s of σ per m/s of speed) of rows of C/N0 ``cn0`` (dB-Hz; missing: reference)."""
        cn0 = np.nan_to_num(np.asarray(cn0, dtype=float), nan=CN0_REFERENCE_DBHZ)
        k = self.k_ref * 10.0 ** (self.k_slope * (cn0 - CN0_REFERENCE_DBHZ) / 10.0)
        return np.minimum(k, MAX_K)

    def sigma(self, prior_sigma: np.ndarray, cn0: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """σ (m/s) of rows with a-priori σ ``prior_sigma`` at ``speed`` (m/s; NaN: none). Where
        no moving row was fitted (``n_moving_rows`` 0), the rest factor stays with the rows at
        rest and moving rows keep their a-priori σ: nothing measured them."""
        speed = np.nan_to_num(np.abs(np.asarray(speed, dtype=float)))
        factor = np.full(speed.shape, self.rest_factor)
        if self.n_moving_rows == 0:
            factor = np.where(speed < AT_REST_MPS, self.rest_factor, 1.0)
        moving = self.speed_coefficient(cn0) * speed
        return np.hypot(factor * np.asarray(prior_sigma, dtype=float), moving)

    def to_dict(self) -> dict:
        out = asdict(self)
        out["k_at_25_dbhz"] = float(self.speed_coefficient(np.array([25.0]))[0])
        out["k_at_40_dbhz"] = float(self.speed_coefficient(np.array([40.0]))[0])
        return out


def fit_moving_noise(
    residual: np.ndarray, prior_sigma: np.ndarray, cn0: np.ndarray, speed: np.ndarray
) -> MovingNoiseModel:
    """The model of the module docstring from normalised residuals (m/s, NaN where unknown),
    the rows' a-priori σ, C/N0 (dB-Hz) and their epochs' speed (m/s). f = 1 with fewer than
    ``MIN_REST_ROWS`` rows at rest; k = 0 (and no moving row counted) with fewer than
    ``MIN_MOVING_ROWS`` moving rows or where no C/N0 bin has ``MIN_BIN_ROWS`` of them."""
    residual, prior_sigma, cn0, speed = (
        np.asarray(v, dtype=float) for v in (residual, prior_sigma, cn0, speed)
    )
    known = np.isfinite(residual) & np.isfinite(speed) & np.isfinite(prior_sigma)
    rest = known & (speed < AT_REST_MPS)
    factor = 1.0
    if rest.sum() >= MIN_REST_ROWS:
        ratio = residual[rest] / prior_sigma[rest]
        factor = float(np.clip(nmad(ratio, centre=False), *FACTOR_RANGE))
    moving = known & np.isfinite(cn0) & (speed >= AT_REST_MPS)
    bins = np.floor(cn0 / CN0_BIN_DBHZ)
    centres, logs, counts = [], [], []
    for b in np.unique(bins[moving]):
        members = moving & (bins == b)
        if members.sum() < MIN_BIN_ROWS:
            continue
        r = residual[members]
        spread = nmad(r)
        excess = spread**2 - np.median((factor * prior_sigma[members]) ** 2)
        if excess <= 0:
            continue
        centres.append(np.median(cn0[members]))
        logs.append(0.5 * np.log10(excess / np.median(speed[members] ** 2)))
        counts.append(int(members.sum()))
    n_rest = int(rest.sum())
    if not counts or moving.sum() < MIN_MOVING_ROWS:
        return MovingNoiseModel(factor, n_rest_rows=n_rest)
    centres, logs, weight = np.array(centres), np.array(logs), np.array(counts, dtype=float)
    x = (centres - CN0_REFERENCE_DBHZ) / 10.0
    slope = DEFAULT_SLOPE
    if len(counts) >= 2 and np.ptp(x) > 0:
        design = np.column_stack([np.ones_like(x), x]) * np.sqrt(weight)[:, None]
        fitted = np.linalg.lstsq(design, logs * np.sqrt(weight), rcond=None)[0][1]
        slope = float(np.clip(fitted, *SLOPE_RANGE))
    intercept = float(np.sum(weight * (logs - slope * x)) / np.sum(weight))
    return MovingNoiseModel(factor, 10.0**intercept, slope, n_rest, int(sum(counts)), len(counts))


def moving_noise_weights(
    rows: DopplerRows, solution: VelocitySolution
) -> tuple[DopplerRows, MovingNoiseModel]:
    """The model fitted to ``solution``'s residuals and the rows re-weighted by it (the speed
    of each row: its epoch's horizontal speed in ``solution``)."""
    if not len(rows) or rows.epoch is None:
        return rows, MovingNoiseModel()
    cn0 = rows.cn0 if rows.cn0 is not None else np.full(len(rows), np.nan)
    solved = np.hypot(solution.velocity_enu[:, 0], solution.velocity_enu[:, 1])
    prior = rows.sigma()
    model = fit_moving_noise(normalised_residuals(rows, solution), prior, cn0, solved[rows.epoch])
    if model.identity:
        return rows, model
    speed = epoch_speed(solution.t, solved)[rows.epoch]
    sigma = np.where(np.isfinite(speed), model.sigma(prior, cn0, speed), prior)
    return replace(rows, weight=sigma**-2.0), model


def epoch_speed(t: np.ndarray, speed: np.ndarray) -> np.ndarray:
    """``speed`` with the unsolved epochs (NaN) interpolated in time from the solved ones (all
    NaN when none is solved): a row of an unsolved epoch is as noisy as its neighbours'."""
    known = np.isfinite(speed)
    if not known.any():
        return speed
    return np.interp(t, t[known], speed[known])
