"""One scalar signal sampled in time: yaw rate, wheel speed, any ``t,value`` sensor record."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.errors import InputError


@dataclass
class SensorSeries:
    """One scalar sensor signal: sample times ``t`` (s, strictly increasing) and ``value`` (SI
    units), both 1-D, of equal length and finite; empty is allowed.

    Checked on construction (:class:`~vo_doppler.errors.InputError` naming the series and the
    first bad sample), because every stage interpolates and integrates the signal: one NaN
    value spreads through the integral from its sample on, and unsorted times make the
    interpolation meaningless, both giving silently empty or wrong results far from the cause.
    No stage reads NaN as "missing": a sample without a value is left out, as the readers do
    (``n_skipped`` counts them). ``t`` and ``value`` are float64 copies of the arrays given,
    so that a later change to the caller's arrays cannot bypass the check, and the series
    cannot change its caller's data. (Writeable, not read-only: SciPy 1.17's ``Rotation``
    refuses read-only arrays, and a series' arrays go wherever the user takes them.)
    """

    t: np.ndarray
    value: np.ndarray
    name: str = ""
    unit: str = ""
    n_skipped: int = 0
    """Input rows the reader could not use (unreadable or non-finite)."""

    def __post_init__(self) -> None:
        self.t = np.array(self.t, dtype=float)
        self.value = np.array(self.value, dtype=float)
        self._check()

    def _check(self) -> None:
        """Raise an :class:`InputError` unless the invariants of the class docstring hold."""
        what = f"sensor series {self.name!r}" if self.name else "sensor series"
        for field_name, array in (("t", self.t), ("value", self.value)):
            if array.ndim != 1:
                raise InputError(f"{what}: {field_name} must be 1-D, not of shape {array.shape}")
        if len(self.t) != len(self.value):
            raise InputError(f"{what}: {len(self.t)} times but {len(self.value)} values")
        bad = np.flatnonzero(~np.isfinite(self.t))
        if bad.size:
            k = int(bad[0])
            raise InputError(
                f"{what}: t[{k}] is {self.t[k]} ({bad.size} of {len(self.t)} times not finite)"
            )
        bad = np.flatnonzero(np.diff(self.t) <= 0)
        if bad.size:
            k = int(bad[0]) + 1
            raise InputError(
                f"{what}: times must increase strictly, but t[{k}] = {self.t[k]:.6f} s follows "
                f"t[{k - 1}] = {self.t[k - 1]:.6f} s ({bad.size} of {len(self.t)} samples): "
                "sort the samples and keep one per time"
            )
        bad = np.flatnonzero(~np.isfinite(self.value))
        if bad.size:
            k = int(bad[0])
            raise InputError(
                f"{what}: value[{k}] (t = {self.t[k]:.6f} s) is {self.value[k]} ({bad.size} of "
                f"{len(self.value)} values not finite): leave such samples out (no stage reads "
                "NaN as missing)"
            )

    def __len__(self) -> int:
        return len(self.t)

    def shifted(self, offset_s: float) -> SensorSeries:
        """The same samples with ``offset_s`` added to every time (sensor clock → GPS time)."""
        return SensorSeries(self.t + offset_s, self.value, self.name, self.unit, self.n_skipped)
