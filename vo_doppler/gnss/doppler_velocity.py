"""Conventional Doppler velocity: receiver velocity and clock drift per epoch (docs/design.md,
"Conventional Doppler velocity").

Sign convention (RINEX 3.05 sec. 5.2.10: Doppler is positive for approaching satellites):
range rate ρ̇ = −λ·D. With the unit line of sight e = (x_s − x_r)/|x_s − x_r| (receiver →
satellite, ECEF of the reception epoch), satellite velocity v_s, receiver velocity v, receiver
clock drift b = c·δṫ_r (m/s) and satellite clock drift c·δṫ_s (m/s):

    ρ̇ = e·(v_s − v) + b − c·δṫ_s
    ⇔ ρ̇ − e·v_s + c·δṫ_s = −e·v + b            (one row [−e, 1] of the design matrix)

Weights: σ_i = σ₀ · 10^((C/N0_ref − C/N0_i)/20) / sin(elevation_i), or the receiver's own σ
where it reports one, or σ fitted to the residuals (``doppler_noise``). Fault detection and
exclusion: chi-square test, iterated (``lsq.lsq_with_exclusion``). Fewer than four satellites
(after mask and exclusion) → the epoch is unavailable (NaN), never guessed. ``valid`` only where
the solution could be tested and passed: at least five satellites left after the exclusion
(redundancy), the chi-square test accepting them, and a vertical velocity that a land vehicle
can have (:func:`vertical_velocity_plausible`) — these make it ``verified`` — and a course
continuous with the neighbouring epochs' (:mod:`vo_doppler.gnss.continuity`); a four-satellite
solution is given, with its σ, but not valid (``untestable``: the heading stage's calibration
tests it against the wheels and the gyro instead).

The vertical test adds the one fact about a car that the GNSS-only solution leaves out: it
climbs no steeper than its road. Reflected (NLOS) Doppler from several satellites at once can
be fitted by a wrong velocity that passes the chi-square test (with five or six satellites it
has one or two degrees of freedom), but the wrong velocity then rarely stays horizontal
(docs/design.md (2a): measured on simulated canyons and the real recordings).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace

import numpy as np

from vo_doppler.geo import SPEED_OF_LIGHT, ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.gnss.continuity import continuity_checked
from vo_doppler.gnss.doppler_noise import fitted_sigma
from vo_doppler.gnss.lsq import (
    DEFAULT_ALPHA,
    LsqResult,
    lsq_with_exclusion,
    minimal_detectable_shift,
)
from vo_doppler.gnss.noise_model import NoiseModel, fit_noise_models, modelled_sigma
from vo_doppler.gnss.satellite_source import (
    SatelliteSource,
    StateSource,
    satellite_source,
    transmit_states,
)
from vo_doppler.gnss.signals import strength_code, wavelengths
from vo_doppler.gnss.spp import elevation_azimuth
from vo_doppler.model.doppler import DopplerRows, read_only
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.gnss_solutions import VelocitySolution
from vo_doppler.model.observations import Observations, lookup, row_keys
from vo_doppler.model.signals import DEFAULT_SYSTEMS

log = logging.getLogger(__name__)

SIGMA_RANGE_RATE_MPS = 0.05
CN0_REFERENCE_DBHZ = 45.0
CN0_DEFAULT_DBHZ = 40.0
MIN_SATELLITES = 4
NOISE_PASSES = 3
GRADE_SIGMA = 0.1
"""σ of a land vehicle's vertical over its horizontal speed: a road's grade of 10 %, so that
the 3σ gate is a 30 % grade, steeper than public roads (the steepest streets are 30–35 %)."""
VERTICAL_FLOOR_MPS = 0.1
"""σ of the vertical velocity at any speed: suspension, a walker's gait, a phone in a hand."""
VERTICAL_GATE = 3.0


def range_rate_sigma(cn0: np.ndarray, elevation: np.ndarray, sigma0: float) -> np.ndarray:
    """σ of a range rate (m/s) from C/N0 and elevation (module docstring)."""
    cn0 = np.where(np.isfinite(cn0), cn0, CN0_DEFAULT_DBHZ)
    strength = 10.0 ** ((CN0_REFERENCE_DBHZ - np.minimum(cn0, 55.0)) / 20.0)
    return sigma0 * strength / np.sin(np.maximum(elevation, np.deg2rad(5.0)))


