"""One scalar signal sampled in time: yaw rate, wheel speed, any ``t,value`` sensor record."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class SensorSeries:
    """One scalar sensor signal: sample times ``t`` (s, sorted) and ``value`` (SI units)."""

    t: np.ndarray
    value: np.ndarray
    name: str = ""
    unit: str = ""
    n_skipped: int = 0
    """Input rows the reader could not use (unreadable or non-finite)."""

    def __post_init__(self) -> None:
        self.t = np.asarray(self.t, dtype=float).reshape(-1)
        self.value = np.asarray(self.value, dtype=float).reshape(-1)
        if len(self.t) != len(self.value):
            raise ValueError(f"{len(self.t)} times but {len(self.value)} values")

    def __len__(self) -> int:
        return len(self.t)

    def shifted(self, offset_s: float) -> SensorSeries:
        """The same samples with ``offset_s`` added to every time (sensor clock → GPS time)."""
        return SensorSeries(
            self.t + offset_s, self.value.copy(), self.name, self.unit, self.n_skipped
        )
