"""A recording's GNSS decimated to a lower rate, as a receiver logging at that rate would have
recorded it (e.g. the 10 Hz comma2k19 minute at 1 Hz).

An epoch is kept when it is the recorded epoch nearest a tick of the new rate (multiples of
1/rate in GPS seconds: whole seconds at 1 Hz, or x.3 s with a phase of 0.3 s) and lies within
half a recorded interval of it; a receiver whose clock runs a few milliseconds off GPS time
(epochs at x.997 s) keeps the epoch nearest each whole second, and a tick with no recorded
epoch near it stays empty, as a receiver's skipped epoch would. The kept epochs' observation
rows and the receiver's reported Doppler σ of those epochs go with them; images, vehicle
signals, navigation and ground truth are unchanged.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from vo_doppler.model.doppler_sigma import TIME_RESOLUTION_S
from vo_doppler.model.observations import Observations
from vo_doppler.model.sequence import Sequence


def recorded_interval(epoch_time: np.ndarray) -> float:
    """Median interval between data epochs (s); NaN with fewer than two epochs."""
    steps = np.diff(np.asarray(epoch_time, dtype=float))
    return float(np.median(steps)) if steps.size else float("nan")


def decimated_epochs(epoch_time: np.ndarray, rate_hz: float, phase_s: float = 0.0) -> np.ndarray:
    """Mask of the epochs kept at ``rate_hz`` (module docstring), the ticks shifted by
    ``phase_s`` (a receiver logging at x.3 s: 0.3). At or above the recorded rate every epoch
    is kept."""
    if not rate_hz > 0:
        raise ValueError(f"rate {rate_hz} Hz: give a positive rate")
    t = np.asarray(epoch_time, dtype=float)
    keep = np.zeros(t.size, dtype=bool)
    if t.size == 0:
        return keep
    interval = recorded_interval(t)
    if not np.isfinite(interval) or 1.0 / rate_hz <= interval * (1.0 + 1e-6):
        keep[:] = True
        return keep
    tick = np.round((t - phase_s) * rate_hz)
    offset = np.abs(t - phase_s - tick / rate_hz)
    # nearest epoch per tick: sort by (tick, offset) and take the first of each tick
    order = np.lexsort((offset, tick))
    first = np.ones(order.size, dtype=bool)
    first[1:] = tick[order][1:] != tick[order][:-1]
    nearest = order[first]
    keep[nearest[offset[nearest] <= 0.5 * interval + TIME_RESOLUTION_S]] = True
    return keep


def decimate_observations(observations: Observations, keep: np.ndarray) -> Observations:
    """The observations of the kept epochs (mask over ``epoch_time``) and their rows; the
    header's interval becomes the kept epochs' median interval."""
    kept_times = observations.epoch_time[keep]
    index = np.searchsorted(observations.epoch_time, observations.time)
    index = np.clip(index, 0, max(observations.epoch_time.size - 1, 0))
    rows = keep[index] & (observations.epoch_time[index] == observations.time)
    subset = observations.subset(rows)
    interval = recorded_interval(kept_times)
    header = observations.header
    if np.isfinite(interval):
        header = replace(header, interval=interval)
    return replace(
        subset,
        header=header,
        epoch_time=kept_times,
        epoch_flag=observations.epoch_flag[keep],
    )


def decimate(sequence: Sequence, rate_hz: float, phase_s: float = 0.0) -> Sequence:
    """``sequence`` with its GNSS observations (and reported Doppler σ) at ``rate_hz``, the
    ticks shifted by ``phase_s``; a sequence without GNSS, or recorded at or below that rate,
    comes back unchanged."""
    obs = sequence.observations
    if obs is None:
        return sequence
    keep = decimated_epochs(obs.epoch_time, rate_hz, phase_s)
    if keep.all():
        return sequence
    sigma = sequence.doppler_sigma
    if sigma is not None:
        ticks = np.round(obs.epoch_time[keep] / TIME_RESOLUTION_S).astype(np.int64)
        rows = np.isin(np.round(sigma.t / TIME_RESOLUTION_S).astype(np.int64), ticks)
        sigma = replace(
            sigma,
            t=sigma.t[rows],
            sat_id=sigma.sat_id[rows],
            code=sigma.code[rows],
            sigma_mps=sigma.sigma_mps[rows],
        )
    return replace(
        sequence,
        observations=decimate_observations(obs, keep),
        doppler_sigma=sigma,
    )
