"""Simulated GNSS observations of a vehicle in a city: visibility, pseudorange, Doppler, C/N0.

Sign convention (the GNSS code's, RINEX 3.04 sec. 5.2.10): the Doppler D is positive for an
approaching satellite and the range rate is ρ̇ = −λ·D.

Model per epoch tag T (receiver time, GPS s) and satellite, with the true reception time
t = T − δt_r(T), the antenna at r(t), and the satellite state at transmission (``transmit_states``
of the GNSS code: broadcast ephemeris, light time solved geometrically, Earth rotation during
travel; p and v_s expressed in the reception ECEF frame):

    ρ = |p − r|,  u = (p − r)/ρ
    ρ̇ = u·(v_s − v) / (1 − B/c),  B = Ω_e·u·(p_y, −p_x, 0) − u·v_s       (exact d/dt of ρ(t),
         the light-time derivative included; the first-order model u·(v_s − v) differs by mm/s)
    P = ρ + c·δt_r − c·(δt_s − T_GD) + T_trop + I_Klobuchar + ε_P  [+ NLOS excess]
    −λ·D = ρ̇ + c·δṫ_r − c·δṫ_s + ε_D  [+ NLOS excess rate]

with δt_s including the relativistic term (IS-GPS-200 sec. 20.3.3.3.3.1), T_GD the broadcast
group delay (GPS T_GD, Galileo BGD(E1,E5b)), the Saastamoinen troposphere and the broadcast
Klobuchar ionosphere (``vo_doppler.gnss.atmosphere``). The atmospheric delays' rates (mm/s)
are left out of the Doppler.

Visibility: a satellite above the elevation mask is received directly when the ray from the
antenna towards it leaves the city without entering any building box (slab test, vectorised
over rays × boxes). With ``nlos`` on, a blocked satellite can still be received by one specular
reflection on a vertical facade: the arrival direction is the line of sight mirrored in the
facade plane; the ray along it must hit a facade of that orientation first, and the ray from
the reflection point towards the satellite must be clear. For a facade at perpendicular
distance d and line-of-sight component u_n along its normal, the extra path is 2·d·|u_n| and
its rate −2·(v·m)·|u_n| (m: unit vector from the antenna towards the facade; the slow change
of u_n is neglected). Reflected signals lose ``nlos_loss_db`` of C/N0; only a fraction of the
facades reflect (glass, drawn per building side), and signals whose mean C/N0 is below the
tracking threshold are not received.

C/N0 = C/N0_horizon + (C/N0_zenith − C/N0_horizon)·sin(el) (− reflection loss) + white noise;
noise standard deviations scale as 10^((45 − C/N0)/20) (tracking-loop noise ∝ (C/N0)^−½).
Receiver clock: drift a random walk, bias its integral plus a random walk that reaches the
pseudorange only (code-tracking clock noise; the Doppler sees the drift).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from vo_doppler.geo import SPEED_OF_LIGHT, EnuFrame
from vo_doppler.gnss.atmosphere import klobuchar_delay, troposphere_delay
from vo_doppler.gnss.ephemeris import OMEGA_E
from vo_doppler.gnss.satellite_source import transmit_states
from vo_doppler.gnss.signals import FREQUENCIES_HZ
from vo_doppler.io.rinex_write import ObsEpochs
from vo_doppler.model.navigation import Navigation
from vo_doppler.sim.canyon_realism import (
    CanyonRealism,
    canyon_rows,
    scatterers,
    thermal_sigma_mps,
)
from vo_doppler.sim.constellation import GROUP_DELAY_FIELD

CODES = ("C1C", "D1C", "S1C")
"""Observables written per satellite: L1 C/A (GPS) / E1 (Galileo) code, Doppler, C/N0."""
CN0_NOISE_REFERENCE_DBHZ = 45.0
_RAY_CHUNK = 4096


@dataclass(frozen=True)
class GnssSimConfig:
    """Receiver and signal settings (noise standard deviations at 45 dB-Hz)."""

    rate_hz: float = 20.0
    systems: str = "GE"
    elevation_mask_deg: float = 5.0
    cn0_zenith_dbhz: float = 48.0
    cn0_horizon_dbhz: float = 34.0
    cn0_noise_db: float = 0.5
    sigma_pseudorange_m: float = 0.6
    sigma_range_rate_mps: float = 0.03
    noise: bool = True
    atmosphere: bool = True
    nlos: bool = False
    nlos_loss_db: float = 8.0
    nlos_reflective_fraction: float = 0.3
    tracking_threshold_dbhz: float = 28.0
    clock_bias0_s: float | None = None
    clock_drift0_mps: float | None = None
    clock_drift_walk_mps_per_sqrt_s: float = 0.01
    clock_bias_walk_m_per_sqrt_s: float = 0.1
    canyon: CanyonRealism | None = None
    """The real canyon's diffraction, scattering and noise floor
    (:mod:`vo_doppler.sim.canyon_realism`; None: the geometric canyon)."""


@dataclass(frozen=True)
class ReceiverClock:
    """Receiver clock at the epoch tags: bias (s) and drift (s/s)."""

    bias_s: np.ndarray
    drift: np.ndarray
    bias_noise_m: np.ndarray


def receiver_clock(n: int, dt: float, config: GnssSimConfig, rng: np.random.Generator):
    """Drift: random walk (σ = ``clock_drift_walk_mps_per_sqrt_s``/c per √s); bias: trapezoidal
    integral of the drift; a separate random walk (``clock_bias_walk_m_per_sqrt_s``) for the
    pseudorange."""
    drift0 = config.clock_drift0_mps if config.clock_drift0_mps is not None else rng.normal(0, 60.0)
    bias0 = config.clock_bias0_s if config.clock_bias0_s is not None else rng.uniform(-3e-4, 3e-4)
    steps = rng.normal(0.0, config.clock_drift_walk_mps_per_sqrt_s * np.sqrt(dt), n - 1)
    drift = (drift0 + np.concatenate([[0.0], np.cumsum(steps)])) / SPEED_OF_LIGHT
    bias = bias0 + np.concatenate([[0.0], np.cumsum(0.5 * (drift[1:] + drift[:-1]) * dt)])
    walk = rng.normal(0.0, config.clock_bias_walk_m_per_sqrt_s * np.sqrt(dt), n - 1)
    return ReceiverClock(bias, drift, np.concatenate([[0.0], np.cumsum(walk)]))


@dataclass(frozen=True)
class Boxes:
    """Axis-aligned boxes (buildings): lower and upper corners (M, 3), ENU metres."""

    lo: np.ndarray
    hi: np.ndarray

    @classmethod
    def from_buildings(cls, buildings) -> Boxes:
        lo = np.array([[b.x0, b.y0, 0.0] for b in buildings]).reshape(-1, 3)
        hi = np.array([[b.x1, b.y1, b.height] for b in buildings]).reshape(-1, 3)
        return cls(lo, hi)


@dataclass(frozen=True)
class RayHits:
    """First box hit per ray: ``hit``, distance along the ray, the axis of the face hit and
    the box index (−1 when nothing is hit)."""

    hit: np.ndarray
    distance: np.ndarray
    axis: np.ndarray
    box: np.ndarray


def ray_hits(origins: np.ndarray, directions: np.ndarray, boxes: Boxes) -> RayHits:
    """Slab test of rays (N, 3) against boxes, vectorised over rays × boxes (chunks of rays).

    A ray starting inside a box counts as hitting it at distance 0. Directions need not be
    unit vectors; distances are in units of their length.
    """
    n = len(origins)
    hit = np.zeros(n, dtype=bool)
    distance = np.full(n, np.inf)
    axis = np.full(n, -1, dtype=np.int64)
    box = np.full(n, -1, dtype=np.int64)
    if n == 0 or len(boxes.lo) == 0:
        return RayHits(hit, distance, axis, box)
    safe = np.where(np.abs(directions) < 1e-12, 1e-12, directions)
    inverse = 1.0 / safe
    for start in range(0, n, _RAY_CHUNK):
        sl = slice(start, start + _RAY_CHUNK)
        o, inv = origins[sl, None, :], inverse[sl, None, :]
        t1 = (boxes.lo[None] - o) * inv
        t2 = (boxes.hi[None] - o) * inv
        near = np.minimum(t1, t2)
        t_near = near.max(axis=2)
        t_far = np.maximum(t1, t2).min(axis=2)
        entered = (t_far >= np.maximum(t_near, 0.0)) & (t_far > 0.0)
        entry = np.where(entered, np.maximum(t_near, 0.0), np.inf)
        first = np.argmin(entry, axis=1)
        rows = np.arange(entry.shape[0])
        distance[sl] = entry[rows, first]
        hit[sl] = np.isfinite(distance[sl])
        axis[sl] = np.where(hit[sl], np.argmax(near[rows, first], axis=1), -1)
        box[sl] = np.where(hit[sl], first, -1)
    return RayHits(hit, distance, axis, box)


@dataclass(frozen=True)
class Reflections:
    """Single-bounce facade reflections of blocked rays: ``found``, extra path and its rate."""

    found: np.ndarray
    excess_m: np.ndarray
    excess_rate_mps: np.ndarray


def facade_reflections(
    origins: np.ndarray,
    directions: np.ndarray,
    velocity: np.ndarray,
    boxes: Boxes,
    reflective: np.ndarray | None = None,
) -> Reflections:
    """Best (shortest extra path) specular reflection on an x- or y-facing facade per ray
    (unit ``directions`` towards the satellites; model in the module docstring).
    ``reflective`` (M, 2) says which boxes' x- and y-facing facades reflect (default all)."""
    n = len(origins)
    best = np.full(n, np.inf)
    rate = np.zeros(n)
    for k in (0, 1):
        mirrored = directions.copy()
        mirrored[:, k] *= -1.0
        first = ray_hits(origins, mirrored, boxes)
        ok = first.hit & (first.axis == k) & (np.abs(directions[:, k]) > 1e-6)
        if reflective is not None:
            ok &= reflective[np.maximum(first.box, 0), k]
        point = origins + (first.distance[:, None] - 1e-3) * mirrored
        rows = np.flatnonzero(ok)
        onward = ray_hits(point[rows], directions[rows], boxes)
        ok[rows[onward.hit]] = False
        component = np.abs(directions[:, k])
        excess = np.where(ok, 2.0 * first.distance * component**2, np.inf)
        towards_wall = np.sign(mirrored[:, k])
        better = excess < best
        best = np.where(better, excess, best)
        rate = np.where(better, -2.0 * velocity[:, k] * towards_wall * component, rate)
    found = np.isfinite(best)
    return Reflections(found, np.where(found, best, 0.0), np.where(found, rate, 0.0))


