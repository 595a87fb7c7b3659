"""Satellite states tabulated per (epoch, satellite) by a data provider instead of ephemerides.

Google's GSDC ``device_gnss.csv`` gives, for every measurement, the satellite's ECEF position and
velocity at the signal's transmission time, expressed in the Earth-fixed frame *of that
transmission time* (checked on the Pixel 7 Pro fixture: the pseudorange residuals against the
file's own WLS position scatter 8.3 m with the Earth-rotation (Sagnac) correction applied and
17.8 m without), and the satellite clock bias and drift. ``time`` is the receive epoch (GPS s),
``travel_time_s`` the signal's travel time used to rotate into the reception frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.model.observations import lookup, row_keys


@dataclass(frozen=True)
class SatelliteTable:
    """One row per (receive epoch, satellite): ``position``/``velocity`` (N, 3) ECEF of the
    transmission instant, ``clock_bias_s`` (relativistic term included), ``clock_drift`` (s/s),
    ``travel_time_s``."""

    time: np.ndarray
    system: np.ndarray
    prn: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    clock_bias_s: np.ndarray
    clock_drift: np.ndarray
    travel_time_s: np.ndarray

    def __len__(self) -> int:
        return int(self.time.size)

    def rows_for(self, time, system, prn, tolerance_s: float = 1e-3) -> np.ndarray:
        """Index of the table row of each (epoch, satellite) query, −1 where none matches.

        Epochs match when they differ by less than ``tolerance_s``.
        """
        time = np.asarray(time, dtype=float)
        epochs = np.unique(self.time)
        nearest = np.clip(np.searchsorted(epochs, time), 0, max(epochs.size - 1, 0))
        previous = np.clip(nearest - 1, 0, None)
        if epochs.size:
            closer = np.abs(epochs[previous] - time) < np.abs(epochs[nearest] - time)
            nearest = np.where(closer, previous, nearest)
        near_time = epochs[nearest] if epochs.size else time
        matched = (
            np.abs(near_time - time) < tolerance_s if epochs.size else np.zeros(time.shape, bool)
        )
        mine = row_keys(epochs, self.time, self.system, self.prn)
        wanted = row_keys(epochs, near_time, system, prn)
        index = lookup(mine, np.arange(len(self), dtype=float), wanted)
        found = matched & np.isfinite(index)
        return np.where(found, np.nan_to_num(index, nan=-1), -1).astype(np.int64)
