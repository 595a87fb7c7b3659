"""Pseudorange single-point positioning: position and one receiver clock per system, per epoch.

Model (IS-GPS-200 sec. 20.3.3.3.3): P = ρ + c·δt_r,sys − c·(δt_sv − T_GD) + T + ε with the
satellite state at transmission (``transmit_states``), Earth rotation during travel, the
Saastamoinen troposphere and the broadcast Klobuchar ionosphere (``atmosphere``); the positions
serve the line-of-sight vectors and the ENU origin. Gauss–Newton iterations, elevation
mask once the position is known, then chi-square fault exclusion (``lsq``) and a final pass
without the excluded rows.
"""

from __future__ import annotations

import logging
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace

import numpy as np

from vo_doppler.bounds import RECEIVER_RADIUS
from vo_doppler.errors import InputError
from vo_doppler.geo import SPEED_OF_LIGHT, ecef_to_enu_rotation, ecef_to_geodetic
from vo_doppler.gnss.atmosphere import L1_HZ, klobuchar_delay, troposphere_delay
from vo_doppler.gnss.doppler_noise import MIN_REDUNDANCY
from vo_doppler.gnss.ephemeris import rotate_earth
from vo_doppler.gnss.lsq import (
    DEFAULT_ALPHA,
    lsq_with_exclusion,
    minimal_detectable_shift,
    weighted_lsq,
)
from vo_doppler.gnss.pseudorange_noise import (
    SIGMA_PRIOR_M,
    PseudorangeNoiseModel,
    fit_pseudorange_noise,
    prior_sigma,
)
from vo_doppler.gnss.satellite_source import SatelliteSource, StateSource, satellite_source
from vo_doppler.gnss.signals import strength_code, wavelengths
from vo_doppler.model.gnss_solutions import SppSolution
from vo_doppler.model.observations import Observations, lookup, row_keys
from vo_doppler.model.signals import DEFAULT_SYSTEMS
from vo_doppler.model.timeseries import TIME_TOLERANCE_S

log = logging.getLogger(__name__)

PSEUDORANGE_PRIORITY = {
    "G": ("C1C", "C1W", "C1X", "C1", "P1", "C2W", "C2L", "C5Q", "P2"),
    "R": ("C1C", "C1P", "C1", "P1", "C2C", "C2P", "P2"),
    "E": ("C1C", "C1X", "C1B", "C1", "C5Q", "C5X", "C7Q", "C7X"),
    "C": ("C2I", "C2X", "C1I", "C7I", "C1P", "C1X", "C6I"),
    "J": ("C1C", "C1X", "C1", "C2L", "C5Q"),
    "S": ("C1C", "C1"),
    "I": ("C5A", "C9A"),
}
EARTH_SURFACE_M = RECEIVER_RADIUS.low
"""A position nearer the Earth's centre (m) is no receiver's: no solution, or zeros for none."""
SIGNAL_IN_SPACE_SIGMA_M = {"G": 0.6, "E": 0.4, "C": 1.0, "J": 0.6, "R": 1.8, "I": 2.0, "S": 2.0}
"""σ (m) of the broadcast orbit and clock along the line of sight per system (the signal-in-
space range errors of O. Montenbruck et al., "Multi-GNSS signal-in-space range error
assessment", GPS Solutions 22, 2018, rounded up; 2 m where not assessed)."""
IONOSPHERE_FRACTION = 0.5
TROPOSPHERE_SIGMA_M = 0.3


def pseudorange_codes(obs: Observations, systems: str) -> dict[str, str]:
    """The preferred pseudorange observable per system present in the file."""
    chosen = {}
    for system in systems:
        present = set(obs.codes_of(system))
        for code in PSEUDORANGE_PRIORITY.get(system, ()):
            if code in present:
                chosen[system] = code
                break
    return chosen


def no_system_message(obs: Observations, systems: str) -> str:
    """Why none of ``systems`` can be used: the systems whose pseudoranges the file holds."""
    in_file = "".join(sorted(set(np.unique(obs.system).tolist())))
    usable = "".join(pseudorange_codes(obs, in_file))
    message = f"the file has no pseudoranges of the systems {systems!r}"
    if usable:
        return message + f"; it has those of {usable} (e.g. --systems {usable})"
    return message + f"; it has none of any system (observations of {in_file or 'none'})"