@dataclass(frozen=True)
class Geometry:
    """Noise-free geometry of (epoch, satellite) rows at the true reception times."""

    range_m: np.ndarray
    range_rate_mps: np.ndarray
    los_ecef: np.ndarray
    sat_clock_bias_s: np.ndarray
    sat_clock_drift: np.ndarray
    group_delay_s: np.ndarray
    valid: np.ndarray


def range_and_rate(
    nav: Navigation, system, prn, t: np.ndarray, r_ecef: np.ndarray, v_ecef: np.ndarray
) -> Geometry:
    """Geometric range and its exact time derivative (module docstring) per row."""
    states, _ = transmit_states(nav, system, prn, t, receiver_ecef=r_ecef)
    p, vs = states.position, states.velocity
    los = p - r_ecef
    rho = np.linalg.norm(los, axis=1)
    u = los / rho[:, None]
    a = np.einsum("ij,ij->i", u, vs - v_ecef)
    spin = np.stack([p[:, 1], -p[:, 0], np.zeros(len(p))], axis=1)
    b = OMEGA_E["G"] * np.einsum("ij,ij->i", u, spin) - np.einsum("ij,ij->i", u, vs)
    group_delay = np.zeros(len(rho))
    system = np.broadcast_to(np.asarray(system), rho.shape)
    for letter, name in GROUP_DELAY_FIELD.items():
        rows = states.valid & (system == letter)
        group_delay[rows] = nav.kepler[name][states.record[rows]]
    return Geometry(
        rho,
        a / (1.0 - b / SPEED_OF_LIGHT),
        u,
        states.clock_bias_s,
        states.clock_drift,
        group_delay,
        states.valid,
    )


