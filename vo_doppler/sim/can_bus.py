"""Simulated vehicle CAN bus: wheel speeds and yaw rate, encoded with ``vehicle.dbc``, written
as a candump ``-l`` log (``(unix_time) can0 1A0#0011…``).

Signals (the DBC is the reference for ids, bit layout and scaling):
- ``WHEEL_SPEEDS`` (0x1A0): four wheel speeds in km/h, factor 0.01. With the vehicle origin at
  the rear-axle centre, speed v and yaw rate ω: rear wheels v ∓ ω·track/2 (left/right), front
  wheels √((v ∓ ω·track/2)² + (ω·wheelbase)²). All multiplied by (1 + wheel scale error)
  (tyre radius error; default +2 %), plus white noise.
- ``VEHICLE_DYNAMICS`` (0x130): yaw rate in deg/s (counter-clockwise positive, factor 0.01)
  = ω + bias (default 0.3 deg/s) + bias random walk + white noise; lateral acceleration v·ω;
  longitudinal acceleration as an accelerometer on the city's level roads measures it, dv/dt +
  bias (default 0.1 m/s², sensor offset and mounting pitch) + white noise (its noise drawn from
  a generator spawned off ``rng``, so the other signals are those of a bus without it); a 4-bit
  rolling counter.
Raw values are rounded to the DBC step (quantisation) and saturated at the signal range.
Both messages are sent every 12 ms (second one half a period later) with a little jitter.
Log times are Unix seconds (UTC, as candump writes them): t_unix = t_gps + 315 964 800 − leap.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import cantools
import numpy as np

from vo_doppler.model.gpstime import UNIX_TIME_AT_GPS_EPOCH_S
from vo_doppler.sim.vo_sequence import VehicleMotion

DBC_PATH = Path(__file__).with_name("vehicle.dbc")
WHEEL_MESSAGE = "WHEEL_SPEEDS"
DYNAMICS_MESSAGE = "VEHICLE_DYNAMICS"
WHEELS = ("FL", "FR", "RL", "RR")
YAW_RATE_SIGNAL = f"{DYNAMICS_MESSAGE}.YAW_RATE"
FORWARD_ACCELERATION_SIGNAL = f"{DYNAMICS_MESSAGE}.LONG_ACCEL"
WHEEL_SPEED_SIGNALS = f"{WHEEL_MESSAGE}.WHEEL_SPEED_RL,{WHEEL_MESSAGE}.WHEEL_SPEED_RR"


def gps_to_unix_offset(leap_seconds: int) -> float:
    """t_unix − t_gps (s)."""
    return UNIX_TIME_AT_GPS_EPOCH_S - leap_seconds


@dataclass(frozen=True)
class CanSimConfig:
    """Bus timing and sensor errors (defaults: issue 5)."""

    period_s: float = 0.012
    jitter_s: float = 2e-4
    wheel_scale_error: float = 0.02
    wheel_noise_kmh: float = 0.05
    yaw_rate_bias_dps: float = 0.3
    yaw_bias_walk_dps_per_sqrt_s: float = 0.003
    yaw_rate_noise_dps: float = 0.05
    long_accel_bias_mps2: float = 0.1
    long_accel_noise_mps2: float = 0.03
    track_m: float = 1.55
    wheelbase_m: float = 2.7
    channel: str = "can0"


@dataclass(frozen=True)
class CanSimulation:
    """Generated signals before quantisation (GPS times) and the log lines.

    ``wheel_kmh`` (n_wheel_frames, 4) in ``WHEELS`` order; ``yaw_rate_dps`` and
    ``yaw_bias_dps`` at the dynamics frames.
    """

    t_wheel: np.ndarray
    wheel_kmh: np.ndarray
    t_dynamics: np.ndarray
    yaw_rate_dps: np.ndarray
    yaw_bias_dps: np.ndarray
    lines: list[str]


def _raw(message, values: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Physical values → rounded, saturated raw integers per signal."""
    out = {}
    for signal in message.signals:
        value = values[signal.name]
        raw = np.round((value - signal.offset) / signal.scale)
        low = (signal.minimum - signal.offset) / signal.scale
        high = (signal.maximum - signal.offset) / signal.scale
        out[signal.name] = np.clip(raw, low, high).astype(np.int64)
    return out