def doppler_codes(obs: Observations, systems: str, bands: str | None = None) -> list[str]:
    """Doppler observables present for the systems (optionally only the given band digits)."""
    codes = set()
    for system in systems:
        codes.update(c for c in obs.codes_of(system) if c.startswith("D"))
    return sorted(c for c in codes if bands is None or c[1:2] in bands)


def doppler_rows(
    obs: Observations,
    source: StateSource,
    receiver_ecef: np.ndarray,
    systems: str = DEFAULT_SYSTEMS,
    bands: str | None = None,
    elevation_mask_rad: float = np.deg2rad(10.0),
    reported_sigma: ReportedSigma | None = None,
    log_missing: bool = True,
) -> DopplerRows:
    """Doppler rows of the chosen systems/bands with satellite states and geometry: the terms
    of docs/design.md (1)–(2) per row, weighted by the receiver's ``reported_sigma`` where it
    gives one, else by the C/N0 and elevation model (:func:`range_rate_sigma`, σ₀
    ``SIGMA_RANGE_RATE_MPS``).

    ``receiver_ecef``: (3,) or one position per observation epoch (E, 3; NaN rows are skipped).
    Satellite states are taken at signal transmission (travel time from the geometric range) in
    the ECEF frame of reception, from ``source`` (broadcast or precise, ``satellite_source``).
    Rows without ephemeris or wavelength are dropped and counted, the satellites without one
    logged unless ``log_missing`` is False (a second pass over the same file, which would
    repeat the warning).
    """
    source = satellite_source(source)
    receiver = np.broadcast_to(np.asarray(receiver_ecef, dtype=float), (obs.epoch_time.size, 3))
    sel, code_names = _doppler_observations(obs, systems, bands)
    wavelength, cn0 = _wavelength_and_strength(obs, sel, code_names, source)
    epoch = np.searchsorted(obs.epoch_time, sel.time)
    blocks = [
        _row_block(
            source,
            sel,
            np.arange(k, min(k + ROWS_CHUNK, len(sel))),
            (wavelength, receiver[epoch[k : k + ROWS_CHUNK]]),
            elevation_mask_rad,
        )
        for k in range(0, len(sel), ROWS_CHUNK)
    ]
    no_eph = _joined(blocks, "no_ephemeris", bool)
    visible = _joined(blocks, "elevation_with_ephemeris", float)
    idx = _joined(blocks, "index", np.int64)
    missing = _missing_messages(sel, no_eph)
    if log_missing:
        _log_skipped(missing, visible, elevation_mask_rad)
    kept = sel.subset(idx)
    elevation = _joined(blocks, "elevation", float)
    model_sigma = range_rate_sigma(cn0[idx], elevation, SIGMA_RANGE_RATE_MPS)
    rows = {
        "t": kept.time,
        "epoch": epoch[idx],
        "system": kept.system,
        "prn": kept.prn,
        "code": code_names[idx],
        "wavelength_m": wavelength[idx],
        "los": _joined(blocks, "los", float, 3),
        "sat_position": _joined(blocks, "sat_position", float, 3),
        "sat_velocity": _joined(blocks, "sat_velocity", float, 3),
        "sat_clock_drift": _joined(blocks, "sat_clock_drift", float),
        "range_rate": -wavelength[idx] * kept.value,
        "weight": _row_sigma(model_sigma, reported_sigma, kept, code_names[idx]) ** -2.0,
        "sat_id": kept.satellites(),
        "cn0": cn0[idx],
        "elevation": elevation,
        "azimuth": _joined(blocks, "azimuth", float),
    }
    rows["receiver_ecef"] = receiver[rows["epoch"]]
    return DopplerRows(
        **{name: read_only(array) for name, array in rows.items()},
        frame="ecef",
        n_no_ephemeris=int(no_eph.sum()),
        n_no_wavelength=int((~np.isfinite(wavelength)).sum()),
        n_below_mask=int(visible.size - idx.size),
        missing=missing,
    )


ROWS_CHUNK = 8192
"""Doppler observations turned into rows at once (:func:`_row_block`): the satellite states,
geometry and row arrays of a whole drive at once took about 650 bytes an observation, 92 MiB
on a 30-min drive at 20 Hz, three times the rows they made."""


