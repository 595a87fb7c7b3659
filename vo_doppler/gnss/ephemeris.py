"""Satellite position, velocity and clock from broadcast ephemerides (vectorised).

- GPS / QZSS: IS-GPS-200 sec. 20.3.3.4.3 and Table 20-IV (user algorithm for ephemeris
  determination), clock sec. 20.3.3.3.3.1 incl. the relativistic term Δt_r = F·e·√A·sin E_k.
- Galileo: OS SIS ICD sec. 5.1.1 (same algorithm, own μ) and 5.1.4 (clock).
- BeiDou: BDS-SIS-ICD-B1I sec. 5.2.4.12; GEO satellites (C01–C05, C59–C63) computed in the
  inertial-like frame then rotated by R_X(−5°) and R_Z(Ω_e·t_k).
- GLONASS: ICD-GLONASS 5.1 (2008) App. A.3.1.2, PZ-90 equations of motion with J2 and the
  luni-solar accelerations held constant, integrated with fourth-order Runge–Kutta; clock
  t_sys = t_sv + τ_n − γ_n (t − t_b).
Velocities of Keplerian satellites are the analytic time derivatives of Table 20-IV.
Ephemeris selection: per satellite the healthy record with the nearest reference time within
the validity window (4 h Keplerian, 30 min GLONASS); other satellites report ``valid = False``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.model.navigation import Navigation, NavRecords

OMEGA_E = {"G": 7.2921151467e-5, "J": 7.2921151467e-5, "E": 7.2921151467e-5, "C": 7.292115e-5}
MU = {"G": 3.986005e14, "J": 3.986005e14, "E": 3.986004418e14, "C": 3.986004418e14}
OMEGA_E_GLONASS = 7.292115e-5
MU_GLONASS = 3.9860044e14
J2_GLONASS = 1.0826257e-3
AE_GLONASS = 6378136.0
KEPLER_MAX_AGE_S = 4 * 3600.0
GLONASS_MAX_AGE_S = 1800.0
GLONASS_STEP_S = 30.0
_BDS_GEO_TILT = np.deg2rad(-5.0)


@dataclass(frozen=True)
class SatelliteStates:
    """Satellite states at given GPS times, ECEF (WGS-84 / PZ-90, same epoch frame).

    ``clock_bias_s`` includes the relativistic correction (no group delay);
    ``clock_drift`` in s/s. Rows without a usable ephemeris have ``valid = False`` and NaN states.
    ``record`` is the index of the selected record in ``nav.kepler`` or ``nav.glonass``.
    """

    position: np.ndarray
    velocity: np.ndarray
    clock_bias_s: np.ndarray
    clock_drift: np.ndarray
    valid: np.ndarray
    record: np.ndarray

    @classmethod
    def empty(cls, n: int) -> SatelliteStates:
        return cls(
            np.full((n, 3), np.nan),
            np.full((n, 3), np.nan),
            np.full(n, np.nan),
            np.full(n, np.nan),
            np.zeros(n, dtype=bool),
            np.full(n, -1, dtype=np.int64),
        )


def select_records(
    records: NavRecords, system, prn, t, reference: np.ndarray, max_age: float
) -> np.ndarray:
    """Index of the healthy record nearest in reference time per query, −1 when none is valid."""
    system, prn, t = np.broadcast_arrays(np.asarray(system), np.asarray(prn), np.asarray(t, float))
    chosen = np.full(t.shape, -1, dtype=np.int64)
    health = records["health"].astype(np.int64)
    # QZSS: bit 0 flags the L6 signal only (IS-QZSS-PNT sec. 4.1.2.3), not the ranging signals
    health[records.system == "J"] &= 0b111110
    healthy = health == 0
    keys = np.char.add(records.system.astype("U1"), records.prn.astype(str))
    query_keys = np.char.add(system.astype("U1"), prn.astype(str)) if t.size else keys[:0]
    for key in np.intersect1d(np.unique(query_keys), keys[healthy]):
        candidates = np.flatnonzero(healthy & (keys == key))
        rows = np.flatnonzero(query_keys == key)
        age = np.abs(t[rows][:, None] - reference[candidates][None, :])
        best = np.argmin(age, axis=1)
        ok = age[np.arange(rows.size), best] <= max_age
        chosen[rows[ok]] = candidates[best[ok]]
    return chosen


def satellite_states(nav: Navigation, system, prn, t) -> SatelliteStates:
    """States at GPS times ``t`` (s) for satellites (system letter, PRN), arrays broadcast."""
    system, prn, t = np.broadcast_arrays(
        np.asarray(system, dtype="U1"), np.asarray(prn), np.asarray(t, dtype=float)
    )
    system, prn, t = system.ravel(), prn.ravel(), t.ravel()
    out = SatelliteStates.empty(t.size)
    kepler_rows = np.flatnonzero(np.isin(system, list(MU)))
    if kepler_rows.size and len(nav.kepler):
        record = select_records(
            nav.kepler,
            system[kepler_rows],
            prn[kepler_rows],
            t[kepler_rows],
            nav.kepler["toe"],
            KEPLER_MAX_AGE_S,
        )
        _fill(out, kepler_rows, record, kepler_states(nav.kepler, record, t[kepler_rows]))
    glonass_rows = np.flatnonzero(system == "R")
    if glonass_rows.size and len(nav.glonass):
        record = select_records(
            nav.glonass,
            system[glonass_rows],
            prn[glonass_rows],
            t[glonass_rows],
            nav.glonass.toc,
            GLONASS_MAX_AGE_S,
        )
        _fill(out, glonass_rows, record, glonass_states(nav.glonass, record, t[glonass_rows]))
    return out


def _fill(out: SatelliteStates, rows, record, states: SatelliteStates) -> None:
    ok = record >= 0
    target = rows[ok]
    out.position[target] = states.position[ok]
    out.velocity[target] = states.velocity[ok]
    out.clock_bias_s[target] = states.clock_bias_s[ok]
    out.clock_drift[target] = states.clock_drift[ok]
    out.valid[target] = True
    out.record[target] = record[ok]


def kepler_states(records: NavRecords, record: np.ndarray, t: np.ndarray) -> SatelliteStates:
    """IS-GPS-200 Table 20-IV for the chosen records (index −1 → invalid row)."""
    ok = record >= 0
    idx = np.where(ok, record, 0)
    p = {name: values[idx] for name, values in records.params.items()}
    system = records.system[idx]
    mu = np.array([MU.get(s, MU["G"]) for s in system]) if system.size else np.zeros(0)
    omega_e = np.array([OMEGA_E.get(s, OMEGA_E["G"]) for s in system]) if system.size else mu
    t = np.asarray(t, dtype=float)
    a = p["sqrt_a"] ** 2
    n = np.sqrt(mu / a**3) + p["delta_n"]
    tk = t - p["toe"]
    mk = p["m0"] + n * tk
    e = p["e"]
    ek = mk.copy()
    for _ in range(30):
        step = (ek - e * np.sin(ek) - mk) / (1.0 - e * np.cos(ek))
        ek -= step
        if np.all(np.abs(step) < 1e-15):
            break
    sin_e, cos_e = np.sin(ek), np.cos(ek)
    one_minus = 1.0 - e * cos_e
    ek_dot = n / one_minus
    beta = np.sqrt(1.0 - e**2)
    nu = np.arctan2(beta * sin_e, cos_e - e)
    nu_dot = ek_dot * beta / one_minus
    phi = nu + p["omega"]
    s2, c2 = np.sin(2 * phi), np.cos(2 * phi)
    u = phi + p["cus"] * s2 + p["cuc"] * c2
    r = a * one_minus + p["crs"] * s2 + p["crc"] * c2
    inc = p["i0"] + p["idot"] * tk + p["cis"] * s2 + p["cic"] * c2
    u_dot = nu_dot * (1.0 + 2.0 * (p["cus"] * c2 - p["cuc"] * s2))
    r_dot = a * e * sin_e * ek_dot + 2.0 * nu_dot * (p["crs"] * c2 - p["crc"] * s2)
    inc_dot = p["idot"] + 2.0 * nu_dot * (p["cis"] * c2 - p["cic"] * s2)
    xp, yp = r * np.cos(u), r * np.sin(u)
    xp_dot = r_dot * np.cos(u) - r * u_dot * np.sin(u)
    yp_dot = r_dot * np.sin(u) + r * u_dot * np.cos(u)
    geo = (system == "C") & ((records.prn[idx] <= 5) | (records.prn[idx] >= 59))
    # GEO: right ascension in the inertial-like frame, rotated to ECEF afterwards
    big_omega_dot = p["omega_dot"] - np.where(geo, 0.0, omega_e)
    big_omega = p["omega0"] + big_omega_dot * tk - omega_e * p["toe_sow"]
    position, velocity = _orbit_to_frame(
        xp, yp, xp_dot, yp_dot, inc, inc_dot, big_omega, big_omega_dot
    )
    if np.any(geo):
        position[geo], velocity[geo] = _bds_geo_to_ecef(
            position[geo], velocity[geo], omega_e[geo] * tk[geo], omega_e[geo]
        )
    f_rel = -2.0 * np.sqrt(mu) / SPEED_OF_LIGHT**2
    dt_clock = t - records.toc[idx]
    bias = p["af0"] + p["af1"] * dt_clock + p["af2"] * dt_clock**2 + f_rel * e * p["sqrt_a"] * sin_e
    drift = p["af1"] + 2.0 * p["af2"] * dt_clock + f_rel * e * p["sqrt_a"] * cos_e * ek_dot
    return _masked(position, velocity, bias, drift, ok, record)


def _orbit_to_frame(xp, yp, xp_dot, yp_dot, inc, inc_dot, big_omega, big_omega_dot):
    """Orbital-plane coordinates and their rates to the Earth-fixed (or GEO inertial) frame."""
    cos_o, sin_o = np.cos(big_omega), np.sin(big_omega)
    cos_i, sin_i = np.cos(inc), np.sin(inc)
    x = xp * cos_o - yp * cos_i * sin_o
    y = xp * sin_o + yp * cos_i * cos_o
    z = yp * sin_i
    vx = xp_dot * cos_o - yp_dot * cos_i * sin_o + yp * sin_i * sin_o * inc_dot - big_omega_dot * y
    vy = xp_dot * sin_o + yp_dot * cos_i * cos_o - yp * sin_i * cos_o * inc_dot + big_omega_dot * x
    vz = yp_dot * sin_i + yp * cos_i * inc_dot
    return np.stack([x, y, z], axis=-1), np.stack([vx, vy, vz], axis=-1)


def _bds_geo_to_ecef(position, velocity, angle, rate):
    """BDS-SIS-ICD 5.2.4.12: P = R_Z(Ω_e t_k) R_X(−5°) P_GK, and its time derivative."""
    cx, sx = np.cos(_BDS_GEO_TILT), np.sin(_BDS_GEO_TILT)
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cx, sx], [0.0, -sx, cx]])
    p = position @ rx.T
    v = velocity @ rx.T
    c, s = np.cos(angle), np.sin(angle)
    x = c * p[:, 0] + s * p[:, 1]
    y = -s * p[:, 0] + c * p[:, 1]
    vx = c * v[:, 0] + s * v[:, 1] + rate * y
    vy = -s * v[:, 0] + c * v[:, 1] - rate * x
    return np.stack([x, y, p[:, 2]], axis=-1), np.stack([vx, vy, v[:, 2]], axis=-1)


def _masked(position, velocity, bias, drift, ok, record) -> SatelliteStates:
    position[~ok] = np.nan
    velocity[~ok] = np.nan
    return SatelliteStates(
        position,
        velocity,
        np.where(ok, bias, np.nan),
        np.where(ok, drift, np.nan),
        ok.copy(),
        np.where(ok, record, -1),
    )


def _glonass_derivative(state: np.ndarray, acceleration: np.ndarray) -> np.ndarray:
    """ICD-GLONASS App. A.3.1.2 equations of motion in PZ-90 (rows: x y z vx vy vz)."""
    pos, vel = state[:, :3], state[:, 3:]
    r2 = np.sum(pos**2, axis=1)
    r = np.sqrt(r2)
    mu_r3 = MU_GLONASS / (r2 * r)
    j2 = 1.5 * J2_GLONASS * MU_GLONASS * AE_GLONASS**2 / (r2 * r2 * r)
    z2 = 5.0 * pos[:, 2] ** 2 / r2
    w2 = OMEGA_E_GLONASS**2
    ax = (-mu_r3 - j2 * (1.0 - z2) + w2) * pos[:, 0] + 2 * OMEGA_E_GLONASS * vel[:, 1]
    ay = (-mu_r3 - j2 * (1.0 - z2) + w2) * pos[:, 1] - 2 * OMEGA_E_GLONASS * vel[:, 0]
    az = (-mu_r3 - j2 * (3.0 - z2)) * pos[:, 2]
    return np.concatenate([vel, np.stack([ax, ay, az], axis=1) + acceleration], axis=1)


def glonass_states(records: NavRecords, record: np.ndarray, t: np.ndarray) -> SatelliteStates:
    """RK4 integration from t_b to t of the chosen GLONASS records (index −1 → invalid row)."""
    ok = record >= 0
    idx = np.where(ok, record, 0)
    p = {name: values[idx] for name, values in records.params.items()}
    state = np.stack([p["x"], p["y"], p["z"], p["vx"], p["vy"], p["vz"]], axis=1)
    acceleration = np.stack([p["ax"], p["ay"], p["az"]], axis=1)
    dt = np.asarray(t, dtype=float) - records.toc[idx]
    dt = np.where(ok, dt, 0.0)
    n_steps = int(np.ceil(np.max(np.abs(dt), initial=0.0) / GLONASS_STEP_S))
    if n_steps:
        h = (dt / n_steps)[:, None]
        for _ in range(n_steps):
            k1 = _glonass_derivative(state, acceleration)
            k2 = _glonass_derivative(state + 0.5 * h * k1, acceleration)
            k3 = _glonass_derivative(state + 0.5 * h * k2, acceleration)
            k4 = _glonass_derivative(state + h * k3, acceleration)
            state = state + h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    bias = p["minus_tau_n"] + p["gamma_n"] * dt
    return _masked(state[:, :3].copy(), state[:, 3:].copy(), bias, p["gamma_n"], ok, record)


def rotate_earth(vectors: np.ndarray, travel_time_s) -> np.ndarray:
    """Express ECEF vectors of the transmission epoch in the ECEF frame of the reception epoch
    (Earth rotation during signal travel, IS-GPS-200 sec. 20.3.3.4.3.4)."""
    angle = OMEGA_E["G"] * np.asarray(travel_time_s, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    v = np.asarray(vectors, dtype=float)
    return np.stack([c * v[..., 0] + s * v[..., 1], -s * v[..., 0] + c * v[..., 1], v[..., 2]], -1)
