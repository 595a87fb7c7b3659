"""A Doppler noise model estimated from the data: σ of the range rate as a function of C/N0
and elevation, one per receiver signal (system and Doppler code), fitted to the residuals of
the conventional solutions.

Model (the thermal-noise law of a frequency-lock loop, σ ∝ (C/N0)^(−1/2) in linear units,
i.e. 10^(−C/N0/20) in dB-Hz, Kaplan & Hegarty, "Understanding GPS/GNSS", 3rd ed., sec. 8.7,
with its slope left free because multipath makes the weak signals noisier still, and the
usual 1/sin(elevation) multipath factor with a free exponent):

    log₁₀ σ = a − b · (C/N0 − C/N0_ref) / 20 + c · log₁₀(1 / sin el)

Fit (robust residual statistics): every row's residual about its epoch's solution is divided
by √r_i, r_i its redundancy number (``doppler_noise.redundancy_numbers``), so that its
variance is σ_i². The rows are binned by C/N0 (``CN0_BIN_DBHZ``) and elevation
(``ELEVATION_BIN_RAD``); each bin with at least ``MIN_BIN_ROWS`` rows gives a robust σ, the
normalised median absolute deviation 1.4826 · median |r| (unmoved by up to half of the rows
being reflections), and (a, b, c) are the weighted least-squares fit of log₁₀ of those σ,
each bin weighted by its row count (the variance of log MAD falls as 1/n). Without two
distinct C/N0 bins the slope cannot be fitted and the signal keeps the a-priori model; without
two elevation bins c is 0. The model is used inside the C/N0 and elevation range it was
fitted on (queries are clamped to it) and never below ``FLOOR_MPS``.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from vo_doppler.gnss.doppler_noise import redundancy_numbers
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.gnss_solutions import VelocitySolution
from vo_doppler.robust import nmad

CN0_REFERENCE_DBHZ = 45.0
CN0_BIN_DBHZ = 2.0
ELEVATION_BIN_RAD = np.deg2rad(10.0)
MIN_BIN_ROWS = 30
FLOOR_MPS = 0.01
MIN_ELEVATION_RAD = np.deg2rad(5.0)
SLOPE_BOUNDS = (-2.0, 5.0)
"""The C/N0 slope b and elevation exponent c a receiver's noise can have (thermal noise: b = 1;
measured 0.2–1.5 and 0.2–1.9): a fit beyond them (bins of nearly exact rows, e.g. a
simulator's noise-free pseudoranges, gave b ≈ 3,900) describes no noise and is not used."""
MAX_LOG_SIGMA_REF = 6.0


@dataclass(frozen=True)
class NoiseModel:
    """σ(C/N0, elevation) of one receiver signal (module docstring): ``sigma_ref_mps`` = 10^a
    (σ at ``CN0_REFERENCE_DBHZ`` and zenith), ``cn0_slope`` = b (1 for the thermal law),
    ``elevation_exponent`` = c, the C/N0 (dB-Hz) and elevation (rad) ranges of the data, and
    how many rows and bins it was fitted on."""

    system: str
    code: str
    sigma_ref_mps: float
    cn0_slope: float
    elevation_exponent: float
    cn0_range_dbhz: tuple[float, float]
    elevation_range_rad: tuple[float, float]
    n_rows: int
    n_bins: int

    def sigma(self, cn0: np.ndarray, elevation: np.ndarray) -> np.ndarray:
        """σ (m/s) of rows of this signal; a missing C/N0 reads as the reference."""
        law = (self.sigma_ref_mps, self.cn0_slope, self.elevation_exponent)
        ranges = (self.cn0_range_dbhz, self.elevation_range_rad)
        return sigma_law(law, ranges, cn0, elevation, FLOOR_MPS)

    def to_dict(self) -> dict:
        """JSON-ready fields, the elevation range in degrees (for the run summary)."""
        out = asdict(self)
        out["elevation_range_deg"] = [float(np.degrees(v)) for v in out.pop("elevation_range_rad")]
        out["cn0_range_dbhz"] = [float(v) for v in out["cn0_range_dbhz"]]
        return out


def sigma_law(
    law: tuple[float, float, float],
    ranges: tuple[tuple[float, float], tuple[float, float]],
    cn0: np.ndarray,
    elevation: np.ndarray,
    floor: float,
) -> np.ndarray:
    """σ of the module docstring's law, ``law`` = (10^a, b, c), at C/N0 ``cn0`` (dB-Hz; missing:
    the reference) and ``elevation`` (rad), each clamped to its fitted range of ``ranges``
    (C/N0, elevation), never below ``floor`` (any unit: that of 10^a)."""
    sigma_ref, slope, exponent = law
    cn0 = np.where(np.isfinite(cn0), cn0, CN0_REFERENCE_DBHZ)
    cn0 = np.clip(cn0, *ranges[0])
    elevation = np.clip(elevation, *ranges[1])
    log_sigma = (
        np.log10(sigma_ref)
        - slope * (cn0 - CN0_REFERENCE_DBHZ) / 20.0
        - exponent * np.log10(np.sin(elevation))
    )
    return np.maximum(10.0**log_sigma, floor)


def normalised_residuals(rows: DopplerRows, solution: VelocitySolution) -> np.ndarray:
    """r_i / √r_i per row about its epoch's solution (NaN where the epoch is unsolved or has
    no redundancy)."""
    state = np.column_stack([solution.velocity_ecef, solution.clock_drift_mps])[rows.epoch]
    predicted = -np.einsum("ij,ij->i", rows.los, state[:, :3]) + state[:, 3]
    return (rows.reduced() - predicted) / np.sqrt(redundancy_numbers(rows, rows.sigma()))


def fit_noise_models(
    rows: DopplerRows, solution: VelocitySolution, min_bin_rows: int = MIN_BIN_ROWS
) -> dict[tuple[str, str], NoiseModel]:
    """One model per (system, Doppler code) with enough data (module docstring)."""
    residual = normalised_residuals(rows, solution)
    usable = np.isfinite(residual) & np.isfinite(rows.cn0) & np.isfinite(rows.elevation)
    models = {}
    signals = {(str(s), str(c)) for s, c in zip(rows.system, rows.code, strict=True)}
    for system, code in sorted(signals):
        members = usable & (rows.system == system) & (rows.code == code)
        model = fit_sigma_law(
            residual[members], rows.cn0[members], rows.elevation[members], min_bin_rows
        )
        if model is not None:
            sigma_ref, slope, exponent, cn0_range, elevation_range, n_bins = model
            models[(system, code)] = NoiseModel(
                system,
                code,
                sigma_ref,
                slope,
                exponent,
                cn0_range,
                elevation_range,
                int(members.sum()),
                n_bins,
            )
    return models


def modelled_sigma(
    models: dict[tuple[str, str], NoiseModel], rows: DopplerRows, fallback: np.ndarray
) -> np.ndarray:
    """σ (m/s) of each row from its signal's model; ``fallback`` for signals without one."""
    sigma = np.asarray(fallback, dtype=float).copy()
    for (system, code), model in models.items():
        members = (rows.system == system) & (rows.code == code)
        sigma[members] = model.sigma(rows.cn0[members], rows.elevation[members])
    return sigma


def fit_sigma_law(
    residual: np.ndarray, cn0: np.ndarray, elevation: np.ndarray, min_bin_rows: int = MIN_BIN_ROWS
) -> tuple | None:
    """(σ_ref, b, c, C/N0 range, elevation range, bins) of the module docstring's law fitted
    to normalised residuals (any unit; σ_ref in it) of one signal at C/N0 ``cn0`` (dB-Hz) and
    ``elevation`` (rad), all finite; None without two C/N0 bins of ``min_bin_rows`` rows whose
    residuals spread (a bin of exact rows, e.g. a simulator's noise-free pseudoranges, has no
    scale to fit: its logarithm would be −∞ and the law's σ 0 or ∞); None also for a law
    beyond ``SLOPE_BOUNDS`` or whose σ_ref is beyond 10^±``MAX_LOG_SIGMA_REF``."""
    cn0_bin = np.floor(cn0 / CN0_BIN_DBHZ)
    elevation_bin = np.floor(elevation / ELEVATION_BIN_RAD)
    keys, inverse = np.unique(
        np.column_stack([cn0_bin, elevation_bin]), axis=0, return_inverse=True
    )
    inverse = inverse.reshape(-1)
    count = np.bincount(inverse, minlength=len(keys))
    bins = np.flatnonzero(count >= min_bin_rows)
    spread = np.array([nmad(residual[inverse == k], centre=False) for k in bins])
    bins, spread = bins[spread > 0.0], spread[spread > 0.0]  # exact rows: no noise to fit
    if np.unique(keys[bins, 0]).size < 2:
        return None
    log_sigma = np.log10(spread)
    centre_cn0 = np.array([np.mean(cn0[inverse == k]) for k in bins])
    centre_el = np.array([np.mean(elevation[inverse == k]) for k in bins])
    columns = [np.ones(bins.size), -(centre_cn0 - CN0_REFERENCE_DBHZ) / 20.0]
    if np.unique(keys[bins, 1]).size >= 2:
        columns.append(-np.log10(np.sin(np.maximum(centre_el, MIN_ELEVATION_RAD))))
    design = np.column_stack(columns)
    weight = np.sqrt(count[bins])
    solution = np.linalg.lstsq(design * weight[:, None], log_sigma * weight, rcond=None)[0]
    a, b = solution[0], solution[1]
    c = solution[2] if solution.size > 2 else 0.0
    if not (
        abs(a) < MAX_LOG_SIGMA_REF
        and SLOPE_BOUNDS[0] <= b <= SLOPE_BOUNDS[1]
        and SLOPE_BOUNDS[0] <= c <= SLOPE_BOUNDS[1]
    ):
        return None
    inside = np.isin(inverse, bins)
    return (
        float(10.0**a),
        float(b),
        float(c),
        (float(cn0[inside].min()), float(cn0[inside].max())),
        (float(max(elevation[inside].min(), MIN_ELEVATION_RAD)), float(elevation[inside].max())),
        int(bins.size),
    )
