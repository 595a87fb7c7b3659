"""Satellite states from precise orbits and clocks (SP3, RINEX clock) at any time.

Position: Lagrange interpolation of ``n_points`` consecutive tabulated epochs centred on the
query (degree n_points − 1; the default 10 points, degree 9, is the usual choice for 15-min
SP3 epochs, Schenewerk 2003, "A brief review of basic GPS orbit interpolation strategies",
GPS Solutions 6: mm-level). The nodes are first turned into a quasi-inertial frame by the
Earth rotation angle, r_i(t_k) = R_z(ω_e (t_k − t_0)) r_e(t_k), where the orbit is smoother,
and the result is turned back: r_e = R_z(−ω_e (t − t_0)) r_i, velocity
v_e = R_z(−ω_e (t − t_0)) ṙ_i − ω_e ẑ × r_e from the derivative of the same polynomial.
Each satellite uses its own tabulated epochs (a missing position is skipped, the window
shifts); no extrapolation: a query outside them, or next to a gap wider than two intervals,
is invalid.

Clock: linear interpolation between the two tabulated epochs around the query (clocks are not
smooth enough for high-order polynomials, IGS convention), the clock drift its slope; from the
RINEX clock file when one is attached, else from the SP3 clock column. The periodic
relativistic term, which the products leave out, is added as for the broadcast clocks
(IS-GPS-200 sec. 20.3.3.3.3.1 in its vector form): Δt_r = −2 r·v / c², and its rate
−2 (|v_i|² + r_i·a_i) / c² from the polynomial's first and second derivatives (r·v is the same
in both frames).
"""

from __future__ import annotations

import numpy as np

from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.ephemeris import OMEGA_E, SatelliteStates, rotate_earth
from vo_doppler.model.precise_orbits import PreciseOrbits

LAGRANGE_POINTS = 10
MAX_GAP = 2.0
"""Largest span between the tabulated epochs around a query, in intervals (one missing)."""


def precise_states(
    orbits: PreciseOrbits, system, prn, t, n_points: int = LAGRANGE_POINTS
) -> SatelliteStates:
    """States at GPS times ``t`` for satellites (system letter, PRN), arrays broadcast.
    ``record`` holds the satellite's column in ``orbits.sat_id`` (−1 where invalid)."""
    system, prn, t = np.broadcast_arrays(
        np.asarray(system, dtype="U1"), np.asarray(prn), np.asarray(t, dtype=float)
    )
    system, prn, t = system.ravel(), prn.ravel(), t.ravel()
    out = SatelliteStates.empty(t.size)
    column = _columns(orbits.sat_id, system, prn)
    position, velocity, acceleration = _interpolate_positions(orbits, column, t, n_points)
    if orbits.clocks is None:
        bias, drift = _interpolate_clock(orbits.t, orbits.sat_id, orbits.clock_s, system, prn, t)
    else:
        clocks = orbits.clocks
        bias, drift = _interpolate_clock(clocks.t, clocks.sat_id, clocks.bias_s, system, prn, t)
    ok = np.isfinite(position[:, 0]) & np.isfinite(bias)
    inertial_rv = np.einsum("ni,ni->n", position, velocity)  # r·v, frame-independent
    inertial_dot = np.einsum("ni,ni->n", velocity, velocity) + np.einsum(
        "ni,ni->n", position, acceleration
    )
    since = t - orbits.t[0] if orbits.t.size else t
    position_e = rotate_earth(position, since)
    velocity_e = rotate_earth(velocity, since) - OMEGA_E["G"] * np.stack(
        [-position_e[:, 1], position_e[:, 0], np.zeros(t.size)], axis=1
    )
    out.position[ok] = position_e[ok]
    out.velocity[ok] = velocity_e[ok]
    out.clock_bias_s[ok] = bias[ok] - 2.0 * inertial_rv[ok] / SPEED_OF_LIGHT**2
    out.clock_drift[ok] = drift[ok] - 2.0 * inertial_dot[ok] / SPEED_OF_LIGHT**2
    out.valid[ok] = True
    out.record[ok] = column[ok]
    return out


def _columns(sat_ids: np.ndarray, system: np.ndarray, prn: np.ndarray) -> np.ndarray:
    """Column of each queried satellite in ``sat_ids``, −1 when absent."""
    index = {str(s): i for i, s in enumerate(sat_ids)}
    wanted = (f"{s}{int(p):02d}" for s, p in zip(system, prn, strict=True))
    return np.fromiter((index.get(w, -1) for w in wanted), dtype=np.int64, count=system.size)


def _interpolate_positions(orbits: PreciseOrbits, column, t, n_points):
    """Quasi-inertial position, velocity and acceleration (NaN where invalid), each satellite
    over the window of its own tabulated (non-missing) epochs."""
    # scipy.interpolate brings scipy.optimize (about 24 MiB resident): loaded by the GNSS stage
    # that needs it, not by every process that imports the GNSS package (run's parent among
    # them; tests/architecture/test_lazy_imports.py).
    from scipy.interpolate import KroghInterpolator

    out = np.full((3, t.size, 3), np.nan)
    if orbits.t.size < 2:
        return out
    interval = orbits.interval_s
    inertial = rotate_earth(orbits.position, -(orbits.t - orbits.t[0])[:, None])
    for sat in np.unique(column[column >= 0]):
        nodes = np.flatnonzero(np.isfinite(inertial[:, sat, 0]))
        if nodes.size < 2:
            continue
        times = orbits.t[nodes]
        rows = np.flatnonzero(column == sat)
        after = np.searchsorted(times, t[rows], side="right")
        bracket = np.clip(after, 1, times.size - 1)
        gap = times[bracket] - times[bracket - 1]
        ok = (t[rows] >= times[0]) & (t[rows] <= times[-1]) & (gap <= MAX_GAP * interval)
        n = min(n_points, nodes.size)
        start = np.clip(after - n // 2, 0, nodes.size - n)
        for first in np.unique(start[ok]):
            hits = rows[ok & (start == first)]
            centre = times[first + n // 2]
            x = (times[first : first + n] - centre) / interval
            polynomial = KroghInterpolator(x, inertial[nodes[first : first + n], sat])
            derivatives = polynomial.derivatives((t[hits] - centre) / interval, 3)
            for k in range(3):
                out[k, hits] = derivatives[k] / interval**k
    return out


def _interpolate_clock(times, sat_ids, table, system, prn, t):
    """Clock offset (s) and drift (s/s) by linear interpolation; NaN where not bracketed."""
    bias = np.full(t.size, np.nan)
    drift = np.full(t.size, np.nan)
    if times.size < 2:
        return bias, drift
    column = _columns(sat_ids, system, prn)
    left = np.clip(np.searchsorted(times, t, side="right") - 1, 0, times.size - 2)
    inside = (column >= 0) & (t >= times[0]) & (t <= times[-1])
    rows = np.flatnonzero(inside)
    a = table[left[rows], column[rows]]
    b = table[left[rows] + 1, column[rows]]
    span = times[left[rows] + 1] - times[left[rows]]
    slope = (b - a) / span
    bias[rows] = a + slope * (t[rows] - times[left[rows]])
    drift[rows] = slope
    return bias, drift
