"""Doppler-like observables from time-differenced carrier phase (optional, cleaner range rate).

Carrier phase L (cycles) grows with range, Doppler D is positive when approaching, so over an
unbroken arc D ≈ −dL/dt. The central difference D̃(t_k) = −(L_{k+1} − L_{k−1}) / (t_{k+1} − t_{k−1})
is exact for a range that is quadratic in time and carries the phase noise (mm) instead of the
Doppler noise (dm/s on low-cost receivers). A difference is used only when both neighbours are
within ``max_gap_s``, no loss-of-lock indicator (LLI bit 0, RINEX 3.05 sec. 5.7) is set on the
current or next epoch, and — when a Doppler was logged — it agrees with the Doppler to within
``max_disagreement_hz`` (catches unflagged cycle slips).
"""

from __future__ import annotations

import numpy as np

from vo_doppler.model.observations import Observations, lookup, row_keys

MAX_GAP_S = 1.5
MAX_DISAGREEMENT_HZ = 5.0


def carrier_phase_doppler(
    obs: Observations,
    max_gap_s: float = MAX_GAP_S,
    max_disagreement_hz: float = MAX_DISAGREEMENT_HZ,
) -> Observations:
    """Copy of ``obs`` whose Doppler rows ('D…') are replaced by phase-rate values.

    A phase-rate row is made for every phase observable 'Lxx' whose Doppler code 'Dxx' is among
    the file's codes; where no phase rate exists the Doppler row is dropped (not kept).
    """
    codes = obs.codes
    phase_to_doppler = {
        i: codes.index("D" + c[1:])
        for i, c in enumerate(codes)
        if c.startswith("L") and "D" + c[1:] in codes
    }
    is_phase = np.isin(obs.code, list(phase_to_doppler))
    phase = obs.subset(is_phase)
    doppler_code = np.array([phase_to_doppler.get(int(c), -1) for c in phase.code], dtype=np.int16)
    group = (
        np.array([ord(s) for s in phase.system], dtype=np.int64) * 1000 + phase.prn
    ) * 1000 + phase.code
    order = np.lexsort((phase.time, group))
    g, t, value = group[order], phase.time[order], phase.value[order]
    slip = (phase.lli[order] >= 0) & (phase.lli[order] & 1 == 1)
    ok = np.zeros(order.size, dtype=bool)
    rate = np.full(order.size, np.nan)
    if order.size >= 3:
        same = (g[:-2] == g[1:-1]) & (g[1:-1] == g[2:])
        gaps = (t[1:-1] - t[:-2] <= max_gap_s) & (t[2:] - t[1:-1] <= max_gap_s)
        clean = ~slip[1:-1] & ~slip[2:]
        ok[1:-1] = same & gaps & clean
        rate[1:-1] = -(value[2:] - value[:-2]) / (t[2:] - t[:-2])
    rows = order[ok]
    rate = rate[ok]
    new_code = doppler_code[rows]
    logged = _logged_doppler(obs, phase.time[rows], phase.system[rows], phase.prn[rows], new_code)
    agree = ~(np.abs(logged - rate) > max_disagreement_hz)
    rows, rate, new_code = rows[agree], rate[agree], new_code[agree]
    keep = ~np.isin(obs.code, list(phase_to_doppler.values()))
    return Observations(
        header=obs.header,
        time=np.concatenate([obs.time[keep], phase.time[rows]]),
        system=np.concatenate([obs.system[keep], phase.system[rows]]),
        prn=np.concatenate([obs.prn[keep], phase.prn[rows]]),
        code=np.concatenate([obs.code[keep], new_code]).astype(np.int16),
        codes=codes,
        value=np.concatenate([obs.value[keep], rate]),
        lli=np.concatenate([obs.lli[keep], np.full(rows.size, -1, dtype=np.int8)]),
        ssi=np.concatenate([obs.ssi[keep], phase.ssi[rows]]),
        epoch_time=obs.epoch_time,
        epoch_flag=obs.epoch_flag,
        problems=obs.problems,
    )


def _logged_doppler(obs: Observations, time, system, prn, code) -> np.ndarray:
    """The Doppler the receiver logged for the same epoch, satellite and signal (NaN if none)."""
    is_doppler = np.isin(obs.code, np.unique(code))
    keys = row_keys(
        obs.epoch_time,
        obs.time[is_doppler],
        obs.system[is_doppler],
        obs.prn[is_doppler],
        obs.code[is_doppler],
    )
    wanted = row_keys(obs.epoch_time, time, system, prn, code)
    return lookup(keys, obs.value[is_doppler], wanted)
