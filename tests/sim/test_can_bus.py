"""Simulator CAN: the candump log + DBC decode through ``vo_doppler.io.can`` to the generating
signals within the DBC quantisation; wheel-speed scale error and yaw-rate bias as configured."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.io.can import read_can_log, read_can_motion
from vo_doppler.sim.can_bus import (
    DBC_PATH,
    FORWARD_ACCELERATION_SIGNAL,
    WHEEL_SPEED_SIGNALS,
    YAW_RATE_SIGNAL,
    CanSimConfig,
    gps_to_unix_offset,
    simulate_can,
    write_candump,
)
from vo_doppler.sim.vo_sequence import VehicleMotion

T0 = 1_425_953_418.0
SPEED = 10.0
YAW_RATE = 0.2


def circling(t: np.ndarray) -> VehicleMotion:
    """Constant speed and yaw rate."""
    t = np.asarray(t, dtype=float)
    yaw = YAW_RATE * (t - T0)
    xy = np.column_stack([np.sin(yaw), 1 - np.cos(yaw)]) * SPEED / YAW_RATE
    n = len(t)
    return VehicleMotion(t, xy, yaw, np.full(n, SPEED), np.full(n, YAW_RATE))


@pytest.fixture(scope="module")
def can_log(tmp_path_factory):
    path = tmp_path_factory.mktemp("can") / "vehicle.log"
    config = CanSimConfig()
    simulation = simulate_can(circling, T0, T0 + 30.0, config, np.random.default_rng(3))
    write_candump(path, simulation)
    return path, simulation, config


def read_on_gps_time(path, **options):
    """The log's yaw rate and rear wheel speed (and ``options``' signals) on GPS time."""
    offset = -gps_to_unix_offset(18)
    return read_can_motion(
        path,
        DBC_PATH,
        YAW_RATE_SIGNAL,
        WHEEL_SPEED_SIGNALS,
        yaw_rate_offset_s=offset,
        speed_offset_s=offset,
        **options,
    )


def test_log_is_candump_format_at_12_ms(can_log):
    path, _, _ = can_log
    first = path.read_text().splitlines()[0]
    assert first.startswith(f"({T0 + gps_to_unix_offset(18):.0f}.")
    assert first.split()[1] == "can0" and "#" in first.split()[2]
    frames = read_can_log(path)
    assert frames.n_unreadable == 0
    assert len(frames) == 2 * 2500
    wheel_times = frames.t[frames.arbitration_id == 0x1A0]
    np.testing.assert_allclose(np.diff(wheel_times), 0.012, atol=2.5e-4)


def test_decoded_signals_equal_generating_values_within_quantisation(can_log):
    path, simulation, _ = can_log
    motion = read_on_gps_time(path)
    assert motion.report.n_undecodable == 0 and motion.report.n_padded == 0
    yaw = motion.yaw_rate
    np.testing.assert_allclose(yaw.t, simulation.t_dynamics, atol=1e-6)
    step = np.radians(0.01)
    assert np.max(np.abs(yaw.value - np.radians(simulation.yaw_rate_dps))) <= step / 2 + 1e-12
    speed = motion.speed
    np.testing.assert_allclose(speed.t, simulation.t_wheel, atol=1e-6)
    rear = simulation.wheel_kmh[:, 2:].mean(axis=1) / 3.6
    assert np.max(np.abs(speed.value - rear)) <= 0.01 / 3.6 / 2 + 1e-12


def test_sensor_errors_are_the_configured_ones(can_log):
    path, simulation, config = can_log
    offset = -gps_to_unix_offset(18)
    motion = read_can_motion(
        path, DBC_PATH, YAW_RATE_SIGNAL, WHEEL_SPEED_SIGNALS, 1.0, offset, offset
    )
    scale = np.mean(motion.speed.value) / SPEED
    assert scale == pytest.approx(1.0 + config.wheel_scale_error, abs=2e-4)
    bias = np.degrees(np.mean(motion.yaw_rate.value) - YAW_RATE)
    assert bias == pytest.approx(np.mean(simulation.yaw_bias_dps), abs=0.003)
    assert np.mean(simulation.yaw_bias_dps) == pytest.approx(config.yaw_rate_bias_dps, abs=0.03)
    left, right = simulation.wheel_kmh[:, 2], simulation.wheel_kmh[:, 3]
    track = (right - left).mean() / 3.6 / (1 + config.wheel_scale_error) / YAW_RATE
    assert track == pytest.approx(config.track_m, abs=0.01)  # wheel noise: σ ≈ 0.002 m


def test_longitudinal_accelerometer_reads_the_speed_change_plus_its_bias_and_noise(can_log):
    path, _, config = can_log
    motion = read_on_gps_time(path, forward_acceleration=FORWARD_ACCELERATION_SIGNAL)
    acceleration = motion.forward_acceleration
    assert acceleration.unit == "m/s^2" and len(acceleration) == 2500
    # constant speed: what is read is the bias and the noise (σ 0.03: the mean within 0.002)
    assert np.mean(acceleration.value) == pytest.approx(config.long_accel_bias_mps2, abs=0.002)
    assert np.std(acceleration.value) == pytest.approx(config.long_accel_noise_mps2, rel=0.05)


def test_the_accelerometer_noise_leaves_the_other_signals_as_they_were():
    quiet = CanSimConfig(long_accel_noise_mps2=0.0)
    noisy = CanSimConfig(long_accel_noise_mps2=0.5)
    a = simulate_can(circling, T0, T0 + 5.0, quiet, np.random.default_rng(3))
    b = simulate_can(circling, T0, T0 + 5.0, noisy, np.random.default_rng(3))
    np.testing.assert_array_equal(a.wheel_kmh, b.wheel_kmh)
    np.testing.assert_array_equal(a.yaw_rate_dps, b.yaw_rate_dps)
    assert a.lines != b.lines