def _encode(message, raw: dict[str, np.ndarray]) -> list[str]:
    n = len(next(iter(raw.values())))
    names = list(raw)
    return [
        message.encode({name: int(raw[name][i]) for name in names}, scaling=False).hex().upper()
        for i in range(n)
    ]


def simulate_can(
    vehicle_at: Callable[[np.ndarray], VehicleMotion],
    t_start: float,
    t_end: float,
    config: CanSimConfig,
    rng: np.random.Generator,
    leap_seconds: int = 18,
) -> CanSimulation:
    """Frames from ``t_start`` to ``t_end`` (GPS s) of the vehicle ``vehicle_at(times)``."""
    db = cantools.database.load_file(str(DBC_PATH))
    wheel_msg = db.get_message_by_name(WHEEL_MESSAGE)
    dyn_msg = db.get_message_by_name(DYNAMICS_MESSAGE)
    n = int(np.floor((t_end - t_start - config.period_s / 2) / config.period_s)) + 1
    base = t_start + config.period_s * np.arange(n)
    t_wheel = base + rng.uniform(0.0, config.jitter_s, n)
    t_dyn = base + config.period_s / 2 + rng.uniform(0.0, config.jitter_s, n)

    motion = vehicle_at(t_wheel)
    v, w = motion.speed, motion.yaw_rate
    half = w * config.track_m / 2
    lateral = w * config.wheelbase_m
    wheels = np.stack(
        [np.hypot(v - half, lateral), np.hypot(v + half, lateral), v - half, v + half], axis=1
    )
    wheel_kmh = wheels * 3.6 * (1.0 + config.wheel_scale_error)
    wheel_kmh += rng.normal(0.0, config.wheel_noise_kmh, wheel_kmh.shape)
    wheel_kmh = np.maximum(wheel_kmh, 0.0)

    motion = vehicle_at(t_dyn)
    walk = rng.normal(0.0, config.yaw_bias_walk_dps_per_sqrt_s * np.sqrt(config.period_s), n)
    bias = config.yaw_rate_bias_dps + np.concatenate([[0.0], np.cumsum(walk[1:])])
    yaw_dps = np.degrees(motion.yaw_rate) + bias + rng.normal(0.0, config.yaw_rate_noise_dps, n)
    long_accel = np.gradient(motion.speed, t_dyn) if n > 1 else np.zeros(n)
    long_accel += config.long_accel_bias_mps2
    long_accel += rng.spawn(1)[0].normal(0.0, config.long_accel_noise_mps2, n)
    dyn_raw = _raw(
        dyn_msg,
        {
            "YAW_RATE": yaw_dps,
            "LAT_ACCEL": motion.speed * motion.yaw_rate,
            "LONG_ACCEL": long_accel,
            "COUNTER": np.arange(n) % 16,
        },
    )
    wheel_raw = _raw(
        wheel_msg, {f"WHEEL_SPEED_{name}": wheel_kmh[:, k] for k, name in enumerate(WHEELS)}
    )
    offset = gps_to_unix_offset(leap_seconds)
    entries = [
        (t, f"{wheel_msg.frame_id:03X}#{data}")
        for t, data in zip(t_wheel, _encode(wheel_msg, wheel_raw), strict=True)
    ] + [
        (t, f"{dyn_msg.frame_id:03X}#{data}")
        for t, data in zip(t_dyn, _encode(dyn_msg, dyn_raw), strict=True)
    ]
    entries.sort(key=lambda item: item[0])
    lines = [f"({t + offset:.6f}) {config.channel} {frame}\n" for t, frame in entries]
    return CanSimulation(t_wheel, wheel_kmh, t_dyn, yaw_dps, bias, lines)


def write_candump(path: str | Path, simulation: CanSimulation) -> None:
    """Write the candump ``-l`` log."""
    Path(path).write_text("".join(simulation.lines))