@dataclass(frozen=True)
class GnssSimulation:
    """Observations (one row per received (epoch, satellite)) and their truth.

    Per epoch (K): ``epoch_time`` tags (GPS s, receiver time), ``t_true`` reception times,
    ``clock``, ``n_direct``/``n_reflected`` received satellites, ``n_above_mask``.
    Per row: ``epoch``, ``system``, ``prn``, ``pseudorange_m``, ``doppler_hz``, ``cn0_dbhz``,
    ``range_rate_true_mps`` (noise-free −λ·D), ``elevation``/``azimuth`` (rad), ``reflected``
    (no line of sight), ``range_rate_direct_mps`` (the noise-free −λ·D of the direct path: the
    truth a Doppler error is measured against) and, with the real canyon, ``scatter_weight``
    (the scattered power's share w).
    """

    epoch_time: np.ndarray
    t_true: np.ndarray
    clock: ReceiverClock
    n_direct: np.ndarray
    n_reflected: np.ndarray
    n_above_mask: np.ndarray
    epoch: np.ndarray
    system: np.ndarray
    prn: np.ndarray
    pseudorange_m: np.ndarray
    doppler_hz: np.ndarray
    cn0_dbhz: np.ndarray
    wavelength_m: np.ndarray
    range_rate_true_mps: np.ndarray
    elevation: np.ndarray
    azimuth: np.ndarray
    reflected: np.ndarray
    range_rate_direct_mps: np.ndarray | None = None
    scatter_weight: np.ndarray | None = None

    @property
    def n_visible(self) -> np.ndarray:
        return self.n_direct + self.n_reflected

    @property
    def satellite(self) -> np.ndarray:
        return np.char.add(self.system, np.char.zfill(self.prn.astype(str), 2))

    def obs_epochs(self) -> ObsEpochs:
        """The rows as RINEX observables (``CODES``)."""
        values = np.column_stack([self.pseudorange_m, self.doppler_hz, self.cn0_dbhz])
        return ObsEpochs(self.epoch_time, self.epoch, self.satellite, values, CODES)


