"""GPS and Galileo constellations from realistic Keplerian elements → broadcast ephemerides.

GPS: six orbital planes (A–F) 60° apart in right ascension, inclination ≈ 55°, semi-major axis
26 559.7 km (half a sidereal day), 31 satellites (the 24 baseline slots plus expansion slots,
SPS Performance Standard 2020 sec. 3.2), eccentricities 0.002–0.02. Galileo: Walker 24/3/1 at
56°, 29 599.8 km (OS SIS ICD sec. 2.3 / the nominal constellation), near-circular. Slot phases
carry a few degrees of deterministic jitter; the harmonic corrections (C_uc … C_is), Δn, Ω̇,
IDOT and clock terms are drawn within the ranges seen in real broadcast messages. The
constellation is fixed (its own seed), so every simulation sees the same sky at a given time.

Each satellite gets one ephemeris per ``toe`` (every two hours, the GPS practice), generated
from the same slot at reference epoch :data:`REFERENCE_EPOCH`: mean anomaly and right ascension
are propagated from the reference to ``toe`` with the mean motion and Ω̇, so the sky moves
correctly with the chosen start time. The broadcast model itself *is* the truth of the
simulation: satellite states come from :func:`vo_doppler.gnss.ephemeris.satellite_states` on
the values as written to the file (rounded to the D19.12 format), never from a second model.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from vo_doppler.gnss.ephemeris import MU, OMEGA_E
from vo_doppler.io.rinex_nav import KEPLER_FIELDS
from vo_doppler.io.rinex_write import KeplerRecord, rounded_nav_value
from vo_doppler.model.gpstime import SECONDS_PER_WEEK, calendar_to_gps_seconds, time_of_week
from vo_doppler.model.navigation import Navigation, NavRecords

REFERENCE_EPOCH = float(calendar_to_gps_seconds(2025, 3, 14, 0, 0, 0))
"""GPS seconds of the epoch at which slot phases and right ascensions are defined."""
CONSTELLATION_SEED = 19780222
TOE_SPACING_S = 7200.0
GROUP_DELAY_FIELD = {"G": "tgd", "E": "iodc"}
"""Field holding the L1/E1 group delay (GPS T_GD; Galileo I/NAV BGD(E1,E5b))."""

_GPS_PRNS = (
    (4, 31, 30, 7, 25),
    (2, 19, 1, 12, 26),
    (8, 10, 13, 6, 28),
    (3, 14, 24, 18, 29),
    (11, 20, 5, 21, 16, 32),
    (9, 23, 27, 15, 17),
)
_GAL_PRNS = (
    (1, 2, 3, 4, 5, 7, 8, 9),
    (10, 11, 12, 13, 14, 15, 19, 21),
    (24, 25, 26, 27, 30, 31, 33, 34),
)
KLOBUCHAR = np.array(
    [1.1176e-08, 7.4506e-09, -5.9605e-08, -5.9605e-08, 9.0112e04, 1.6384e04, -1.9661e05, -6.5536e04]
)
"""Broadcast ionosphere coefficients α0–α3, β0–β3 of a mid-activity day."""


@dataclass(frozen=True)
class Slot:
    """A satellite's mean orbit at :data:`REFERENCE_EPOCH` plus its per-satellite constants."""

    system: str
    prn: int
    sqrt_a: float
    e: float
    i0: float
    raan: float
    omega: float
    mean_anomaly: float
    extras: dict[str, float]


def _slots() -> list[Slot]:
    rng = np.random.default_rng(CONSTELLATION_SEED)
    slots = []
    for plane, prns in enumerate(_GPS_PRNS):
        phases = 360.0 * np.arange(len(prns)) / len(prns) + 17.0 * plane
        for prn, phase in zip(prns, phases, strict=True):
            slots.append(_slot(rng, "G", prn, 26_559_700.0, plane * 60.0 + 272.8, phase, 55.0))
    for plane, prns in enumerate(_GAL_PRNS):
        for k, prn in enumerate(prns):
            phase = 45.0 * k + 15.0 * plane
            slots.append(_slot(rng, "E", prn, 29_599_800.0, plane * 120.0 + 25.0, phase, 56.0))
    return slots


def _slot(rng, system, prn, a, raan_deg, phase_deg, inclination_deg) -> Slot:
    gps = system == "G"
    e = rng.uniform(0.002, 0.02) if gps else rng.uniform(1e-4, 6e-4)
    omega = rng.uniform(-np.pi, np.pi)
    u = np.radians(phase_deg + rng.normal(0.0, 3.0))
    extras = {
        "delta_n": rng.normal(4.5e-9, 5e-10) if gps else rng.normal(3.0e-9, 3e-10),
        "omega_dot": rng.normal(-8.0e-9, 3e-10) if gps else rng.normal(-5.6e-9, 1e-10),
        "idot": rng.normal(0.0, 2.5e-10),
        "cuc": rng.normal(0.0, 4e-6),
        "cus": rng.normal(0.0, 4e-6),
        "crs": rng.normal(0.0, 60.0),
        "crc": rng.uniform(150.0, 350.0),
        "cic": rng.normal(0.0, 8e-8),
        "cis": rng.normal(0.0, 8e-8),
        "af0": rng.uniform(-4e-4, 4e-4),
        "af1": rng.normal(0.0, 4e-12),
        "group_delay": rng.uniform(-1e-8, 1e-8) if gps else rng.uniform(-5e-9, 5e-9),
    }
    return Slot(
        system,
        prn,
        float(np.sqrt(a)),
        e,
        np.radians(inclination_deg + rng.normal(0.0, 0.8 if gps else 0.3)),
        np.radians(raan_deg + rng.normal(0.0, 1.0)),
        omega,
        u - omega,
        extras,
    )


