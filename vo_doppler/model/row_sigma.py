"""Receiver-reported standard deviations of observation rows (u-blox, Android, GSDC).

Kept beside :class:`~vo_doppler.model.observations.Observations` rather than inside it: a table
keyed by (epoch time, system, PRN, observable code) whose σ is in the unit of that observable's
value (Doppler ``D``: Hz, pseudorange ``C``: m, carrier ``L``: cycles). ``at`` joins it to any
rows of the same recording.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.model.observations import lookup, row_keys


@dataclass(frozen=True)
class RowSigma:
    """1σ per observation row: ``time`` (GPS s), ``system``, ``prn``, ``code`` (e.g. 'D1C')."""

    time: np.ndarray
    system: np.ndarray
    prn: np.ndarray
    code: np.ndarray
    sigma: np.ndarray

    def __len__(self) -> int:
        return int(self.sigma.size)

    def at(self, time, system, prn, code) -> np.ndarray:
        """σ of the given rows (``code`` as strings), NaN where the receiver reported none."""
        time = np.asarray(time, dtype=float)
        code = np.asarray(code, dtype="U3")
        epochs = np.unique(np.concatenate([self.time, time]))
        names = np.unique(np.concatenate([self.code.astype("U3"), code]))
        mine = row_keys(epochs, self.time, self.system, self.prn, np.searchsorted(names, self.code))
        wanted = row_keys(epochs, time, system, prn, np.searchsorted(names, code))
        return lookup(mine, self.sigma, wanted)