def _row_block(
    source: SatelliteSource,
    sel: Observations,
    block: np.ndarray,
    signal: tuple[np.ndarray, np.ndarray],
    elevation_mask_rad: float,
) -> dict[str, np.ndarray]:
    """What :func:`doppler_rows` computes for the observations ``block`` of ``sel``
    (``signal``: the wavelength of every observation of ``sel``, the receiver position of each
    of the block's): the satellite states at transmission and the geometry of the rows whose
    wavelength and position are known, and which of them are kept (a healthy ephemeris, above
    the elevation mask). Each row's result is its own, whatever the block."""
    wavelength, position = signal
    usable = np.isfinite(wavelength[block]) & np.isfinite(position).all(axis=1)
    rows = block[usable]
    states, _ = transmit_states(
        source, sel.system[rows], sel.prn[rows], sel.time[rows], receiver_ecef=position[usable]
    )
    los, elevation, azimuth = _line_of_sight(states.position, position[usable])
    good = states.valid & (elevation >= elevation_mask_rad)
    no_eph = np.zeros(len(block), dtype=bool)
    no_eph[np.flatnonzero(usable)[~states.valid]] = True
    return {
        "no_ephemeris": no_eph,
        "elevation_with_ephemeris": elevation[states.valid],
        "index": rows[good],
        "los": los[good],
        "sat_position": states.position[good],
        "sat_velocity": states.velocity[good],
        "sat_clock_drift": SPEED_OF_LIGHT * states.clock_drift[good],
        "elevation": elevation[good],
        "azimuth": azimuth[good],
    }


def _joined(blocks: list[dict[str, np.ndarray]], name: str, dtype, width: int = 0) -> np.ndarray:
    """The blocks' arrays ``name`` end to end, each block's let go as it is joined (the rows
    of a long drive are not held twice)."""
    empty = np.zeros((0, width) if width else 0, dtype=dtype)
    return np.concatenate([empty, *(block.pop(name) for block in blocks)])


def _doppler_observations(
    obs: Observations, systems: str, bands: str | None
) -> tuple[Observations, np.ndarray]:
    """The finite Doppler observations of the ``systems`` (and ``bands``,
    :func:`doppler_codes`), and each one's observable code."""
    keep = np.zeros(len(obs), dtype=bool)
    for system in systems:
        for code in doppler_codes(obs, system, bands):
            keep |= obs.mask(system, code)
    sel = obs.subset(keep & np.isfinite(obs.value))
    code_names = np.array(obs.codes, dtype="U3")[sel.code] if len(sel) else np.zeros(0, "U3")
    return sel, code_names


def _wavelength_and_strength(
    obs: Observations, sel: Observations, code_names: np.ndarray, source: SatelliteSource
) -> tuple[np.ndarray, np.ndarray]:
    """Carrier wavelength (m) and C/N0 (dB-Hz) of each observation of ``sel``, NaN where
    unknown (a GLONASS satellite's channel from the file's header, else from ``source``)."""
    channels = {**source.glonass_channels(), **obs.header.glonass_channels}
    wavelength = np.full(len(sel), np.nan)
    cn0 = np.full(len(sel), np.nan)
    for code in np.unique(code_names):
        rows = code_names == code
        wavelength[rows] = wavelengths(
            sel.system[rows], sel.prn[rows], str(code), channels, obs.header.version
        )
        cn0[rows] = _signal_strength(obs, sel, rows, strength_code(str(code)))
    return wavelength, cn0