def elevation_azimuth(
    receiver_ecef: np.ndarray, los: np.ndarray, lat_lon: tuple[float, float] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Elevation and azimuth (rad, azimuth clockwise from north) of unit vectors at receivers
    (``lat_lon`` of a single receiver may be passed to skip the geodetic conversion)."""
    if lat_lon is None:
        lat, lon, _ = ecef_to_geodetic(np.broadcast_to(receiver_ecef, los.shape))
    else:
        lat, lon = lat_lon
    lat, lon = np.atleast_1d(lat), np.atleast_1d(lon)
    east = np.stack([-np.sin(lon), np.cos(lon), np.zeros_like(lon)], axis=-1)
    north = np.stack([-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)], axis=-1)
    up = np.stack([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)], axis=-1)
    e, n, u = (np.sum(los * axis, axis=-1) for axis in (east, north, up))
    return np.arcsin(np.clip(u, -1.0, 1.0)), np.mod(np.arctan2(e, n), 2.0 * np.pi)


def solve_spp(
    obs: Observations,
    source: StateSource,
    systems: str = DEFAULT_SYSTEMS,
    elevation_mask_rad: float = np.deg2rad(10.0),
    fit_noise: bool = True,
    alpha: float = DEFAULT_ALPHA,
) -> SppSolution:
    """Single-point position per data epoch of ``obs`` (invalid epochs NaN, never guessed),
    satellite states from ``source`` (broadcast or precise, ``satellite_source``).

    Integrity (as the Doppler velocity's, ``doppler_velocity.solve_velocity``): unless
    ``fit_noise`` is False, a first solution with the a-priori σ (``pseudorange_noise``) gives
    the residuals that fit each signal's σ(C/N0, elevation), and every epoch is solved again
    with those σ; an epoch is valid when it has redundancy and its weighted residuals pass the
    chi-square test at ``alpha`` (after at most a third of its rows excluded). Its σ
    (horizontal √(σ_e² + σ_n²), vertical σ_u) come from the weighted covariance, its
    protection levels from Baarda's minimal detectable bias (``lsq.minimal_detectable_shift``):
    the largest horizontal and vertical shifts a bias on one satellite could cause while the
    test would miss it more than once in five."""
    codes = pseudorange_codes(obs, systems)
    if not codes:
        raise InputError(no_system_message(obs, systems), obs.header.path)
    source = satellite_source(source)
    data, n_no_ephemeris = _epoch_rows(obs, source, codes)
    start = obs.header.approx_position
    if start is None or np.linalg.norm(start) < EARTH_SURFACE_M:
        start = np.zeros(3)
    model = _Model(sorted(codes), elevation_mask_rad, source.klobuchar, {}, alpha)
    fits = _solve_all(data, model, start)
    noise_models = {}
    if fit_noise:
        starts, table = _first_pass(data, fits, codes)
        noise_models = fit_pseudorange_noise(*table)
        model = replace(
            model,
            noise={s: noise_models[(s, c)] for s, c in codes.items() if (s, c) in noise_models},
        )
        fits = _solve_all(data, model, start, starts)
    return _solution(obs.epoch_time, fits, model.systems, n_no_ephemeris, noise_models, alpha)


def _epoch_rows(
    obs: Observations, source: SatelliteSource, codes: dict[str, str]
) -> tuple[_EpochRows, int]:
    """The pseudoranges of ``codes`` (system → code) with a healthy satellite state, by epoch,
    corrected for the satellite clock, with their carrier frequency and C/N0; and the count of
    those without a state. The satellite states at the receive time less the travel time give
    the satellite clock, and so the transmission time, at which the states are taken again.
    The arrays of the whole drive made on the way (the satellite states, twice) are let go
    before the epochs are solved, and the first states as soon as their clock is read."""
    rows = np.zeros(len(obs), dtype=bool)
    for system, code in codes.items():
        rows |= obs.mask(system, code)
    sel = obs.subset(rows & np.isfinite(obs.value) & (obs.value > 1e6))
    travel = sel.value / SPEED_OF_LIGHT
    clock_first = source.states(sel.system, sel.prn, sel.time - travel).clock_bias_s
    states = source.states(sel.system, sel.prn, sel.time - travel - np.nan_to_num(clock_first))
    group_delay = source.group_delay_s(sel.system, states, codes, obs.header.version)
    satellite_clock_m = SPEED_OF_LIGHT * (states.clock_bias_s - np.nan_to_num(group_delay))
    channels = {**source.glonass_channels(), **obs.header.glonass_channels}
    frequency = np.full(len(sel), L1_HZ)
    cn0 = np.full(len(sel), np.nan)
    for system, code in codes.items():
        hit = sel.system == system
        lam = wavelengths(sel.system[hit], sel.prn[hit], code, channels, obs.header.version)
        frequency[hit] = np.nan_to_num(SPEED_OF_LIGHT / lam, nan=L1_HZ)
        cn0[hit] = _signal_strength(obs, sel.subset(hit), strength_code(code))
    epoch = np.searchsorted(obs.epoch_time, sel.time)
    bounds = np.searchsorted(epoch, np.arange(obs.epoch_time.size + 1))
    healthy = states.valid
    flat = _EpochData(
        obs.epoch_time,
        states.position[healthy],
        (sel.value + satellite_clock_m)[healthy],
        sel.system[healthy],
        sel.prn[healthy],
        frequency[healthy],
        cn0[healthy],
    )
    starts = np.concatenate(([0], np.cumsum(healthy)))[bounds]
    return _EpochRows(flat, starts), int((~healthy).sum())


def _solution(t, fits, systems, n_no_ephemeris, noise_models, alpha) -> SppSolution:
    """The per-epoch fits as an :class:`SppSolution` (unsolved epochs NaN, not valid)."""
    n_epochs = t.size
    position = np.full((n_epochs, 3), np.nan)
    clocks = {s: np.full(n_epochs, np.nan) for s in systems}
    n_sat = np.zeros(n_epochs, dtype=np.int64)
    figures = np.full((n_epochs, 7), np.nan)
    valid = np.zeros(n_epochs, dtype=bool)
    for k, fit in enumerate(fits):
        if fit is None:
            continue
        valid[k] = fit.passed
        position[k] = fit.x
        for s, value in fit.clock.items():
            clocks[s][k] = value
        n_sat[k] = fit.n_used
        figures[k] = (fit.rms, fit.pdop, *_quality(fit, alpha))
    return SppSolution(
        t,
        position,
        clocks,
        n_sat,
        figures[:, 0],
        figures[:, 1],
        valid,
        n_no_ephemeris,
        verified=valid.copy(),
        hdop=figures[:, 2],
        horizontal_sigma_m=figures[:, 3],
        vertical_sigma_m=figures[:, 4],
        horizontal_protection_m=figures[:, 5],
        vertical_protection_m=figures[:, 6],
        noise_models=noise_models,
    )


def _signal_strength(obs: Observations, sel: Observations, code: str) -> np.ndarray:
    """C/N0 (dB-Hz) of the rows ``sel`` from the same satellite's ``code`` observable at the
    same epoch (NaN where the file has none)."""
    strength = obs.select(code=code)
    keys = row_keys(obs.epoch_time, strength.time, strength.system, strength.prn)
    return lookup(keys, strength.value, row_keys(obs.epoch_time, sel.time, sel.system, sel.prn))


@dataclass(frozen=True)
class _EpochData:
    """One epoch's pseudoranges, corrected for the satellite clock and group delay."""

    t: float
    sat_position: np.ndarray
    corrected_range: np.ndarray
    system: np.ndarray
    prn: np.ndarray
    frequency: np.ndarray
    cn0: np.ndarray


_ROW_FIELDS = ("sat_position", "corrected_range", "system", "prn", "frequency", "cn0")


@dataclass(frozen=True)
class _EpochRows:
    """Every epoch's rows with a healthy ephemeris: ``flat`` holds them all (its ``t`` the
    epochs' times), epoch ``k``'s from row ``bounds[k]`` to ``bounds[k + 1]``; each epoch's
    :class:`_EpochData` is made when its turn comes. One set of small arrays per epoch held
    for the whole drive cost about 1 kB each (36 MiB on a 30-min drive at 20 Hz)."""

    flat: _EpochData
    bounds: np.ndarray

    def __iter__(self) -> Iterator[_EpochData]:
        flat = self.flat
        for k, t in enumerate(flat.t):
            rows = slice(self.bounds[k], self.bounds[k + 1])
            yield _EpochData(t, *(getattr(flat, name)[rows] for name in _ROW_FIELDS))


@dataclass(frozen=True)
class _Model:
    systems: list[str]
    mask: float
    klobuchar: np.ndarray | None
    noise: dict[str, PseudorangeNoiseModel]
    """The fitted σ law per system (its pseudorange code); absent: the a-priori law."""
    alpha: float


@dataclass(frozen=True)
class _EpochFit:
    """One epoch's solution and what the integrity figures and the noise fit need of it:
    ``rows`` the data rows above the mask, their post-fit ``residual`` (m), ``spread`` the
    standard deviation of each residual in units of its σ (√r_i for a kept row, r_i its
    redundancy number, NaN below ``MIN_REDUNDANCY``; √(1 + h_ii) for an excluded one,
    predicted by the others) and
    ``elevation`` (rad); ``design``, ``sigma`` and ``groups`` of the kept rows."""

    x: np.ndarray
    clock: dict[str, float]
    n_used: int
    rms: float
    pdop: float
    passed: bool
    dof: int
    covariance: np.ndarray
    design: np.ndarray
    sigma: np.ndarray
    groups: np.ndarray
    rows: np.ndarray
    residual: np.ndarray
    spread: np.ndarray
    elevation: np.ndarray


def _solve_all(
    data: _EpochRows,
    model: _Model,
    start: np.ndarray,
    starts: tuple[np.ndarray, np.ndarray] | None = None,
) -> Iterator[_EpochFit | None]:
    """Every epoch in turn, each started from ``starts``' position where it marks the epoch
    solved (positions, mask), else from the last solution. One fit alive at a time: held for
    the whole drive, the fits (a dozen small arrays each) cost about 2.5 kB per epoch."""
    x = start
    for k, epoch in enumerate(data):
        here = starts[0][k] if starts is not None and starts[1][k] else x
        fit = _solve_epoch(epoch, model, here)
        yield fit
        if fit is not None:
            x = fit.x


def _first_pass(
    data: _EpochRows, fits: Iterable[_EpochFit | None], codes: dict[str, str]
) -> tuple[tuple[np.ndarray, np.ndarray], tuple[np.ndarray, ...]]:
    """The first solution's positions and which epochs it solved (the second pass's starts),
    and the (residual / spread, system, code, C/N0, elevation) of every row of its solved
    epochs, in epoch and row order: the normalised residuals that fit the noise models."""
    starts = np.zeros((data.flat.t.size, 3))
    solved = np.zeros(data.flat.t.size, dtype=bool)
    normalised = np.full(data.flat.corrected_range.size, np.nan)
    elevation = np.full(data.flat.corrected_range.size, np.nan)
    used = np.zeros(data.flat.corrected_range.size, dtype=bool)
    for k, fit in enumerate(fits):
        if fit is None:
            continue
        starts[k], solved[k] = fit.x, True
        rows = data.bounds[k] + fit.rows
        normalised[rows] = fit.residual / fit.spread
        elevation[rows] = fit.elevation
        used[rows] = True
    system = data.flat.system[used]
    code = np.array([codes[s] for s in system], dtype="U3")
    return (starts, solved), (normalised[used], system, code, data.flat.cn0[used], elevation[used])


def _solve_epoch(data: _EpochData, model: _Model, start: np.ndarray) -> _EpochFit | None:
    """Gauss–Newton with elevation mask and FDE; None when fewer than 3 + n_clock satellites."""
    keep = np.ones(data.corrected_range.size, dtype=bool)
    x = np.asarray(start, dtype=float).copy()
    clocks = np.zeros(len(model.systems))
    rows = _SystemRows.of(data, model)
    for _ in range(2):
        for _ in range(12):
            H, residual, sigma, keep_now, present, elevation = _linearise(
                data, model, rows, x, clocks, keep
            )
            if keep_now.sum() < 3 + present.sum():
                return None
            H = H[keep_now][:, np.r_[True, True, True, present]]
            dx, _, _ = weighted_lsq(H, residual[keep_now], sigma[keep_now])
            x += dx[:3]
            clocks[present] += dx[3:]
            if np.linalg.norm(dx[:3]) < 1e-4:
                break
        groups = np.char.add(data.system[keep_now], data.prn[keep_now].astype(str))
        result = lsq_with_exclusion(
            H, residual[keep_now], sigma[keep_now], groups, 3 + int(present.sum()), model.alpha
        )
        if not result.valid:
            return None
        if result.used.all():
            break
        keep[np.flatnonzero(keep_now)[~result.used]] = False
    if np.linalg.norm(x) < EARTH_SURFACE_M:
        return None
    used = result.used
    rms_value = float(np.sqrt(np.mean(result.residuals[used] ** 2)))
    pdop = float(np.sqrt(np.trace(np.linalg.inv(H.T @ H)[:3, :3])))
    clock = {s: clocks[i] for i, s in enumerate(model.systems) if present[i]}
    s = sigma[keep_now]
    leverage = np.einsum("ij,jk,ik->i", H, result.covariance, H) / s**2
    redundancy = np.where(used, 1.0 - leverage, np.nan)
    spread = np.where(
        used,
        np.sqrt(np.where(redundancy >= MIN_REDUNDANCY, np.minimum(redundancy, 1.0), np.nan)),
        np.sqrt(1.0 + leverage),
    )
    return _EpochFit(
        x,
        clock,
        int(used.sum()),
        rms_value,
        pdop,
        result.passed,
        result.dof,
        result.covariance,
        H[used],
        s[used],
        groups[used],
        np.flatnonzero(keep_now),
        result.residuals,
        spread,
        elevation[keep_now],
    )


def _quality(fit: _EpochFit, alpha: float) -> tuple[float, float, float, float, float]:
    """HDOP (unweighted geometry), √(σ_e² + σ_n²) and σ_u (weighted covariance), and the
    horizontal and vertical protection levels (module docstring of ``lsq``) at the fix."""
    lat, lon, _ = ecef_to_geodetic(fit.x)
    rotation = ecef_to_enu_rotation(float(lat), float(lon))
    geometry = np.linalg.inv(fit.design.T @ fit.design)[:3, :3]
    hdop = np.sqrt(np.trace((rotation @ geometry @ rotation.T)[:2, :2]))
    weighted = rotation @ fit.covariance[:3, :3] @ rotation.T
    shift = minimal_detectable_shift(
        fit.design, fit.sigma, fit.groups, fit.covariance, fit.dof, alpha
    )[:, :3]
    if np.all(np.isfinite(shift)):
        enu = shift @ rotation.T
        horizontal = float(np.max(np.hypot(enu[:, 0], enu[:, 1])))
        vertical = float(np.max(np.abs(enu[:, 2])))
    else:
        horizontal = vertical = float("inf")
    return (
        float(hdop),
        float(np.sqrt(np.trace(weighted[:2, :2]))),
        float(np.sqrt(weighted[2, 2])),
        horizontal,
        vertical,
    )


def signal_in_space_sigma(system: np.ndarray) -> np.ndarray:
    """σ (m) of the broadcast orbit and clock of each row's system (``SIGNAL_IN_SPACE_SIGMA_M``,
    2 m for a system it does not list)."""
    return np.array([SIGNAL_IN_SPACE_SIGMA_M.get(str(s), 2.0) for s in system])


def model_error_sigma(
    orbit_clock: np.ndarray, elevation: np.ndarray, ionosphere_m: np.ndarray
) -> np.ndarray:
    """σ (m) of the errors of the models behind a pseudorange that its epoch's residuals do not
    show (common to the satellites, slowly varying), added to the fitted noise in quadrature:
    the broadcast orbit and clock (``orbit_clock``, :func:`signal_in_space_sigma`), half of the
    broadcast ionospheric delay (the Klobuchar model corrects about half of it, IS-GPS-200
    sec. 20.3.3.5.2.5) and the troposphere's residual 0.3 m / (sin el + 0.1) (the budget of
    RTKLIB's ``pntpos``, T. Takasu, RTKLIB 2.4.2 manual, appendix E.6)."""
    troposphere = TROPOSPHERE_SIGMA_M / (np.sin(elevation) + 0.1)
    return np.sqrt(orbit_clock**2 + (IONOSPHERE_FRACTION * ionosphere_m) ** 2 + troposphere**2)


@dataclass(frozen=True)
class _SystemRows:
    """An epoch's rows by system, the same at every iteration: the clock columns (rows ×
    systems, one-hot), the rows of each system with a noise model and the σ of each row's
    broadcast orbit and clock."""

    one_hot: np.ndarray
    noise_rows: dict[str, np.ndarray]
    orbit_clock: np.ndarray

    @classmethod
    def of(cls, data: _EpochData, model: _Model) -> _SystemRows:
        one_hot = np.stack([data.system == s for s in model.systems], axis=1).astype(float)
        noise_rows = {system: data.system == system for system in model.noise}
        return cls(one_hot, noise_rows, signal_in_space_sigma(data.system))


def _linearise(data: _EpochData, model: _Model, rows: _SystemRows, x, clocks, keep):
    travel = np.linalg.norm(data.sat_position - x, axis=1) / SPEED_OF_LIGHT
    vector = rotate_earth(data.sat_position, travel) - x
    rho = np.linalg.norm(vector, axis=1)
    los = vector / rho[:, None]
    keep_now = keep.copy()
    sigma = np.full(rho.size, SIGMA_PRIOR_M)
    atmosphere = np.zeros(rho.size)
    elevation = np.full(rho.size, np.pi / 2)
    if np.linalg.norm(x) > EARTH_SURFACE_M:
        lat, lon, height = (float(v) for v in ecef_to_geodetic(x))
        elevation, azimuth = elevation_azimuth(x, los, (lat, lon))
        keep_now &= elevation >= model.mask
        sigma = prior_sigma(elevation)
        for system, noise in model.noise.items():
            hit = rows.noise_rows[system]
            sigma[hit] = noise.sigma(data.cn0[hit], elevation[hit])
        troposphere = troposphere_delay(lat, height, elevation)
        ionosphere = np.zeros(rho.size)
        if model.klobuchar is not None:
            ionosphere = klobuchar_delay(
                model.klobuchar, lat, lon, elevation, azimuth, data.t, data.frequency
            )
        atmosphere = troposphere + ionosphere
        if model.noise:
            sigma = np.hypot(sigma, model_error_sigma(rows.orbit_clock, elevation, ionosphere))
    one_hot = rows.one_hot
    present = one_hot[keep_now].any(axis=0)
    predicted = rho + one_hot @ clocks + atmosphere
    H = np.hstack([-los, one_hot])
    return H, data.corrected_range - predicted, sigma, keep_now, present, elevation


def receiver_positions(solution: SppSolution, fallback: np.ndarray | None) -> np.ndarray:
    """One position per epoch: the SPP fix, else the nearest valid fix in time, else
    ``fallback`` (e.g. the RINEX approximate position); NaN rows when none exists."""
    out = solution.position_ecef.copy()
    valid = solution.valid
    if valid.any():
        good = np.flatnonzero(valid)
        missing = ~valid
        nearest = good[nearest_time(solution.t[good], solution.t[missing])]
        out[missing] = solution.position_ecef[nearest]
    elif fallback is not None and np.linalg.norm(fallback) > EARTH_SURFACE_M:
        out[:] = fallback
    return out


def nearest_time(sorted_t: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Index into ascending times ``sorted_t`` (non-empty) of the nearest to each of ``t``: on a
    tie the earlier, among equal times the first, as ``argmin`` over all pairs would choose,
    in O((n + m) log n) time and O(m) memory instead of an (m × n) table. Distances within
    :data:`~vo_doppler.model.timeseries.TIME_TOLERANCE_S` are a tie: an epoch midway between
    two fixes takes the earlier whatever the time origin (at GPS seconds shifted by 10⁹ s the
    rounding of the times chose the later for some, 42 m away on the sample; issue 30)."""
    last = sorted_t.size - 1
    after = np.searchsorted(sorted_t, t)
    before = np.searchsorted(sorted_t, sorted_t[np.maximum(after - 1, 0)])
    after = np.searchsorted(sorted_t, sorted_t[np.minimum(after, last)])
    use_before = np.abs(t - sorted_t[before]) <= np.abs(t - sorted_t[after]) + TIME_TOLERANCE_S
    return np.where(use_before, before, after)
