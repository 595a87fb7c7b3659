"""Image sensor of the simulated camera: vignetting, changing light, auto exposure and noise.

The renderer gives scene radiance as grey levels (albedo × sun shading, 0–255). The sensor
turns it into a raw frame:

    S = R · V(u, v) · L(t) · g_k,      V = 1 − a·(ρ/ρ_corner)²

with V the residual vignetting left after lens-shading correction (ρ the distance to the image
centre), L(t) the ambient light (clouds: log L an Ornstein–Uhlenbeck process), and g_k the gain
of auto exposure. The auto exposure meters the mean of the previous frame and moves the gain a
fraction of the way to the target in log space, as camera AE loops do, so frames change
brightness when the view changes (sky, shadowed facades) and lag the light.

Noise is the photon shot noise and read noise of the pixel: with c electrons per grey level at
unit gain, a pixel of S grey levels collects S·c/g electrons, so its variance is
S·g/c + σ_read² (grey levels², Gaussian approximation of the Poisson count, EMVA 1288 linear
camera model). Frames are clipped to 0–255 (saturation).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class SensorConfig:
    """Magnitudes of the sensor effects; a zero switches the effect off."""

    electrons_per_grey: float = 25.0
    """Conversion at unit gain (≈ 6,400 e⁻ full well over 255 grey levels, a small CMOS pixel)."""
    read_noise_grey: float = 1.0
    vignetting: float = 0.2
    """Brightness lost in the image corners (fraction)."""
    light_variation: float = 0.15
    """Standard deviation of log ambient light (clouds)."""
    light_time_constant_s: float = 8.0
    exposure_target_grey: float = 110.0
    exposure_rate: float = 0.25
    """Fraction of the log-exposure error the auto exposure corrects per frame (0: fixed gain)."""
    gain_range: tuple[float, float] = (0.25, 8.0)


def vignetting(width: int, height: int, strength: float) -> np.ndarray:
    """V(u, v) = 1 − strength·(ρ/ρ_corner)² (float32, height × width)."""
    u = np.arange(width, dtype=float) - (width - 1) / 2.0
    v = np.arange(height, dtype=float) - (height - 1) / 2.0
    rho2 = u[None, :] ** 2 + v[:, None] ** 2
    return (1.0 - strength * rho2 / rho2.max()).astype(np.float32)


def ambient_light(times: np.ndarray, config: SensorConfig, rng: np.random.Generator) -> np.ndarray:
    """L(t) = exp(x(t)), x an Ornstein–Uhlenbeck process with stationary standard deviation
    ``light_variation`` and time constant ``light_time_constant_s``, sampled exactly at the
    (increasing) times: x_k = x_{k−1}·e^(−Δt/τ) + σ·√(1 − e^(−2Δt/τ))·n_k."""
    times = np.asarray(times, dtype=float)
    sigma = config.light_variation
    if sigma == 0.0 or len(times) == 0:
        return np.ones(len(times))
    decay = np.exp(-np.diff(times) / config.light_time_constant_s)
    steps = rng.standard_normal(len(times))
    x = np.empty(len(times))
    x[0] = sigma * steps[0]
    for k in range(1, len(times)):
        x[k] = x[k - 1] * decay[k - 1] + sigma * np.sqrt(1.0 - decay[k - 1] ** 2) * steps[k]
    return np.exp(x)


def add_noise(signal: np.ndarray, gain: float, config: SensorConfig, rng) -> np.ndarray:
    """Shot and read noise on a frame of S grey levels: variance S·g/c + σ_read², clipped."""
    variance = np.maximum(signal, 0.0) * (gain / config.electrons_per_grey)
    variance += config.read_noise_grey**2
    noisy = signal + np.sqrt(variance) * rng.standard_normal(signal.shape, dtype=np.float32)
    return np.clip(noisy, 0.0, 255.0)


class Sensor:
    """Turns radiance frames into raw frames, in order (the auto exposure has memory).

    ``frame(radiance, k)`` is frame k of a sequence whose ambient light was drawn for all frame
    times at construction; noise of frame k comes from a generator seeded by (seed, k), so a
    sequence is reproducible. ``noise=False`` keeps the exposure but adds no noise.
    """

    def __init__(
        self,
        config: SensorConfig,
        times: np.ndarray,
        width: int,
        height: int,
        seed: int,
        noise: bool = True,
    ):
        self.config = config
        self.seed = seed
        self.noise = noise
        self.light = ambient_light(times, config, np.random.default_rng([seed, 0x11647]))
        self.shading = vignetting(width, height, config.vignetting)
        self.gain: float | None = None
        self.gains: list[float] = []

    def frame(self, radiance: np.ndarray, k: int) -> np.ndarray:
        """Raw frame k (float32 grey levels, 0–255) of the radiance image."""
        config = self.config
        lit = radiance.astype(np.float32) * self.shading * np.float32(self.light[k])
        low, high = config.gain_range
        if self.gain is None:
            self.gain = float(
                np.clip(config.exposure_target_grey / max(lit.mean(), 1e-3), low, high)
            )
        gain = self.gain
        self.gains.append(gain)
        signal = lit * np.float32(gain)
        if config.exposure_rate > 0.0:
            error = np.log(config.exposure_target_grey / max(float(signal.mean()), 1e-3))
            self.gain = float(np.clip(gain * np.exp(config.exposure_rate * error), low, high))
        if not self.noise:
            return np.clip(signal, 0.0, 255.0)
        rng = np.random.default_rng([self.seed, k])
        return add_noise(signal, gain, config, rng)
