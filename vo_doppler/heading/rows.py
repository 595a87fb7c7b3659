"""Doppler observations as flat rows: one row per satellite per epoch.

Sign conventions (stated once, used by every heading solver):

* ``los`` G is the unit vector from the receiver to the satellite;
* ``range_rate`` is the measured rate of change of the receiver–satellite range, −λ·D (m/s);
* ``sat_clock_drift`` ρ_s and the receiver clock drift ρ are in m/s (c × clock rate);
* the range rate then reads ṙ = G·(v_s − v) + ρ − ρ_s, so the *reduced* observation
  y = ṙ − G·v_s + ρ_s = −G·v + ρ depends only on the receiver velocity v and clock drift ρ
  (the conventional sec. 3.2 equation with its signs made explicit).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class DopplerRows:
    """Doppler rows sorted by epoch time; vectors in the local ENU frame (x east, y north, z up).

    ``weight`` is 1/σ² of the range rate in (m/s)⁻²; ``sat_id`` names the satellite (e.g. "G05").
    """

    t: np.ndarray
    los: np.ndarray
    sat_velocity: np.ndarray
    sat_clock_drift: np.ndarray
    range_rate: np.ndarray
    weight: np.ndarray
    sat_id: np.ndarray

    def __post_init__(self) -> None:
        self.t = np.asarray(self.t, dtype=float).reshape(-1)
        n = len(self.t)
        self.los = np.asarray(self.los, dtype=float).reshape(n, 3)
        self.sat_velocity = np.asarray(self.sat_velocity, dtype=float).reshape(n, 3)
        self.sat_clock_drift = np.broadcast_to(
            np.asarray(self.sat_clock_drift, dtype=float), (n,)
        ).copy()
        self.range_rate = np.asarray(self.range_rate, dtype=float).reshape(n)
        self.weight = np.broadcast_to(np.asarray(self.weight, dtype=float), (n,)).copy()
        self.sat_id = np.asarray(self.sat_id).reshape(n)
        if n and np.any(np.diff(self.t) < 0):
            order = np.argsort(self.t, kind="stable")
            for name in ("t", "los", "sat_velocity", "sat_clock_drift", "range_rate"):
                setattr(self, name, getattr(self, name)[order])
            self.weight, self.sat_id = self.weight[order], self.sat_id[order]

    def __len__(self) -> int:
        return len(self.t)

    @classmethod
    def from_ecef(
        cls,
        t,
        los_ecef,
        sat_velocity_ecef,
        sat_clock_drift,
        range_rate,
        weight,
        sat_id,
        ecef_to_enu: np.ndarray,
    ) -> DopplerRows:
        """Rows whose vectors are in ECEF; ``ecef_to_enu`` is (3, 3) or one matrix per row."""
        rotation = np.asarray(ecef_to_enu, dtype=float)
        spec = "ij,nj->ni" if rotation.ndim == 2 else "nij,nj->ni"
        los = np.einsum(spec, rotation, np.asarray(los_ecef, dtype=float).reshape(-1, 3))
        vel = np.einsum(spec, rotation, np.asarray(sat_velocity_ecef, dtype=float).reshape(-1, 3))
        return cls(t, los, vel, sat_clock_drift, range_rate, weight, sat_id)

    def reduced(self) -> np.ndarray:
        """y = ṙ − G·v_s + ρ_s = −G·v + ρ (m/s)."""
        return (
            self.range_rate
            - np.einsum("ni,ni->n", self.los, self.sat_velocity)
            + self.sat_clock_drift
        )

    def subset(self, index) -> DopplerRows:
        return DopplerRows(
            self.t[index],
            self.los[index],
            self.sat_velocity[index],
            self.sat_clock_drift[index],
            self.range_rate[index],
            self.weight[index],
            self.sat_id[index],
        )
