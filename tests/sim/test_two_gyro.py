"""The generated two-gyro record: a stadium loop that closes, its known length and turns, gyros
whose error is the chosen bias plus noise, GPS near the truth, standstill-only calibration
records, determinism per seed, and the files written."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from vo_doppler.geo import EnuFrame
from vo_doppler.io.gps_fixes import read_gps_csv
from vo_doppler.io.sensor_csv import read_yaw_rate_csv
from vo_doppler.sim.two_gyro import (
    DEG,
    TwoGyroSpec,
    calibration_spec,
    generate_two_gyro,
    write_two_gyro,
)

# a short standstill keeps the record small; the loop is the default one
SPEC = TwoGyroSpec(standstill_s=60.0)


@pytest.fixture(scope="module")
def record():
    return generate_two_gyro(SPEC)


def test_the_loop_closes_after_its_length_and_one_full_turn(record):
    assert SPEC.loop_length_m == pytest.approx(2 * 300.0 + 2 * np.pi * 50.0)
    east, north, yaw = record.truth_east, record.truth_north, record.truth_yaw
    np.testing.assert_allclose([east[-1], north[-1]], [0.0, 0.0], atol=1e-6)
    assert yaw[-1] - yaw[0] == pytest.approx(2 * np.pi, abs=1e-9)
    steps = np.hypot(np.diff(east), np.diff(north))
    assert steps.sum() == pytest.approx(SPEC.loop_length_m, rel=1e-6)
    # the far straight lies 2R north, driven west
    far = np.isclose(north, 100.0) & (np.abs(east - 150.0) < 100.0)
    assert far.any() and np.allclose(yaw[far], np.pi)
    # ramps of 2 m/s² to 10 m/s: 5 s up and down, cruise (loop − 50 m) / 10 m/s
    moving = np.flatnonzero(steps > 0)
    duration = (moving[-1] - moving[0] + 1) / SPEC.gyro1_hz
    assert duration == pytest.approx(10.0 + (SPEC.loop_length_m - 50.0) / 10.0, abs=0.02)


def test_the_record_stands_still_first_and_last(record):
    t0, t1 = record.standstill
    assert (t0, t1) == (SPEC.t_start, SPEC.t_start + 60.0)
    still = record.truth_t < t1
    assert np.all(record.truth_east[still] == 0.0) and np.all(record.truth_yaw[still] == 0.0)
    end = record.truth_t > record.truth_t[-1] - SPEC.end_standstill_s + 0.5
    assert np.ptp(record.truth_east[end]) == 0.0


def test_each_gyro_reads_the_true_rate_plus_its_bias_and_noise(record):
    t1, omega1 = record.gyro1
    t2, omega2 = record.gyro2
    assert np.diff(t1).mean() == pytest.approx(0.01) and np.diff(t2).mean() == pytest.approx(0.02)
    true1 = np.gradient(record.truth_yaw, record.truth_t)
    still1, still2 = t1 < record.standstill[1], t2 < record.standstill[1]
    # over the 60-s standstill the mean is the bias, within the noise's σ/√n and the walk's
    # K·√60 (gyro 1: 0.0007 and 0.0004°/s; gyro 2: 0.0013 and 0.0015°/s), three times over
    assert omega1[still1].mean() == pytest.approx(SPEC.bias1, abs=0.0033 * DEG)
    assert omega2[still2].mean() == pytest.approx(SPEC.bias2, abs=0.006 * DEG)
    # white noise at N·√fs: 0.05°/s for gyro 1, 0.0707°/s for gyro 2
    assert np.std(omega1[still1]) == pytest.approx(0.005 * 10.0 * DEG, rel=0.05)
    assert np.std(omega2[still2]) == pytest.approx(0.01 * np.sqrt(50.0) * DEG, rel=0.05)
    # while driving the error stays the bias and noise: the heading change matches the truth
    turned = np.sum(omega1 - SPEC.bias1) / SPEC.gyro1_hz
    assert turned == pytest.approx(2 * np.pi, abs=2 * DEG)
    assert np.allclose(np.median(omega1 - true1), SPEC.bias1, atol=0.005 * DEG)


def test_gps_fixes_wander_metres_about_the_truth(record):
    t, lat, lon = record.gps
    assert np.diff(t).mean() == pytest.approx(1.0)
    frame = EnuFrame(35.0 * DEG, 139.0 * DEG, 0.0)
    enu = frame.geodetic_to_enu(lat, lon, 0.0)
    truth = np.column_stack(
        [np.interp(t, record.truth_t, v) for v in (record.truth_east, record.truth_north)]
    )
    error = np.hypot(*(enu[:, :2] - truth).T)
    assert 0.3 < np.median(error) < 5.0 and error.max() < 10.0


def test_the_same_spec_gives_the_same_numbers_and_another_seed_others(record):
    again = generate_two_gyro(SPEC)
    np.testing.assert_array_equal(again.gyro1[1], record.gyro1[1])
    np.testing.assert_array_equal(again.gps[1], record.gps[1])
    other = generate_two_gyro(replace(SPEC, seed=8))
    assert not np.array_equal(other.gyro1[1], record.gyro1[1])


def test_a_calibration_record_only_stands_still_with_shifted_biases():
    spec = calibration_spec(SPEC)
    assert spec.drive is False and spec.seed == SPEC.seed + 1
    assert spec.bias1 == pytest.approx(SPEC.bias1 - 0.035 * DEG)
    assert spec.bias2 == pytest.approx(SPEC.bias2 - 0.04 * DEG)
    still = generate_two_gyro(spec)
    assert still.truth_t[-1] - still.truth_t[0] == pytest.approx(60.0, abs=0.02)
    assert np.all(still.truth_east == 0.0) and np.all(still.truth_yaw == 0.0)


def test_the_files_hold_the_streams(record, tmp_path):
    paths = write_two_gyro(record, tmp_path / "two")
    assert sorted(p.name for p in paths.values()) == ["gps.csv", "gyro1.csv", "gyro2.csv"]
    gyro2 = read_yaw_rate_csv(paths["gyro2"])
    np.testing.assert_allclose(gyro2.t, record.gyro2[0], rtol=0, atol=1e-6)
    np.testing.assert_allclose(gyro2.value, record.gyro2[1], rtol=0, atol=1e-9)
    fixes = read_gps_csv(paths["gps"])
    np.testing.assert_allclose(fixes.lat, record.gps[1], rtol=0, atol=1e-9 * DEG)
    np.testing.assert_allclose(fixes.lon, record.gps[2], rtol=0, atol=1e-9 * DEG)
