"""Where the GNSS stage takes satellite states from: broadcast ephemerides (a navigation file)
or precise orbits and clocks (SP3 + RINEX clock), behind one small protocol, so that SPP, the
Doppler rows and the heading never branch on the source.

Every function of the stage accepts a :data:`StateSource` (a ``Navigation``, a
``PreciseOrbits`` or an object following :class:`SatelliteSource`) and turns it into a
source once with :func:`satellite_source`.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass, fields
from typing import Protocol

import numpy as np

from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.gnss.ephemeris import SatelliteStates, rotate_earth, satellite_states
from vo_doppler.gnss.precise_orbits import LAGRANGE_POINTS, precise_states
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.precise_orbits import PreciseOrbits
from vo_doppler.model.signals import beidou_signal

log = logging.getLogger(__name__)

STATES_CHUNK = 8192
"""Rows of satellite states computed at once. Each row gathers its ephemeris' parameters and
their intermediate results (about 100 numbers), so the states of a whole drive in one call
grew with its duration (a 30-min drive's 200,000 Doppler rows: about 130 MB at once); in
chunks the GNSS stage's peak memory stays flat in the duration, with the same results."""

_GROUP_DELAY_FIELD = {("G", "1"): "tgd", ("J", "1"): "tgd", ("E", "1"): "iodc"}
"""Navigation record column of the group delay per (system, band) of the pseudorange: the GPS
and QZSS L1 T_GD (IS-GPS-200 sec. 20.3.3.3.3.2), Galileo's BGD(E1, E5b) (RINEX's IODC slot)."""
BEIDOU_GROUP_DELAY_FIELD: dict[str, str | None] = {"B1I": "tgd", "B2I": "iodc", "B3I": None}
"""BeiDou D1/D2 record column of the group delay per signal (``model.signals.beidou_signal``).
The broadcast clock is B3I's: Δt_sv(B1I) = Δt_sv − T_GD1, Δt_sv(B2I) = Δt_sv − T_GD2, B3I none
(BDS-SIS-ICD-B1I-3.0 sec. 5.2.4.9–5.2.4.10, the D1 clock correction and equipment group delay
differential; T_GD2 and B2I in BDS-SIS-ICD-2.0, the B1I + B2I edition). A RINEX 3 BeiDou record
holds T_GD1 where GPS has T_GD (``tgd``) and T_GD2 where GPS has IODC (``iodc``; BROADCAST
ORBIT-6, "TGD1 B1/B3", "TGD2 B2/B3"). The other signals' group delays (B1C's ISC_B1Cd and
T_GD,B1Cp: BDS-SIS-ICD-B1C-1.0 sec. 7.6; B2a's likewise) come in the B-CNAV messages, which a
D1/D2 record does not carry."""


class SatelliteSource(Protocol):
    """What the GNSS stage needs from a source of satellite states."""

    @property
    def klobuchar(self) -> np.ndarray | None:
        """Broadcast ionosphere coefficients (α₀…α₃, β₀…β₃), None when the source has none."""

    def states(self, system, prn, t) -> SatelliteStates:
        """Satellite states at GPS times ``t`` (s), arrays broadcast (``ephemeris`` docstring)."""

    def group_delay_s(
        self,
        system: np.ndarray,
        states: SatelliteStates,
        codes: dict[str, str],
        rinex_version: float,
    ) -> np.ndarray:
        """Group delay (s) to subtract from the satellite clock for the pseudorange ``codes``
        chosen per system, written in an observation file of ``rinex_version`` (BeiDou's band
        digits depend on it; IS-GPS-200 sec. 20.3.3.3.3.2)."""

    def glonass_channels(self) -> dict[int, int]:
        """GLONASS frequency channel per slot, as far as the source knows them."""


@dataclass(frozen=True)
class BroadcastSource:
    """Broadcast ephemerides (``ephemeris.satellite_states``) and their group delays."""

    nav: Navigation

    @property
    def klobuchar(self) -> np.ndarray | None:
        return self.nav.klobuchar

    def states(self, system, prn, t) -> SatelliteStates:
        return states_in_chunks(lambda *rows: satellite_states(self.nav, *rows), system, prn, t)

    def group_delay_s(
        self,
        system: np.ndarray,
        states: SatelliteStates,
        codes: dict[str, str],
        rinex_version: float,
    ) -> np.ndarray:
        """The broadcast T_GD/BGD of each row's pseudorange (:data:`BEIDOU_GROUP_DELAY_FIELD`,
        ``_GROUP_DELAY_FIELD``), 0 where the record has none; a BeiDou code whose correction
        no D1/D2 record carries gets none, and one warning."""
        delay = np.zeros(system.size)
        for letter, code in codes.items():
            hit = (system == letter) & states.valid
            if not hit.any():
                continue
            if letter == "C":
                signal = beidou_signal(code, rinex_version)
                if signal not in BEIDOU_GROUP_DELAY_FIELD:
                    log.warning(
                        "BeiDou %s pseudoranges (%s in RINEX %.2f): no broadcast group delay "
                        "for them in a D1/D2 ephemeris, their satellite clocks are left "
                        "uncorrected (metres of bias)",
                        signal or "unknown-signal",
                        code,
                        rinex_version,
                    )
                    continue
                name = BEIDOU_GROUP_DELAY_FIELD[signal]
            else:
                name = _GROUP_DELAY_FIELD.get((letter, code[1:2]))
            if name is not None:
                delay[hit] = self.nav.kepler[name][states.record[hit]]
        return delay

    def glonass_channels(self) -> dict[int, int]:
        return self.nav.glonass_channels()


@dataclass(frozen=True)
class PreciseSource:
    """Precise orbits and clocks (``precise_orbits.precise_states``). The products' clocks
    refer to the ionosphere-free code combination; no differential code bias is applied for
    single-frequency pseudoranges (a few ns, within the SPP error budget; Doppler is unaffected).
    """

    orbits: PreciseOrbits
    n_points: int = LAGRANGE_POINTS

    @property
    def klobuchar(self) -> np.ndarray | None:
        return None

    def states(self, system, prn, t) -> SatelliteStates:
        return states_in_chunks(
            lambda *rows: precise_states(self.orbits, *rows, self.n_points), system, prn, t
        )

    def group_delay_s(
        self,
        system: np.ndarray,
        states: SatelliteStates,
        codes: dict[str, str],
        rinex_version: float,
    ) -> np.ndarray:
        return np.zeros(system.size)

    def glonass_channels(self) -> dict[int, int]:
        return {}


StateSource = Navigation | PreciseOrbits | SatelliteSource


def states_in_chunks(
    states: Callable[[np.ndarray, np.ndarray, np.ndarray], SatelliteStates], system, prn, t
) -> SatelliteStates:
    """``states(system, prn, t)`` (flat arrays, one row each; the row results independent of
    the others) computed :data:`STATES_CHUNK` rows at a time and joined, arrays broadcast
    and flattened as ``ephemeris.satellite_states`` does."""
    system, prn, t = (
        np.ravel(a)
        for a in np.broadcast_arrays(np.asarray(system), np.asarray(prn), np.asarray(t, float))
    )
    if t.size <= STATES_CHUNK:
        return states(system, prn, t)
    parts = [
        states(system[k : k + STATES_CHUNK], prn[k : k + STATES_CHUNK], t[k : k + STATES_CHUNK])
        for k in range(0, t.size, STATES_CHUNK)
    ]
    joined = (np.concatenate([getattr(part, f.name) for part in parts]) for f in fields(parts[0]))
    return SatelliteStates(*joined)


def satellite_source(source: StateSource) -> SatelliteSource:
    """The source behind a navigation file, precise orbits, or a source already."""
    if isinstance(source, Navigation):
        return BroadcastSource(source)
    if isinstance(source, PreciseOrbits):
        return PreciseSource(source)
    return source


def transmit_states(
    source: StateSource,
    system,
    prn,
    t_receive,
    receiver_ecef: np.ndarray | None = None,
    pseudorange: np.ndarray | None = None,
) -> tuple[SatelliteStates, np.ndarray]:
    """Satellite states at signal transmission, in the ECEF frame of the reception epoch.

    With a pseudorange P the transmission time is t_tx = t_rx − P/c − Δt_sv (IS-GPS-200
    sec. 20.3.3.3.3.1; exact whatever the receiver clock error); without one, the travel time
    τ is solved by fixed point from the geometric range to ``receiver_ecef``. The Earth rotation
    during travel uses the geometric travel time when ``receiver_ecef`` is given (else P/c).
    Returns the states and the travel times τ (s).
    """
    source = satellite_source(source)
    t_receive = np.asarray(t_receive, dtype=float)
    system, prn, t_receive = np.broadcast_arrays(np.asarray(system), np.asarray(prn), t_receive)
    if pseudorange is not None:
        travel = np.asarray(pseudorange, dtype=float) / SPEED_OF_LIGHT
        first = source.states(system, prn, t_receive - travel)
        t_tx = t_receive - travel - np.nan_to_num(first.clock_bias_s)
        states = source.states(system, prn, t_tx)
    elif receiver_ecef is not None:
        travel = np.full(t_receive.shape, 0.075)
        for _ in range(3):
            states = source.states(system, prn, t_receive - travel)
            travel = _geometric_travel(states.position, travel, receiver_ecef)
    else:
        raise ValueError("need a pseudorange or a receiver position")
    if receiver_ecef is not None:
        travel = _geometric_travel(states.position, travel, receiver_ecef)
    rotated = SatelliteStates(
        rotate_earth(states.position, travel),
        rotate_earth(states.velocity, travel),
        states.clock_bias_s,
        states.clock_drift,
        states.valid,
        states.record,
    )
    return rotated, travel


def _geometric_travel(position, travel, receiver_ecef) -> np.ndarray:
    """Signal travel time from the range between the rotated satellite and the receiver."""
    distance = np.linalg.norm(rotate_earth(position, travel) - receiver_ecef, axis=-1)
    return np.nan_to_num(distance / SPEED_OF_LIGHT, nan=0.075)
