"""Observations from per-row measurements of a non-RINEX receiver format (UBX, Android, GSDC).

Readers of binary or CSV formats collect one row per (epoch, satellite, observable) with a
RINEX 3 observable code (``C1C``, ``L1C``, ``D1C``, ``S1C`` …) and pass them here: rows with a
non-finite value are dropped, the rest sorted by epoch, system, PRN and code, a row repeating an
earlier row's (epoch, satellite, code) is dropped and counted in ``problems`` (the file's first
value kept), and a RINEX-3-like header is synthesised (version 3.05, mixed system, signal
strength in dB-Hz, GPS time).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.model.observations import Observations, ObsHeader


def observations_from_rows(
    path: Path,
    receiver_type: str,
    time: np.ndarray,
    system: np.ndarray,
    prn: np.ndarray,
    code: np.ndarray,
    value: np.ndarray,
    lli: np.ndarray | None = None,
    glonass_channels: dict[int, int] | None = None,
    problems: tuple[str, ...] = (),
    n_lines: int = 0,
    row_fields: dict[str, np.ndarray] | None = None,
) -> Observations:
    """Columnar :class:`Observations` from flat row arrays (``code`` as RINEX 3 strings);
    ``row_fields`` (per-row arrays of the same length, by name) follow their rows."""
    time = np.asarray(time, dtype=float)
    value = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(time)):
        raise InputError("non-finite epoch time", path)
    lli = np.full(time.shape, -1, dtype=np.int8) if lli is None else np.asarray(lli, np.int8)
    keep = np.isfinite(value)
    time, value, lli = time[keep], value[keep], lli[keep]
    extra = {name: np.asarray(v)[keep] for name, v in (row_fields or {}).items()}
    system = np.asarray(system, dtype="U1")[keep]
    prn = np.asarray(prn, dtype=np.int16)[keep]
    code = np.asarray(code, dtype="U3")[keep]
    codes = tuple(sorted({str(c) for c in code}))
    code_index = np.searchsorted(np.array(codes, dtype="U3"), code).astype(np.int16)
    order = np.lexsort((code_index, prn, system, time))  # stable: file order among equals
    key = (time[order], system[order], prn[order], code_index[order])
    repeat = np.zeros(order.size, dtype=bool)
    repeat[1:] = np.logical_and.reduce([k[1:] == k[:-1] for k in key])
    if np.any(repeat):
        problems = (
            *problems,
            f"{path}: {int(repeat.sum())} repeated observations (same epoch, satellite and "
            "signal) dropped, the first kept",
        )
        order = order[~repeat]
    obs_types = {
        str(s): tuple(sorted({str(c) for c in code[system == s]})) for s in np.unique(system)
    }
    header = ObsHeader(
        path=path,
        version=3.05,
        system="M",
        marker_name="",
        receiver_type=receiver_type,
        approx_position=None,
        interval=None,
        obs_types=obs_types,
        glonass_channels=dict(glonass_channels or {}),
        time_system="GPS",
        leap_seconds=None,
        signal_strength_unit="DBHZ",
        n_lines=n_lines,
    )
    epoch_time = np.unique(time)
    return Observations(
        header=header,
        time=time[order],
        system=system[order],
        prn=prn[order],
        code=code_index[order],
        codes=codes,
        value=value[order],
        lli=lli[order],
        ssi=np.full(order.size, -1, dtype=np.int8),
        epoch_time=epoch_time,
        epoch_flag=np.zeros(epoch_time.size, dtype=np.int8),
        problems=tuple(problems),
        row_fields={name: v[order] for name, v in extra.items()},
    )