MotionFn = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
"""times (GPS s) → antenna positions and velocities (N, 3), ENU."""


def simulate_gnss(
    nav: Navigation,
    frame: EnuFrame,
    epoch_time: np.ndarray,
    antenna_motion: MotionFn,
    boxes: Boxes,
    config: GnssSimConfig,
    rng: np.random.Generator,
) -> GnssSimulation:
    """Observations at the epoch tags ``epoch_time`` for every satellite of ``config.systems``
    in ``nav`` (model in the module docstring)."""
    n_epochs = len(epoch_time)
    dt = 1.0 / config.rate_hz
    clock = receiver_clock(n_epochs, dt, config, rng)
    t_true = epoch_time - clock.bias_s
    position_enu, velocity_enu = antenna_motion(t_true)
    rotation = frame.rotation
    r_ecef = frame.enu_to_ecef(position_enu)
    v_ecef = velocity_enu @ rotation
    keep = np.isin(nav.kepler.system, list(config.systems))
    pairs = zip(nav.kepler.system[keep].tolist(), nav.kepler.prn[keep].tolist(), strict=True)
    sats = sorted(set(pairs))
    sat_system = np.array([s for s, _ in sats], dtype="U1")
    sat_prn = np.array([p for _, p in sats], dtype=np.int16)
    epoch = np.repeat(np.arange(n_epochs), len(sats))
    system = np.tile(sat_system, n_epochs)
    prn = np.tile(sat_prn, n_epochs)
    geometry = range_and_rate(nav, system, prn, t_true[epoch], r_ecef[epoch], v_ecef[epoch])
    los_enu = geometry.los_ecef @ rotation.T
    elevation = np.arcsin(np.clip(los_enu[:, 2], -1.0, 1.0))
    azimuth = np.mod(np.arctan2(los_enu[:, 0], los_enu[:, 1]), 2 * np.pi)
    above = geometry.valid & (elevation > np.radians(config.elevation_mask_deg))
    rows = np.flatnonzero(above)
    origins = position_enu[epoch[rows]]
    hits = ray_hits(origins, los_enu[rows], boxes)
    blocked = hits.hit
    reflected = np.zeros(rows.size, dtype=bool)
    excess = np.zeros(rows.size)
    excess_rate = np.zeros(rows.size)
    bounce = None
    if config.nlos and np.any(blocked):
        b = np.flatnonzero(blocked)
        reflective = rng.uniform(size=(len(boxes.lo), 2)) < config.nlos_reflective_fraction
        bounce = facade_reflections(
            origins[b], los_enu[rows[b]], velocity_enu[epoch[rows[b]]], boxes, reflective
        )
        reflected[b] = bounce.found
        excess[b], excess_rate[b] = bounce.excess_m, bounce.excess_rate_mps
    weight = None
    if config.canyon is None:
        cn0_mean = (
            config.cn0_horizon_dbhz
            + (config.cn0_zenith_dbhz - config.cn0_horizon_dbhz) * np.sin(elevation[rows])
            - config.nlos_loss_db * reflected
        )
        received = (~blocked | reflected) & (cn0_mean >= config.tracking_threshold_dbhz)
    else:
        scatter = scatterers(position_enu, len(sats), dt, boxes, config.canyon, rng)
        mixed = canyon_rows(
            config,
            los_enu[rows],
            elevation[rows],
            origins,
            velocity_enu[epoch[rows]],
            hits.distance,
            hits.box,
            scatter,
            scatter.episode.ravel()[rows],
            SPEED_OF_LIGHT / np.array([FREQUENCIES_HZ[s]["1"] for s in system[rows]]),
            boxes,
            rng,
        )
        cn0_mean, received, weight = mixed.cn0_dbhz, mixed.received, mixed.weight[mixed.received]
        reflected = blocked.copy()
        excess, excess_rate = mixed.excess_m, mixed.excess_rate_mps
    rows, reflected, cn0 = rows[received], reflected[received], cn0_mean[received]
    excess, excess_rate = excess[received], excess_rate[received]
    k = epoch[rows]
    el, az = elevation[rows], azimuth[rows]
    frequency = np.array([FREQUENCIES_HZ[s]["1"] for s in system[rows]])
    wavelength = SPEED_OF_LIGHT / frequency
    c = SPEED_OF_LIGHT
    range_rate = (
        geometry.range_rate_mps[rows]
        + c * clock.drift[k]
        - c * geometry.sat_clock_drift[rows]
        + excess_rate
    )
    pseudorange = (
        geometry.range_m[rows]
        + c * clock.bias_s[k]
        + clock.bias_noise_m[k]
        - c * (geometry.sat_clock_bias_s[rows] - geometry.group_delay_s[rows])
        + excess
    )
    if config.atmosphere:
        pseudorange += troposphere_delay(frame.lat_rad, frame.height_m, el) + klobuchar_delay(
            nav.klobuchar, frame.lat_rad, frame.lon_rad, el, az, t_true[k], frequency
        )
    true_range_rate = range_rate.copy()
    if config.noise:
        cn0 = cn0 + rng.normal(0.0, config.cn0_noise_db, rows.size)
        scale = 10.0 ** ((CN0_NOISE_REFERENCE_DBHZ - cn0) / 20.0)
        pseudorange += rng.normal(0.0, 1.0, rows.size) * config.sigma_pseudorange_m * scale
        if config.canyon is None:
            range_rate += rng.normal(0.0, 1.0, rows.size) * config.sigma_range_rate_mps * scale
        else:
            range_rate += rng.normal(0.0, 1.0, rows.size) * thermal_sigma_mps(config, cn0)
    count = np.bincount
    return GnssSimulation(
        epoch_time=np.asarray(epoch_time, dtype=float),
        t_true=t_true,
        clock=clock,
        n_direct=count(k[~reflected], minlength=n_epochs),
        n_reflected=count(k[reflected], minlength=n_epochs),
        n_above_mask=count(epoch[above], minlength=n_epochs),
        epoch=k,
        system=system[rows],
        prn=prn[rows],
        pseudorange_m=pseudorange,
        doppler_hz=-range_rate / wavelength,
        cn0_dbhz=cn0,
        wavelength_m=wavelength,
        range_rate_true_mps=true_range_rate,
        elevation=el,
        azimuth=az,
        reflected=reflected,
        range_rate_direct_mps=true_range_rate - excess_rate,
        scatter_weight=weight,
    )
