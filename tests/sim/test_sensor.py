"""Image sensor: noise statistics of the linear camera model, ambient light process, auto
exposure dynamics, vignetting, determinism per seed."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from vo_doppler.sim.sensor import Sensor, SensorConfig, add_noise, ambient_light, vignetting

CONFIG = SensorConfig()


@pytest.mark.parametrize(("level", "gain"), [(30.0, 1.0), (100.0, 2.0), (180.0, 0.5)])
def test_noise_variance_is_shot_plus_read(level, gain):
    signal = np.full((1000, 1000), level, dtype=np.float32)
    noisy = add_noise(signal, gain, CONFIG, np.random.default_rng(3))
    expected = np.sqrt(level * gain / CONFIG.electrons_per_grey + CONFIG.read_noise_grey**2)
    assert noisy.mean() == pytest.approx(level, abs=0.02)
    assert noisy.std() == pytest.approx(expected, rel=0.01)


def test_noise_saturates_at_white():
    noisy = add_noise(np.full((100, 100), 254.0, np.float32), 4.0, CONFIG, np.random.default_rng(0))
    assert noisy.max() == 255.0 and noisy.min() < 254.0


def test_ambient_light_is_a_stationary_ou_process():
    dt, tau = 0.1, CONFIG.light_time_constant_s
    times = np.arange(200_000) * dt
    log_light = np.log(ambient_light(times, CONFIG, np.random.default_rng(5)))
    assert log_light.std() == pytest.approx(CONFIG.light_variation, rel=0.05)
    lag = int(tau / dt)
    correlation = np.corrcoef(log_light[:-lag], log_light[lag:])[0, 1]
    assert correlation == pytest.approx(np.exp(-1.0), abs=0.05)
    steady = replace(CONFIG, light_variation=0.0)
    np.testing.assert_array_equal(ambient_light(times[:10], steady, np.random.default_rng(5)), 1.0)


def test_auto_exposure_closes_a_fixed_fraction_of_the_log_error_per_frame():
    config = replace(CONFIG, light_variation=0.0, vignetting=0.0, exposure_rate=0.25)
    sensor = Sensor(config, np.arange(8) / 15.0, 64, 48, seed=1, noise=False)
    scene = np.full((48, 64), 55.0, dtype=np.float32)
    first = sensor.frame(scene, 0)
    assert first.mean() == pytest.approx(config.exposure_target_grey, rel=1e-5)
    means = [sensor.frame(2.0 * scene, k).mean() for k in range(1, 8)]
    errors = np.log(np.array(means) / config.exposure_target_grey)
    expected = np.log(2.0) * (1 - config.exposure_rate) ** np.arange(7)
    np.testing.assert_allclose(errors, expected, rtol=1e-4)
    np.testing.assert_allclose(sensor.gains[1:], sensor.gains[0] * np.exp(errors) / 2.0, rtol=1e-4)


def test_vignetting_is_one_at_the_centre_and_one_minus_strength_in_the_corners():
    shading = vignetting(641, 361, 0.2)
    assert shading[180, 320] == pytest.approx(1.0)
    for corner in (shading[0, 0], shading[0, -1], shading[-1, 0], shading[-1, -1]):
        assert corner == pytest.approx(0.8)


def test_frames_are_deterministic_per_seed():
    times = np.arange(3) / 15.0
    scene = np.random.default_rng(0).uniform(0, 200, (48, 64)).astype(np.float32)

    def frames(seed):
        sensor = Sensor(CONFIG, times, 64, 48, seed)
        return [sensor.frame(scene, k) for k in range(3)]

    a, b, c = frames(7), frames(7), frames(8)
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(x, y)
    assert not np.array_equal(a[1], c[1])
    assert not np.array_equal(a[0], a[1])
