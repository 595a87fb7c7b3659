"""Doppler noise estimated from the data, per satellite: the σ of each range rate from the
residuals of the conventional solutions, per satellite and signal, refreshed as the data arrive.

For each (satellite, Doppler code) the residuals r = y − H x̂ of the solved epochs over the
last ``window_s`` seconds (causal: only rows up to the current one), each divided by the row's
``reference`` σ (1 m/s, or the C/N0 model's σ of ``noise_model``), give a robust scale
k = 1.4826 · median |z − median z| (the normalised median absolute deviation (R1) of
:mod:`vo_doppler.robust`, consistent with a Gaussian σ and unmoved by up to half of the rows
being faults, e.g. reflections); the row's σ is k times its reference, so that a satellite's
multipath scales the C/N0 law instead of replacing it. Until a satellite has ``min_rows``
residuals its σ stays the prior one. Each residual is first divided by √r_i, r_i = 1 − h_ii its
redundancy number (h_ii the diagonal of the weighted hat matrix H (HᵀWH)⁻¹ HᵀW of its epoch): a
least-squares residual has variance r_i σ_i², so the raw residuals would understate σ. A floor
keeps one quiet satellite from dominating. The residuals include the fault rows the exclusion
removed, so a satellite that keeps faulting gets a large σ.
"""

from __future__ import annotations

import numpy as np

from vo_doppler.robust import nmad

WINDOW_S = 60.0
MIN_ROWS = 20
FLOOR_MPS = 0.02
MIN_REDUNDANCY = 1e-6
"""A row whose redundancy number r_i is smaller has no residual to fit a noise on: in an epoch
with as many satellites as unknowns r_i is zero up to rounding (~1e-15) and so is the residual
(~1e-8 m for a pseudorange), which divided by √r_i reads as noise of any size: the SPP's
fitted σ on the sample moved by 46 % when every time was shifted by 10⁹ s (issue 30)."""


def fitted_sigma(
    rows,
    solution,
    prior_sigma: np.ndarray,
    reference_sigma: np.ndarray | float = 1.0,
    window_s: float = WINDOW_S,
    min_rows: int = MIN_ROWS,
    floor_mps: float = FLOOR_MPS,
) -> np.ndarray:
    """σ (m/s) per Doppler row from the residuals of ``solution`` (rows of unsolved epochs and
    satellites with too few residuals keep ``prior_sigma``)."""
    state = np.column_stack([solution.velocity_ecef, solution.clock_drift_mps])[rows.epoch]
    predicted = -np.einsum("ij,ij->i", rows.los, state[:, :3]) + state[:, 3]
    redundancy = redundancy_numbers(rows, rows.sigma())
    reference = np.broadcast_to(np.asarray(reference_sigma, dtype=float), (len(rows),))
    residual = (rows.reduced() - predicted) / np.sqrt(redundancy) / reference
    sigma = np.asarray(prior_sigma, dtype=float).copy()
    signal = np.char.add(np.char.add(rows.system, rows.prn.astype(str)), rows.code)
    for name in np.unique(signal):
        members = np.flatnonzero((signal == name) & np.isfinite(residual))
        members = members[np.argsort(rows.t[members], kind="stable")]
        t = rows.t[members]
        start = np.searchsorted(t, t - window_s, side="left")
        for k, row in enumerate(members):
            if k + 1 - start[k] < min_rows:
                continue
            recent = residual[members[start[k] : k + 1]]
            spread = nmad(recent)
            sigma[row] = max(spread * reference[row], floor_mps)
    return sigma


def redundancy_numbers(rows, sigma: np.ndarray) -> np.ndarray:
    """r_i = 1 − h_ii per row with all of its epoch's rows in the design (NaN without
    redundancy, or below ``MIN_REDUNDANCY``)."""
    out = np.full(len(rows), np.nan)
    order = np.argsort(rows.epoch, kind="stable")
    bounds = np.flatnonzero(np.diff(rows.epoch[order])) + 1
    for members in np.split(order, bounds):
        H = np.hstack([-rows.los[members], np.ones((members.size, 1))])
        if members.size <= H.shape[1]:
            continue
        weight = sigma[members] ** -2.0
        normal = (H * weight[:, None]).T @ H
        hat = np.einsum("ij,jk,ik->i", H, np.linalg.pinv(normal), H) * weight
        redundancy = 1.0 - hat
        out[members] = np.where(redundancy >= MIN_REDUNDANCY, np.minimum(redundancy, 1.0), np.nan)
    return out