def _wrap(angle: float) -> float:
    return float((angle + np.pi) % (2.0 * np.pi) - np.pi)


def broadcast_record(slot: Slot, toe: float, iode: int) -> KeplerRecord:
    """The slot's broadcast ephemeris with reference time ``toe`` (GPS s), values as written.

    Mean anomaly M0 = M_ref + n·(toe − t_ref); Ω0 (right ascension at the start of the week,
    IS-GPS-200 Table 20-IV: Ω_k = Ω0 + (Ω̇ − Ω̇_e)·t_k − Ω̇_e·t_oe) places the node at its
    inertial right ascension Ω_ref + Ω̇·(toe − t_ref), Greenwich being at 0 at t_ref.
    """
    mu, omega_e = MU[slot.system], OMEGA_E[slot.system]
    x = slot.extras
    n = np.sqrt(mu / slot.sqrt_a**6) + x["delta_n"]
    week, toe_sow = time_of_week(toe)
    week_start = float(week) * SECONDS_PER_WEEK
    omega0 = (
        slot.raan
        + x["omega_dot"] * (toe - REFERENCE_EPOCH)
        + omega_e * (REFERENCE_EPOCH - week_start)
    )
    gps = slot.system == "G"
    params = {
        "af0": x["af0"],
        "af1": x["af1"],
        "af2": 0.0,
        "iode": float(iode),
        "crs": x["crs"],
        "delta_n": x["delta_n"],
        "m0": _wrap(slot.mean_anomaly + n * (toe - REFERENCE_EPOCH)),
        "cuc": x["cuc"],
        "e": slot.e,
        "cus": x["cus"],
        "sqrt_a": slot.sqrt_a,
        "toe_sow": float(toe_sow),
        "cic": x["cic"],
        "omega0": _wrap(omega0),
        "cis": x["cis"],
        "i0": slot.i0,
        "crc": x["crc"],
        "omega": slot.omega,
        "omega_dot": x["omega_dot"],
        "idot": x["idot"],
        "codes": 1.0 if gps else 517.0,
        "week": float(week),
        "l2p_flag": 0.0,
        "accuracy": 2.0 if gps else 3.12,
        "health": 0.0,
        "tgd": x["group_delay"] if gps else x["group_delay"] * 0.9,
        "iodc": float(iode) if gps else x["group_delay"],
        "transmission_sow": float(toe_sow) - 18.0,
        "fit_interval": 4.0 if gps else 0.0,
    }
    return KeplerRecord(
        slot.system, slot.prn, toe, {k: rounded_nav_value(v) for k, v in params.items()}
    )


def broadcast_ephemerides(t_start: float, t_end: float, systems: str = "GE") -> list[KeplerRecord]:
    """Records of every satellite of ``systems`` for each two-hour ``toe`` from the one at or
    before ``t_start`` to the one nearest ``t_end`` (so every time has a record ≤ 1 h old)."""
    first = np.floor(t_start / TOE_SPACING_S) * TOE_SPACING_S
    toes = np.arange(first, t_end + TOE_SPACING_S / 2, TOE_SPACING_S)
    records = []
    for slot in _slots():
        if slot.system not in systems:
            continue
        for toe in toes:
            iode = round(toe / TOE_SPACING_S) % 256
            records.append(broadcast_record(slot, float(toe), iode))
    return sorted(records, key=lambda r: (r.system, r.prn, r.toc))


def navigation_from_records(records: Sequence[KeplerRecord]) -> Navigation:
    """The in-memory :class:`Navigation` a reader makes of the written records."""
    names = [name for group in KEPLER_FIELDS for name in group]
    params = {name: np.array([r.params[name] for r in records]) for name in names}
    params["toe"] = np.array([r.toc for r in records])
    kepler = NavRecords(
        np.array([r.system for r in records], dtype="U1"),
        np.array([r.prn for r in records], dtype=np.int16),
        np.array([r.toc for r in records]),
        params,
        np.zeros(len(records), dtype=np.int64),
    )
    empty = NavRecords(
        np.zeros(0, dtype="U1"), np.zeros(0, dtype=np.int16), np.zeros(0), {}, np.zeros(0, int)
    )
    return Navigation(kepler, empty, klobuchar=KLOBUCHAR.copy())