def _line_of_sight(
    sat_position: np.ndarray, receiver: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit line of sight G (receiver → satellite, ECEF; docs/design.md (1)), elevation and
    azimuth (rad) of each row."""
    vector = sat_position - receiver
    los = vector / np.linalg.norm(vector, axis=1, keepdims=True)
    elevation, azimuth = elevation_azimuth(receiver, los)
    return los, elevation, azimuth


def _log_skipped(missing: tuple[str, ...], elevation: np.ndarray, mask_rad: float) -> None:
    """Warn of the satellites skipped without ephemeris (``missing``), and when every row with
    one (their ``elevation``) lies below the elevation mask."""
    for message in missing:
        log.warning("satellite %s skipped", message)
    if elevation.size and not np.any(elevation >= mask_rad):
        log.warning(
            "every Doppler row lies below the elevation mask of %.1f° (the highest satellite "
            "at %.1f°): no row is left",
            np.degrees(mask_rad),
            np.degrees(np.max(elevation)),
        )


def _row_sigma(model, reported: ReportedSigma | None, sel: Observations, codes) -> np.ndarray:
    """The receiver-reported σ where it gave one, else the C/N0 model's."""
    if reported is None:
        return model
    given = reported.at(sel.time, sel.satellites(), codes)
    return np.where(np.isfinite(given), given, model)


def _signal_strength(obs: Observations, sel: Observations, rows: np.ndarray, code: str):
    """C/N0 of the same signal at the same epoch and satellite (NaN when absent)."""
    strength = obs.select(code=code)
    keys = row_keys(obs.epoch_time, strength.time, strength.system, strength.prn)
    wanted = row_keys(obs.epoch_time, sel.time[rows], sel.system[rows], sel.prn[rows])
    return lookup(keys, strength.value, wanted)


def _missing_messages(sel: Observations, no_eph: np.ndarray) -> tuple[str, ...]:
    messages = []
    if no_eph.any():
        sats = sel.satellites()[no_eph]
        times = sel.time[no_eph]
        for sat in np.unique(sats):
            first = times[sats == sat].min()
            count = int((sats == sat).sum())
            messages.append(f"{sat}: no healthy ephemeris from GPS time {first:.1f} ({count} rows)")
    return tuple(messages)


def solve_velocity(
    rows: DopplerRows,
    epoch_time: np.ndarray,
    alpha: float = DEFAULT_ALPHA,
) -> VelocitySolution:
    """Weighted LS velocity + clock drift per epoch (docs/design.md (2)) with iterated
    chi-square FDE; each solved epoch's σ, DOP, protection (2c) and tests (2a)
    (:meth:`_VelocityColumns.store`), then the course continuity test (2b)."""
    n = epoch_time.size
    columns = _VelocityColumns.unsolved(n)
    order = np.argsort(rows.epoch, kind="stable")
    bounds = np.searchsorted(rows.epoch[order], np.arange(n + 1))
    y_all = rows.reduced()
    sigma_all = rows.sigma()
    satellite = np.char.add(rows.system, rows.prn.astype(str)) if len(rows) else rows.system
    for k in range(n):
        r = order[bounds[k] : bounds[k + 1]]
        if np.unique(satellite[r]).size < MIN_SATELLITES:
            columns.n_sat[k] = np.unique(satellite[r]).size
            continue
        H = np.hstack([-rows.los[r], np.ones((r.size, 1))])
        result = lsq_with_exclusion(H, y_all[r], sigma_all[r], satellite[r], MIN_SATELLITES, alpha)
        columns.n_sat[k] = np.unique(satellite[r][result.used]).size if result.valid else 0
        if result.valid:
            lat, lon, _ = ecef_to_geodetic(rows.receiver_ecef[r[0]])
            rotation = ecef_to_enu_rotation(float(lat), float(lon))
            columns.store(k, _EpochFit(H, sigma_all[r], satellite[r], result, rotation), alpha)
    return continuity_checked(columns.solution(epoch_time, rows.n_no_ephemeris))


@dataclass(frozen=True)
class _EpochFit:
    """One epoch's weighted least-squares problem (2) and its solution after the exclusion."""

    design: np.ndarray
    """H, one row [−G, 1] per Doppler row."""
    sigma: np.ndarray
    """σ of each row (m/s)."""
    satellite: np.ndarray
    """Each row's satellite, the unit of the exclusion."""
    result: LsqResult
    rotation: np.ndarray
    """ECEF → ENU at the receiver."""


@dataclass
class _VelocityColumns:
    """:func:`solve_velocity`'s per-epoch results, filled epoch by epoch (NaN, 0 or False where
    no velocity is solved); the fields of :class:`VelocitySolution`."""

    velocity_ecef: np.ndarray
    velocity_enu: np.ndarray
    clock_drift_mps: np.ndarray
    covariance: np.ndarray
    dop: np.ndarray
    n_sat: np.ndarray
    n_obs: np.ndarray
    n_excluded: np.ndarray
    residual_rms_mps: np.ndarray
    verified: np.ndarray
    untestable: np.ndarray
    speed_course_sigma: np.ndarray
    """σ of the horizontal speed (m/s) and of the course (rad), :func:`speed_course_sigma`."""
    vertical_sigma_mps: np.ndarray
    horizontal_protection_mps: np.ndarray

    @classmethod
    def unsolved(cls, n: int) -> _VelocityColumns:
        """Columns for ``n`` epochs, none solved."""

        def nan(*shape: int) -> np.ndarray:
            return np.full((n, *shape), np.nan)

        def zeros(dtype) -> np.ndarray:
            return np.zeros(n, dtype=dtype)

        return cls(
            velocity_ecef=nan(3),
            velocity_enu=nan(3),
            clock_drift_mps=nan(),
            covariance=nan(4, 4),
            dop=nan(5),
            n_sat=zeros(np.int64),
            n_obs=zeros(np.int64),
            n_excluded=zeros(np.int64),
            residual_rms_mps=nan(),
            verified=zeros(bool),
            untestable=zeros(bool),
            speed_course_sigma=nan(2),
            vertical_sigma_mps=nan(),
            horizontal_protection_mps=nan(),
        )

    def store(self, k: int, fit: _EpochFit, alpha: float) -> None:
        """Epoch ``k``'s solution with its σ, DOP, protection level (2c) and tests: verified
        with redundancy, the chi-square test passed and a plausible vertical velocity (2a);
        untestable with four satellites and a plausible vertical velocity."""
        result, rotation, used = fit.result, fit.rotation, fit.result.used
        self.velocity_ecef[k] = result.x[:3]
        self.clock_drift_mps[k] = result.x[3]
        self.covariance[k] = result.covariance
        self.n_obs[k] = int(used.sum())
        self.n_excluded[k] = int((~used).sum())
        self.residual_rms_mps[k] = float(np.sqrt(np.mean(result.residuals[used] ** 2)))
        self.velocity_enu[k] = rotation @ result.x[:3]
        covariance_enu = rotation @ result.covariance[:3, :3] @ rotation.T
        self.dop[k] = _dop(fit.design[used], rotation)
        self.speed_course_sigma[k] = speed_course_sigma(self.velocity_enu[k], covariance_enu)
        self.vertical_sigma_mps[k] = np.sqrt(covariance_enu[2, 2])
        shift = minimal_detectable_shift(
            fit.design[used],
            fit.sigma[used],
            fit.satellite[used],
            result.covariance,
            result.dof,
            alpha,
        )
        self.horizontal_protection_mps[k] = _horizontal_protection(shift[:, :3], rotation)
        plausible = vertical_velocity_plausible(self.velocity_enu[k], covariance_enu)
        n_sat = self.n_sat[k]
        self.verified[k] = result.passed and n_sat > MIN_SATELLITES and plausible
        self.untestable[k] = (
            n_sat == MIN_SATELLITES and (result.dof == 0 or result.passed) and plausible
        )

    def solution(self, t: np.ndarray, n_no_ephemeris: int) -> VelocitySolution:
        """The columns as a solution at epochs ``t``, valid where verified (before the
        continuity test)."""
        return VelocitySolution(
            t=t,
            velocity_ecef=self.velocity_ecef,
            velocity_enu=self.velocity_enu,
            clock_drift_mps=self.clock_drift_mps,
            covariance=self.covariance,
            dop=self.dop,
            n_sat=self.n_sat,
            n_obs=self.n_obs,
            n_excluded=self.n_excluded,
            residual_rms_mps=self.residual_rms_mps,
            valid=self.verified.copy(),
            n_no_ephemeris=n_no_ephemeris,
            verified=self.verified,
            untestable=self.untestable,
            speed_sigma_mps=self.speed_course_sigma[:, 0],
            course_sigma_rad=self.speed_course_sigma[:, 1],
            vertical_sigma_mps=self.vertical_sigma_mps,
            horizontal_protection_mps=self.horizontal_protection_mps,
        )


def _horizontal_protection(shift_ecef: np.ndarray, rotation: np.ndarray) -> float:
    """The largest horizontal (ENU) norm of the velocity shifts, one per satellite (inf if a
    satellite's bias cannot be detected at all)."""
    if not np.all(np.isfinite(shift_ecef)):
        return float("inf")
    horizontal = (shift_ecef @ rotation.T)[:, :2]
    return float(np.max(np.hypot(horizontal[:, 0], horizontal[:, 1])))


def vertical_velocity_plausible(velocity_enu: np.ndarray, covariance_enu: np.ndarray) -> bool:
    """Whether the vertical velocity v_u is one a land vehicle can have:
    |v_u| ≤ 3·√(P_uu + σ_g²), σ_g = √((g·s)² + f²) with s the horizontal speed, g
    ``GRADE_SIGMA`` and f ``VERTICAL_FLOOR_MPS``; P_uu the solution's own vertical variance.
    (Capping P_uu's share was tried for issue 29 and not kept: it removed the worst valid
    courses of the Hong Kong canyon drive, but the calibration lost good epochs elsewhere and
    the dead reckoning and the tightly coupled VO drifted more
    (docs/benchmarks.md, "The GNSS velocity's settings").)"""
    speed = np.hypot(velocity_enu[0], velocity_enu[1])
    prior = (GRADE_SIGMA * speed) ** 2 + VERTICAL_FLOOR_MPS**2
    return bool(abs(velocity_enu[2]) <= VERTICAL_GATE * np.sqrt(covariance_enu[2, 2] + prior))


def speed_course_sigma(velocity_enu: np.ndarray, covariance_enu: np.ndarray) -> np.ndarray:
    """σ of the horizontal speed (m/s) and of the course (rad) by first-order propagation:
    the horizontal covariance projected on the unit vectors along and across the velocity
    (the course σ is the across σ over the speed)."""
    east, north = velocity_enu[:2]
    speed = np.hypot(east, north)
    if not speed > 0.0:
        return np.array([np.sqrt(np.trace(covariance_enu[:2, :2]) / 2.0), np.inf])
    along = np.array([east, north]) / speed
    across = np.array([-north, east]) / speed
    horizontal = covariance_enu[:2, :2]
    return np.sqrt([along @ horizontal @ along, across @ horizontal @ across / speed**2])


def _dop(H: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """GDOP, PDOP, HDOP, VDOP, TDOP of a velocity design matrix (rows [−e, 1])."""
    q = np.linalg.inv(H.T @ H)
    q_enu = rotation @ q[:3, :3] @ rotation.T
    return np.sqrt(
        [
            np.trace(q),
            np.trace(q[:3, :3]),
            q_enu[0, 0] + q_enu[1, 1],
            q_enu[2, 2],
            q[3, 3],
        ]
    )


def doppler_velocity(
    obs: Observations,
    source: StateSource,
    receiver_ecef: np.ndarray,
    **row_options,
) -> tuple[VelocitySolution, DopplerRows]:
    """Rows (``doppler_rows`` with ``row_options``: systems, bands, elevation_mask_rad,
    reported_sigma) and the per-epoch solution (``solve_velocity``) in one call."""
    rows = doppler_rows(obs, source, receiver_ecef, **row_options)
    return solve_velocity(rows, obs.epoch_time), rows


def solve_with_fitted_noise(
    rows: DopplerRows, epoch_time: np.ndarray
) -> tuple[VelocitySolution, DopplerRows, dict[tuple[str, str], NoiseModel]]:
    """Solve with the rows' σ, then ``NOISE_PASSES`` times: fit the σ(C/N0, elevation) model
    of each signal to the residuals (``noise_model.fit_noise_models``), scale it per satellite
    by the robust scale of that satellite's residuals in units of the model
    (``doppler_noise.fitted_sigma``), solve again. Every row gets a fitted σ, the receiver's
    reported one included: on the comma2k19 u-blox those are powers of two, one value over a
    wide band of C/N0 across which the residuals' scatter changes several times over. Passes,
    because the first residuals still carry the pull of the noisy rows weighted by the prior:
    on comma2k19 the fitted σ still falls after the first pass
    (docs/benchmarks.md, "The GNSS velocity's settings")."""
    prior = rows.sigma()
    solution = solve_velocity(rows, epoch_time)
    models: dict[tuple[str, str], NoiseModel] = {}
    for _ in range(NOISE_PASSES):
        models = fit_noise_models(rows, solution)
        modelled = modelled_sigma(models, rows, prior)
        rows = replace(rows, weight=fitted_sigma(rows, solution, modelled, modelled) ** -2.0)
        solution = solve_velocity(rows, epoch_time)
    return solution, rows, models
