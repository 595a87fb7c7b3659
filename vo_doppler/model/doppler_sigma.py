"""Receiver-reported standard deviations of Doppler range rates (u-blox RXM-RAWX ``doStdev``,
comma2k19's ``raw_gnss_ublox`` column, Android's ``PseudorangeRateUncertaintyMetersPerSecond``):
where present they replace the C/N0 model in the Doppler rows' weights."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

TIME_RESOLUTION_S = 1e-3


@dataclass(frozen=True)
class ReportedSigma:
    """σ of the range rate (m/s) per (epoch GPS time ``t``, ``sat_id`` 'G05', Doppler ``code``)."""

    t: np.ndarray
    sat_id: np.ndarray
    code: np.ndarray
    sigma_mps: np.ndarray

    def __len__(self) -> int:
        return int(self.t.size)

    def at(self, t: np.ndarray, sat_id: np.ndarray, code: np.ndarray) -> np.ndarray:
        """σ of each queried row (times matched to 1 ms), NaN where the receiver gave none."""
        table = {
            key: sigma
            for key, sigma in zip(
                _keys(self.t, self.sat_id, self.code), self.sigma_mps, strict=True
            )
        }
        return np.array([table.get(k, np.nan) for k in _keys(t, sat_id, code)], dtype=float)


def _keys(t, sat_id, code):
    ticks = np.round(np.asarray(t, dtype=float) / TIME_RESOLUTION_S).astype(np.int64)
    return list(
        zip(ticks.tolist(), np.asarray(sat_id).tolist(), np.asarray(code).tolist(), strict=True)
    )
