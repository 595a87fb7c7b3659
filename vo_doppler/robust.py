"""Robust statistics, in one place: the scale of residuals that contain faults, and the
weights of iteratively reweighted least squares (IRLS) that every robust fit of the project uses.

**Scale.** The median absolute deviation and its normalised form

    MAD(x) = median |x_i − median x|,     NMAD(x) = 1.4826 · MAD(x)                  (R1)

1.4826 = 1/Φ⁻¹(3/4) makes NMAD a consistent estimate of σ for Gaussian samples; it has a
breakdown point of 50 %: up to half of the values can be faults (reflections, blunders) without
moving it without bound (Hampel, Ronchetti, Rousseeuw & Stahel, "Robust Statistics: The
Approach Based on Influence Functions", Wiley 1986, sec. 2.3). Without centring, median |x_i|
is the scale of values whose centre is known to be zero (residuals already normalised).

**Weights.** An M-estimate minimises Σ ρ(r_i/s) over the parameters; with ψ = ρ′ and
w(u) = ψ(u)/u it is the fixed point of weighted least squares with weights w(r_i/s), which IRLS
reaches by refitting with the weights of the previous fit's residuals (Huber, "Robust
Statistics", Wiley 1981, sec. 7.8; Holland & Welsch, "Robust regression using iteratively
reweighted least-squares", Commun. Statist. A6, 1977):

    Huber:      w(u) = min(1, k/|u|)                                                    (R2)
    Cauchy:     w(u) = 1/(1 + (u/c)²)                                                   (R3)
    Student-t:  w(u) = (ν + 1)/(ν + u²)                                                 (R4)

Huber's ψ, the influence of a residual, is the residual clipped at k scales,

    ψ(u) = clip(u, −k, k) = u·w(u)                                                      (R2′)

and a Kalman filter gives an innovation ν of variance S and normalised size u (e.g. ν/√S) its
weight (R2) through that variance: the gain P⁻·w(u)/S is P⁻ over the inflated variance

    S/w(u) = S·max(1, |u|/k)                                                            (R2″)

so that with u = ν/√S a gross innovation moves the state by at most k·P⁻/√S.

Huber's weight levels off (a gross fault keeps the influence k·s); the Cauchy and Student-t
weights redescend, so a fault far from the fit gets almost no weight, at the price of a cost
that is not convex (start them from a Huber fit). k = 1.345 and c = 2.385 give 95 % of least
squares' efficiency for Gaussian errors (Holland & Welsch 1977). Every weight here multiplies an
a-priori weight (1/σ² of each observation) given as ``prior``.

**Covariance of a Huber estimate** (Huber 1981, sec. 7.6): with u_i = r_i/s, ψ of (R2′),
m the fraction of |u_i| ≤ k and p parameters,

    cov β = K²·s²·Σψ(u_i)²/(n − p)/m² · (XᵀX)⁻¹,   K = 1 + p(1 − m)/(n·m)              (R5)

which with k = ∞ is the least-squares covariance.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import TypeVar

import numpy as np

MAD_TO_SIGMA = 1.4826
"""1/Φ⁻¹(3/4): NMAD = MAD_TO_SIGMA · MAD is σ for Gaussian samples (R1)."""

Weights = TypeVar("Weights")


def median_of_finite(values: np.ndarray) -> float:
    """``np.median`` of a 1-D array of finite values, to the bit: the middle order statistic,
    or half the sum of the two middle ones (as ``np.median`` takes their mean), found by one
    partition without ``np.median``'s generic axis and NaN handling (the IRLS of a robust line
    takes two medians per iteration and epoch)."""
    half = values.size // 2
    if values.size % 2:
        return float(np.partition(values, half)[half])
    middle = np.partition(values, (half - 1, half))
    return float((middle[half - 1] + middle[half]) / 2.0)


def _median(values: np.ndarray, axis: int | None, skip_nan: bool, keepdims: bool = False):
    """The median over ``axis`` (all values when None), NaN skipped with ``skip_nan`` (a slice
    of NaN only gives NaN, silently); finite values over all axes by :func:`median_of_finite`."""
    if skip_nan:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            return np.nanmedian(values, axis=axis, keepdims=keepdims)
    if axis is None and values.size and np.isfinite(values).all():
        return median_of_finite(values.ravel())
    return np.median(values, axis=axis, keepdims=keepdims)


def mad(values, axis: int | None = None, centre: bool = True, skip_nan: bool = False):
    """Median absolute deviation (R1) of ``values`` over ``axis`` (all values when None):
    median |x − median x|, or median |x| without ``centre``; NaN ignored with ``skip_nan``.
    A float when ``axis`` is None, else an array over the other axes."""
    values = np.asarray(values, dtype=float)
    if centre:
        values = values - _median(values, axis, skip_nan, keepdims=axis is not None)
    spread = _median(np.abs(values), axis, skip_nan)
    return float(spread) if axis is None else spread


def nmad(values, axis: int | None = None, centre: bool = True, skip_nan: bool = False):
    """Normalised median absolute deviation (R1), MAD_TO_SIGMA · :func:`mad` (same
    arguments): the standard deviation of Gaussian values, unmoved by up to half of them being
    faults."""
    return MAD_TO_SIGMA * mad(values, axis, centre, skip_nan)


def huber_weight(residual, k: float, scale=1.0, floor: float = 0.0, prior=1.0) -> np.ndarray:
    """Huber's weight (R2) times ``prior``: prior·min(1, k·s/max(|r|, floor)) for residuals
    ``residual`` of scale s (``scale``; residuals already in units of their scale by default);
    ``floor`` keeps a zero residual from dividing by zero (with 0, it gets weight 1 and numpy's
    divide warning)."""
    return prior * np.minimum(1.0, k * scale / np.maximum(np.abs(residual), floor))


def huber_psi(u, k: float) -> np.ndarray:
    """Huber's ψ (R2′) of residuals ``u`` in units of their scale: u clipped to [−k, k], which
    is u times the weight :func:`huber_weight` (k = ∞: u itself)."""
    return np.clip(u, -k, k)


def huber_inflated_variance(variance, u, k: float) -> np.ndarray:
    """The variance (R2″) that gives an observation of ``variance`` and normalised residual
    ``u`` its Huber weight (R2) in a least-squares or Kalman update: variance·|u|/k where
    |u| > k, else ``variance`` (k = ∞: ``variance``); NaN residuals keep ``variance``."""
    size = np.abs(u)
    return np.where(size > k, variance * size / k, variance)


def cauchy_weight(u, c: float, prior=1.0) -> np.ndarray:
    """The Cauchy weight (R3) of residuals ``u`` in units of their scale, times ``prior``."""
    return prior / (1.0 + (u / c) ** 2)


def student_weight(u, dof: float, prior=1.0) -> np.ndarray:
    """The Student-t weight (R4) with ``dof`` degrees of freedom of residuals ``u`` in units of
    their scale, times ``prior`` (Lange, Little & Taylor, "Robust statistical modeling using
    the t distribution", JASA 84, 1989)."""
    return prior * (dof + 1.0) / (dof + u**2)


def huber_variance(residual: np.ndarray, scale: float, k: float, params: int) -> float:
    """K²·s²·Σψ(u_i)²/(n − p)/m² of (R5): the factor of (XᵀX)⁻¹ in the covariance of a Huber
    estimate with ``params`` parameters from its ``residual`` (n of them) and their ``scale``;
    NaN when no residual lies within k scales."""
    u = residual / scale
    n = residual.size
    inside = float(np.mean(np.abs(u) <= k))
    if inside == 0:
        return float("nan")
    factor = 1.0 + params * (1.0 - inside) / (n * inside)
    psi = huber_psi(u, k)
    return factor**2 * scale**2 * float(psi @ psi) / (n - params) / inside**2


def irls(
    fit: Callable[[Weights], np.ndarray | None],
    weigh: Callable[[np.ndarray, int], Weights | None],
    weights: Weights,
    passes: int,
    tolerance: float | None = None,
) -> Weights:
    """Iteratively reweighted least squares (Huber 1981, sec. 7.8): ``passes`` times, fit with
    the current weights (``fit(weights)`` returns the fit's residuals) and take the next
    weights from them (``weigh(residuals, pass)``, the pass counted from 0: a caller can switch
    from Huber to redescending weights). Either may return None to stop with the weights as
    they are (nothing to fit, or no scale). With ``tolerance`` the passes also stop once no
    weight moved by more than it. Returns the last weights: the caller's final fit uses them.

    ``weights`` may be any state the two functions share (e.g. weights with the residuals'
    scale); ``tolerance`` then needs it to be an array."""
    for n in range(passes):
        residual = fit(weights)
        updated = None if residual is None else weigh(residual, n)
        if updated is None:
            break
        settled = tolerance is not None and bool(np.all(np.abs(updated - weights) <= tolerance))
        weights = updated
        if settled:
            break
    return weights
