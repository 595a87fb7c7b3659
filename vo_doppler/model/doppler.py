"""Doppler rows: one row per (epoch, satellite, Doppler observable), the input of every Doppler
solver — the conventional velocity ([TK18] sec. 3.2) and the tightly coupled heading (sec. 3.5).

Sign conventions (stated once, used by every solver):

* ``los`` G is the unit vector from the receiver to the satellite;
* ``range_rate`` is the measured rate of change of the receiver–satellite range, −λ·D (m/s;
  RINEX 3.05 sec. 5.2.10: the Doppler is positive for approaching satellites);
* ``sat_clock_drift`` ρ_s and the receiver clock drift ρ are in m/s (c × clock rate);
* the range rate then reads ṙ = G·(v_s − v) + ρ − ρ_s, so the *reduced* observation
  y = ṙ − G·v_s + ρ_s = −G·v + ρ depends only on the receiver velocity v and clock drift ρ.

``frame`` states where the vectors (``los``, ``sat_velocity``, ``sat_position``) live: 'ecef'
(as the GNSS stage computes them, at the reception epoch) or 'enu' (the local frame at each
row's receiver position, :meth:`DopplerRows.in_enu`, what the heading solvers take).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields, replace
from enum import StrEnum

import numpy as np

from vo_doppler.geo import ecef_to_enu_rotation, ecef_to_geodetic


def _is_shareable(given: object, checked: np.ndarray) -> bool:
    """Whether ``given`` is a read-only array owning its data (another rows' array) that
    checking left as it was (same shape and type)."""
    return (
        isinstance(given, np.ndarray)
        and not given.flags.writeable
        and given.base is None
        and given.shape == checked.shape
        and given.dtype == checked.dtype
    )


def read_only(array: np.ndarray) -> np.ndarray:
    """``array`` made read-only: :class:`DopplerRows` take a new array of their own (one no one
    else writes) without copying it."""
    array.flags.writeable = False
    return array


class VectorFrame(StrEnum):
    """Where a :class:`DopplerRows`' vectors live (module docstring)."""

    ECEF = "ecef"
    ENU = "enu"


REQUIRED_ROW_COLUMNS = frozenset(
    {"t", "los", "sat_velocity", "sat_clock_drift", "range_rate", "weight", "sat_id"}
)
"""The columns every :class:`DopplerRows` has (its docstring says what each is)."""


@dataclass
class DopplerRows:
    """Doppler rows sorted by time. Required per row: ``t`` (GPS s), ``los``, ``sat_velocity``
    (N×3, in ``frame``), ``sat_clock_drift`` and ``range_rate`` (m/s), ``weight`` 1/σ² of the
    range rate ((m/s)⁻²) and ``sat_id`` ('G05'). The GNSS stage also fills the measurement's
    origin (``epoch`` index into the observation epochs, ``system``, ``prn``, ``code`` such as
    'D1C', ``wavelength_m``, ``cn0`` dB-Hz, ``elevation``/``azimuth`` rad, ``sat_position`` m,
    ``receiver_ecef`` the position used) and counts of rows it could not form.

    Every per-row array is read-only, so the rows stay sorted and shaped as checked on
    construction: an array given by the caller is copied, one of another rows' (read-only and
    owning its data) is shared. Rows derived from others (``dataclasses.replace``,
    :meth:`in_enu`) therefore hold only what changed: on a 30-min drive at 20 Hz the rows are
    about 28 MiB, a new weight 1 MiB.
    """

    t: np.ndarray
    los: np.ndarray
    sat_velocity: np.ndarray
    sat_clock_drift: np.ndarray
    range_rate: np.ndarray
    weight: np.ndarray
    sat_id: np.ndarray
    frame: VectorFrame = VectorFrame.ENU
    epoch: np.ndarray | None = None
    system: np.ndarray | None = None
    prn: np.ndarray | None = None
    code: np.ndarray | None = None
    wavelength_m: np.ndarray | None = None
    cn0: np.ndarray | None = None
    elevation: np.ndarray | None = None
    azimuth: np.ndarray | None = None
    sat_position: np.ndarray | None = None
    receiver_ecef: np.ndarray | None = None
    n_no_ephemeris: int = 0
    """Rows dropped for lack of a healthy ephemeris (``missing`` lists 'SAT@t' once each)."""
    n_no_wavelength: int = 0
    """Rows dropped because the carrier frequency is unknown (GLONASS channel)."""
    n_below_mask: int = 0
    missing: tuple[str, ...] = field(default=())

    def __post_init__(self) -> None:
        given = {f.name: getattr(self, f.name) for f in fields(self)}
        if self.frame not in tuple(VectorFrame):
            allowed = ", ".join(VectorFrame)
            raise ValueError(f"frame must be one of {allowed}, not {self.frame!r}")
        self.frame = VectorFrame(self.frame)
        self.t = np.asarray(self.t, dtype=float).reshape(-1)
        n = len(self.t)
        self.los = np.asarray(self.los, dtype=float).reshape(n, 3)
        self.sat_velocity = np.asarray(self.sat_velocity, dtype=float).reshape(n, 3)
        self.sat_clock_drift = np.broadcast_to(np.asarray(self.sat_clock_drift, dtype=float), n)
        self.range_rate = np.asarray(self.range_rate, dtype=float).reshape(n)
        self.weight = np.broadcast_to(np.asarray(self.weight, dtype=float), n)
        self.sat_id = np.asarray(self.sat_id).reshape(n)
        order = np.argsort(self.t, kind="stable") if np.any(np.diff(self.t) < 0) else None
        for name, value in self._row_arrays().items():
            if order is None and _is_shareable(given[name], value):
                setattr(self, name, given[name])
                continue
            setattr(self, name, read_only(np.array(value if order is None else value[order])))

    def __len__(self) -> int:
        return len(self.t)

    def _row_arrays(self) -> dict[str, np.ndarray]:
        n = len(self.t)
        return {
            f.name: getattr(self, f.name)
            for f in fields(self)
            if isinstance(getattr(self, f.name), np.ndarray)
            and getattr(self, f.name).shape[:1] == (n,)
        }

    def select(self, keep: np.ndarray) -> DopplerRows:
        """The rows where ``keep`` (mask or indices) selects (counts unchanged)."""
        return replace(
            self, **{name: read_only(value[keep]) for name, value in self._row_arrays().items()}
        )

    def required_only(self) -> DopplerRows:
        """The rows with their required columns alone (class docstring), the measurement's
        origin dropped and the counts kept: all that the heading stage reads. A run's heading
        stage takes these, 12 MiB less than all columns in ENU on a 30-min drive at 20 Hz
        (the velocity solver needs the origin too: each row's epoch, satellite, receiver)."""
        optional = [f.name for f in fields(self) if f.name not in REQUIRED_ROW_COLUMNS]
        return replace(self, **{name: None for name in optional if name in self._row_arrays()})

    def reduced(self) -> np.ndarray:
        """y = ṙ − G·v_s + ρ_s = −G·v + ρ (m/s)."""
        return (
            self.range_rate
            - np.einsum("ni,ni->n", self.los, self.sat_velocity)
            + self.sat_clock_drift
        )

    def sigma(self) -> np.ndarray:
        """Standard deviation of each range rate (m/s), 1/√weight."""
        return 1.0 / np.sqrt(self.weight)

    def in_enu(self) -> DopplerRows:
        """The rows with their vectors turned into the ENU frame at each row's receiver."""
        if self.frame is VectorFrame.ENU:
            return self
        if len(self) == 0:
            return replace(self, frame=VectorFrame.ENU)
        positions, inverse = np.unique(self.receiver_ecef, axis=0, return_inverse=True)
        lat, lon, _ = ecef_to_geodetic(positions)
        rotations = np.stack(
            [
                ecef_to_enu_rotation(a, b)
                for a, b in zip(np.atleast_1d(lat), np.atleast_1d(lon), strict=True)
            ]
        )[inverse.reshape(-1)]

        def turn(vectors: np.ndarray | None) -> np.ndarray | None:
            return None if vectors is None else np.einsum("nij,nj->ni", rotations, vectors)

        return replace(
            self,
            los=turn(self.los),
            sat_velocity=turn(self.sat_velocity),
            sat_position=None,
            frame=VectorFrame.ENU,
        )
