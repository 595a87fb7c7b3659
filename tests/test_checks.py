"""Plausibility checks on exact synthetic cases."""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np
import pytest

from tests.helpers.heading_table import plain_heading_table
from tests.helpers.velocity import velocity_solution
from vo_doppler.checks import (
    ClockOffsetEstimate,
    calibration_warnings,
    check_standstill_is_still,
    check_vehicle_overlap,
    check_yaw_rate_sign,
    check_yaw_rate_unit,
    clock_warning,
    coverage_warning,
    estimate_clock_offset,
    gyro_bias_warning,
    heading_warnings,
    moving_yaw_rate_medians,
    origin_warning,
    speed_ratio_warning,
    wheel_scale_warning,
    yaw_rate_sign_agreement,
)
from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import integral_at
from vo_doppler.model.vehicle_source import VehicleSignalSource

T = np.arange(0.0, 60.0, 0.01)
SPEED = SensorSeries(T, 10.0 + 3.0 * np.sin(0.4 * T) + 2.0 * np.sin(1.3 * T), "speed", "m/s")


DBC = VehicleSignalSource(yaw_rate="v.dbc: signal Y", yaw_rate_unit_fix="fix the DBC")


def test_ordinary_yaw_rate_passes_and_deg_read_as_rad_is_named():
    deg_per_s = 0.3 + 2.0 * np.sin(0.2 * T)  # a drive's yaw rate in °/s
    ordinary = SensorSeries(T, np.radians(deg_per_s), "yaw", "rad/s")
    check_yaw_rate_unit(ordinary, SPEED, replace(DBC, yaw_rate_unit="deg/s"))
    rate, lateral = moving_yaw_rate_medians(ordinary, SPEED)
    assert rate == pytest.approx(np.radians(np.median(np.abs(deg_per_s))))
    assert lateral < 1.5
    wrong = SensorSeries(T, deg_per_s, "yaw", "rad/s")
    with pytest.raises(
        InputError, match=r"^v.dbc: signal Y: implausibly large .* look like deg/s: fix the DBC$"
    ):
        check_yaw_rate_unit(wrong, SPEED, DBC)
    with pytest.raises(InputError, match="implausibly large") as info:
        check_yaw_rate_unit(wrong, SPEED, replace(DBC, yaw_rate_unit="deg/s"))
    assert "look like deg/s" not in str(info.value)
    with pytest.raises(InputError, match=r"^the yaw rate: .*look like deg/s: convert it to rad/s$"):
        check_yaw_rate_unit(wrong, SPEED)  # no source: generic words


def test_standstill_only_yaw_rate_is_not_judged():
    still = SensorSeries(T, np.zeros_like(T), "speed", "m/s")
    check_yaw_rate_unit(SensorSeries(T, np.full_like(T, 5.0), "yaw", "rad/s"), still)


@pytest.mark.parametrize("shift", [0.0, 0.35, -1.2, 4.0])
def test_clock_offset_is_recovered(shift):
    t_gnss = np.arange(5.0, 55.0, 0.2)
    gnss_speed = np.interp(t_gnss, SPEED.t, SPEED.value)
    gnss_speed[::3] = np.nan  # gaps are skipped, not interpolated
    late = SPEED.shifted(-shift)  # the wheel clock runs `shift` s behind
    estimate = estimate_clock_offset(late, t_gnss, gnss_speed)
    assert estimate.difference_mps < 0.02
    assert estimate.residual_s == pytest.approx(shift, abs=0.01)
    warning = clock_warning("CAN", estimate, 100.0)
    if abs(shift) > 0.2:
        assert f"{100.0 + shift:.1f}" in warning and "CAN clock" in warning
    else:
        assert warning is None


@pytest.mark.parametrize("shift", [0.0, 0.5])
@pytest.mark.parametrize("bursts", [False, True])
def test_clock_offset_holds_with_a_third_of_the_epochs_reflected_and_a_scale_error(shift, bursts):
    """Scattered wrong speeds, or 5.5-s bursts at 30 % of the speed (several satellites
    reflected at once): the correlation peak moved to +5 s or vanished on these."""
    t_gnss = np.arange(5.0, 55.0, 0.1)
    gnss_speed = np.interp(t_gnss, SPEED.t, SPEED.value)
    if bursts:
        gnss_speed[t_gnss % 16.0 < 5.5] *= 0.3
    else:
        reflected = np.random.default_rng(3).uniform(size=t_gnss.size) < 0.35
        gnss_speed[reflected] = np.random.default_rng(4).uniform(0.0, 25.0, reflected.sum())
    wheel = SensorSeries(SPEED.t, 1.02 * SPEED.value, "speed", "m/s").shifted(-shift)
    estimate = estimate_clock_offset(wheel, t_gnss, gnss_speed)
    assert estimate.residual_s == pytest.approx(shift, abs=0.03)
    assert (estimate.unshifted_difference_mps > 2 * estimate.difference_mps) == (shift > 0)


@pytest.mark.parametrize(
    ("residual", "speed", "warned"),
    [(0.1, 25.0, True), (-0.05, 25.0, True), (0.1, 5.0, False), (0.03, 25.0, False)],
)
def test_a_clock_offset_warns_by_the_distance_it_shifts_the_track(residual, speed, warned):
    """0.1 s is 2.5 m at 25 m/s (comma2k19: 0.1 s nearly doubled DR + GPS) but 0.5 m at 5 m/s;
    beyond 1 m, or 0.2 s at any speed, it is a warning that says how far."""
    estimate = ClockOffsetEstimate(residual, 0.05, 0.3, moving_speed_mps=speed)
    warning = clock_warning("CAN", estimate, 100.0)
    assert (warning is not None) == warned
    if warned:
        along = f"{abs(residual) * speed:.1f} m along the track at {speed:.1f} m/s"
        assert f"shifted by {residual:+.2f} s, {along} (median" in warning


def test_the_clock_estimate_carries_the_median_moving_speed():
    wheel = _random_drive(0)
    t_gnss, gnss_speed = _noisy_gnss_speed(wheel)
    estimate = estimate_clock_offset(wheel, t_gnss, gnss_speed)
    inside = (t_gnss >= 5.0) & (t_gnss <= wheel.t[-1] - 5.0)
    assert estimate.moving_speed_mps == pytest.approx(np.median(gnss_speed[inside]), rel=1e-12)


def test_featureless_speed_gives_no_lag_and_says_why():
    flat = SensorSeries(T, np.full_like(T, 10.0), "speed", "m/s")
    t_gnss = np.arange(5.0, 55.0, 0.2)
    estimate = estimate_clock_offset(flat, t_gnss, np.full_like(t_gnss, 10.0))
    assert estimate.residual_s is None
    assert estimate.no_lag_reason.startswith("the speed hardly changes: shifted by -5.0 s, only 0")


def test_a_parked_vehicle_gives_no_lag_saying_it_does_not_move():
    parked = SensorSeries(T, np.full_like(T, 0.01), "speed", "m/s")
    t_gnss = np.arange(5.0, 55.0, 0.2)
    estimate = estimate_clock_offset(parked, t_gnss, np.zeros_like(t_gnss))
    assert estimate.residual_s is None
    assert estimate.no_lag_reason == (
        "the vehicle does not move: the wheel speed never exceeds 2 m/s (at most 0.01 m/s), "
        "so its clock cannot be checked against the GNSS"
    )


def test_vehicle_signals_that_miss_the_gnss_epochs_are_an_error_naming_their_offset():
    t_gnss = np.arange(1.4e9, 1.4e9 + 60.0, 0.2)
    on_gps = SensorSeries(T + 1.4e9, SPEED.value)
    on_log_clock = SensorSeries(T, SPEED.value)
    source = VehicleSignalSource(
        sensor="speed CSV",
        offset_name="--time-offset-speed",
        yaw_rate_offset_name="--time-offset-yaw",
    )
    check_vehicle_overlap(on_gps, on_gps, t_gnss, source)
    with pytest.raises(InputError) as yaw:
        check_vehicle_overlap(on_gps, on_log_clock, t_gnss, source)
    assert str(yaw.value).startswith("the speed CSV yaw-rate times (0.000..59.990 s)")
    assert "pass --time-offset-yaw with the GPS time of that start" in str(yaw.value)
    with pytest.raises(InputError) as wheel:
        check_vehicle_overlap(on_log_clock, on_gps, t_gnss, source)
    assert str(wheel.value).startswith("the speed CSV wheel-speed times (0.000..59.990 s)")
    assert "pass --time-offset-speed with the GPS time of that start" in str(wheel.value)


def _random_drive(seed: int) -> SensorSeries:
    """120 s of a wheel speed at 100 Hz around 12 m/s (σ 3 m/s) with smooth random
    accelerations: no two stretches of it alike, unlike a sum of sines."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 120.0, 0.01)
    acceleration = np.convolve(rng.normal(0.0, 10.0, t.size), np.full(200, 1 / 200), "same")
    v = np.cumsum(acceleration) * 0.01
    return SensorSeries(t, 12.0 + 3.0 * (v - v.mean()) / v.std(), "speed", "m/s")


def _noisy_gnss_speed(wheel: SensorSeries) -> tuple[np.ndarray, np.ndarray]:
    """The true speed at 10 Hz with a Doppler speed's noise (σ 0.05 m/s)."""
    t_gnss = np.arange(0.0, 120.0, 0.1)
    noise = np.random.default_rng(1).normal(0.0, 0.05, t_gnss.size)
    return t_gnss, np.interp(t_gnss, wheel.t, wheel.value) + noise


@pytest.mark.parametrize("shift", [-3.7, 2.3, 4.9])
def test_a_lag_inside_the_range_is_found_to_within_a_gnss_sample(shift):
    wheel = _random_drive(0)
    assert wheel.value.min() > 2.0  # moving throughout
    estimate = estimate_clock_offset(wheel.shifted(-shift), *_noisy_gnss_speed(wheel))
    assert estimate.residual_s == pytest.approx(shift, abs=0.1) and not estimate.no_lag_reason
    assert estimate.difference_mps < 0.1


@pytest.mark.parametrize(
    ("shift", "why"),
    [
        (6.0, r"^the agreement is best at the edge of the range, \+5\.0 s \(0\.\d\d m/s\): the "),
        (30.0, r"^no shift matches, the smallest median difference \(\d\.\d\d m/s\) is not "),
        (-30.0, r"^no shift matches"),
    ],
)
def test_an_offset_beyond_the_range_gives_no_lag_and_no_number(shift, why):
    """The QA case (comma2k19 with its CAN clock 30 s off printed a lag of +2.2 s beside the
    coverage warning): the best shift of unrelated stretches, or one at the range's edge, is
    no lag."""
    wheel = _random_drive(0)
    estimate = estimate_clock_offset(wheel.shifted(-shift), *_noisy_gnss_speed(wheel))
    assert estimate.residual_s is None and estimate.difference_mps is None
    assert re.search(why, estimate.no_lag_reason), estimate.no_lag_reason
    warning = clock_warning("CAN", estimate, 100.0, "--time-offset-can")
    assert warning.startswith(
        "CAN clock: no lag found between the wheel speed and the GNSS Doppler speed within ±5 s"
    )
    assert warning.endswith("; --time-offset-can 100.000 s is unchecked")
    assert "should be about" not in warning


def _cruise(changes: tuple[tuple[float, float, float], ...]) -> SensorSeries:
    """120 s at 25 m/s (wheel noise σ 0.01 m/s) with smooth speed changes (start s, change
    m/s, duration s): a highway cruise, steady nine tenths of the time."""
    t = np.arange(0.0, 120.0, 0.01)
    v = np.full_like(t, 25.0) + np.random.default_rng(2).normal(0.0, 0.01, t.size)
    for start, change, duration in changes:
        v += change * (1 - np.cos(np.pi * np.clip((t - start) / duration, 0.0, 1.0))) / 2
    return SensorSeries(t, v, "speed", "m/s")


CRUISE_CHANGES = ((20.0, 3.0, 4.0), (55.0, -5.0, 5.0), (90.0, 2.0, 3.0))


@pytest.mark.parametrize("shift", [0.0, 2.3, -3.7, 4.9])
def test_a_lag_on_a_cruise_with_a_few_speed_changes_is_found(shift):
    """Steady 90 % of the time: over all epochs every shift matched to the noise, so the lag
    was "no lag found"; the epochs where the wheel speed changes show it."""
    wheel = _cruise(CRUISE_CHANGES)
    estimate = estimate_clock_offset(wheel.shifted(-shift), *_noisy_gnss_speed(wheel))
    assert estimate.residual_s == pytest.approx(shift, abs=0.1) and not estimate.no_lag_reason
    assert estimate.difference_mps < 0.1


@pytest.mark.parametrize(
    ("changes", "shift", "why"),
    [
        ((), 2.0, r"^the speed hardly changes: shifted by -5\.0 s, only \d+ valid GNSS epochs "),
        (CRUISE_CHANGES, 30.0, r"^no shift matches"),
    ],
)
def test_a_featureless_cruise_or_an_offset_beyond_the_range_gives_no_lag(changes, shift, why):
    wheel = _cruise(changes)
    estimate = estimate_clock_offset(wheel.shifted(-shift), *_noisy_gnss_speed(wheel))
    assert estimate.residual_s is None and re.search(why, estimate.no_lag_reason)


def _random_cruise(seed: int) -> SensorSeries:
    """120 s at 25 m/s with three smooth speed changes at random times (±5 m/s over 2-8 s)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 120.0, 0.01)
    v = np.full_like(t, 25.0) + rng.normal(0.0, 0.01, t.size)
    for _ in range(3):
        start, change, duration = rng.uniform(5, 110), rng.uniform(-5, 5), rng.uniform(2, 8)
        v += change * (1 - np.cos(np.pi * np.clip((t - start) / duration, 0.0, 1.0))) / 2
    return SensorSeries(t, v, "speed", "m/s")


@pytest.mark.parametrize(
    ("seed", "shift"), [(9, 60.0), (22, 60.0), (31, -30.0), (36, -30.0), (48, 30.0), (57, 60.0)]
)
def test_a_cruise_far_off_gets_no_lag_from_a_match_above_the_noise(seed, shift):
    """Over all epochs these shifted cruises matched best at a wrong lag inside the range, at
    a median difference 2.3 to 12 times the GNSS speed's noise (a true lag leaves 0.65 times
    it): that is no match, and neither is one over the speed changes."""
    wheel = _random_cruise(seed)
    estimate = estimate_clock_offset(wheel.shifted(-shift), *_noisy_gnss_speed(wheel))
    assert estimate.residual_s is None, estimate


def test_too_few_overlapping_epochs_give_no_lag():
    t_gnss = np.arange(5.0, 55.0, 0.2)
    estimate = estimate_clock_offset(SPEED.shifted(100.0), t_gnss, np.full_like(t_gnss, 10.0))
    assert estimate.residual_s is None
    assert estimate.no_lag_reason == (
        "only 0 valid GNSS epochs lie inside the wheel speed's span, 20 needed"
    )


def test_origin_far_from_the_approximate_position_is_a_warning():
    enu = EnuFrame(np.radians(35.6938), np.radians(139.7034), 77.0)
    near = enu.enu_to_ecef(np.array([3000.0, 4000.0, 0.0]))
    assert origin_warning(enu, near) is None
    far = enu.enu_to_ecef(np.array([30_000.0, 40_000.0, 0.0]))
    assert "50.0 km from the manifest's origin" in origin_warning(enu, far)
    assert origin_warning(enu, np.zeros(3)) is None
    assert origin_warning(enu, far / np.linalg.norm(far) * 7.5e6) is None  # 1,100 km up
    assert origin_warning(enu, np.array([np.nan, 0.0, 0.0])) is None
    assert origin_warning(enu, None) is None


def test_standstill_that_moves_is_an_error_and_a_still_one_passes():
    t = np.arange(0.0, 30.0, 0.1)
    speed = np.where(t < 10.0, 0.05 * np.sin(7 * t), 8.0)  # still, then 8 m/s
    check_standstill_is_still((1.0, 9.0), t, speed, "wheel speed")
    check_standstill_is_still((40.0, 50.0), t, speed, "wheel speed")  # no sample: not judged
    moving = r"standstill 8\.00–20\.00 s: the wheel speed shows .*median 8\.00"
    with pytest.raises(InputError, match=moving):
        check_standstill_is_still((8.0, 20.0), t, speed, "wheel speed")


def test_a_wheel_speed_covering_half_the_epochs_is_a_warning_naming_the_offset():
    """The QA case: the CAN clock 30 s off, so half the GNSS epochs have no wheel speed (the
    lag search of ±5 s cannot find such an offset)."""
    t_gnss = np.arange(0.0, 60.0, 0.1)
    late = SensorSeries(T + 30.0, SPEED.value)
    warning = coverage_warning("CAN", late, t_gnss, 12.5, "--time-offset-can")
    assert "CAN clock: the wheel speed covers only 50% of the GNSS epochs" in warning
    assert "(it starts +30.0 s and ends +30.1 s from them)" in warning
    assert warning.endswith("check --time-offset-can 12.500 s")
    assert coverage_warning("CAN", SensorSeries(T + 5.0, SPEED.value), t_gnss, 0.0, "x") is None
    assert coverage_warning("CAN", SensorSeries(T + 7.0, SPEED.value), t_gnss, 0.0, "x")


def test_vehicle_signals_covering_part_of_the_drive_are_not_blamed_on_the_clock():
    """Issue 30: the coverage warning suggested a clock error when the signals simply cover part
    of the drive. A wheel speed over 20-40 s of a 60-s GNSS record (its clock right): part
    coverage, with the clock check's confirmation when it has one; shifted by 30 s over as long
    a record: a clock offset, naming the option."""
    t_gnss = np.arange(0.0, 60.0, 0.1)
    inside = (T >= 20.0) & (T <= 40.0)
    part = SensorSeries(T[inside], SPEED.value[inside])
    confirmed = ClockOffsetEstimate(0.01)
    said = coverage_warning("CAN", part, t_gnss, 12.5, "--time-offset-can", confirmed)
    assert said.startswith("CAN: the wheel speed covers only 34% of the GNSS epochs")
    assert "(clock residual +0.01 s), so the vehicle signals cover part of the drive" in said
    assert "check --" not in said
    unchecked = coverage_warning("CAN", part, t_gnss, 12.5, "--time-offset-can")
    assert "recorded over 20.0 s of the 59.9 s of GNSS, so they cover part of the drive" in (
        unchecked
    )
    assert "check --" not in unchecked
    shifted = SensorSeries(T + 30.0, SPEED.value)
    for clock in (None, ClockOffsetEstimate(None, no_lag_reason="no match")):
        offset = coverage_warning("CAN", shifted, t_gnss, 12.5, "--time-offset-can", clock)
        assert offset.startswith("CAN clock: the wheel speed covers only 50% of the GNSS epochs")
        assert "shifted by +30.0 s" in offset and offset.endswith(
            "check --time-offset-can 12.500 s"
        )
    # through the calibration's checks: the clock confirmed over the overlap
    velocity = velocity_solution(
        t_gnss,
        np.column_stack(
            [np.zeros_like(t_gnss), np.interp(t_gnss, SPEED.t, SPEED.value), 0 * t_gnss]
        ),
        np.ones(t_gnss.size, bool),
    )
    _, found = calibration_warnings(part, velocity, 1.0, "CAN", 0.0)
    assert len(found) == 1 and "cover part of the drive: not a clock offset" in found[0]


@pytest.mark.parametrize("scale", [1.0, 1.099, 0.901, float("nan")])
def test_wheel_scales_within_ten_percent_pass(scale):
    assert wheel_scale_warning(scale) is None


@pytest.mark.parametrize("scale", [1 / 3.6, 1.101, 0.899, 1.609])
def test_wheel_scales_beyond_ten_percent_are_a_warning(scale):
    assert f"the calibration gives {scale:.3f}, beyond 1 ± 0.1" in wheel_scale_warning(scale)


def _gnss_of_speed():
    """GNSS epochs at 5 Hz over 5–55 s with SPEED's exact value northwards, every 4th
    invalid: the times, the speeds (NaN where invalid) and the velocity solution."""
    t_gnss = np.arange(5.0, 55.0, 0.2)
    gnss = np.interp(t_gnss, SPEED.t, SPEED.value)
    gnss[::4] = np.nan
    velocity = velocity_solution(
        t_gnss,
        np.column_stack([np.zeros_like(gnss), np.nan_to_num(gnss), np.zeros_like(gnss)]),
        np.isfinite(gnss),
    )
    return t_gnss, gnss, velocity


def test_calibration_warnings_gather_the_clock_and_the_scale():
    velocity = _gnss_of_speed()[2]
    estimate, found = calibration_warnings(SPEED, velocity, 1.0, "CAN", 0.0)
    assert estimate.residual_s == pytest.approx(0.0, abs=0.01) and found == []
    late = SensorSeries(T, SPEED.value * 3.6).shifted(-1.0)  # km/h, 1 s late
    estimate, found = calibration_warnings(late, velocity, 1 / 3.6, "speed CSV", 2.0, "--x")
    assert estimate.residual_s == pytest.approx(1.0, abs=0.01)
    assert len(found) == 2
    assert (
        found[0].startswith("speed CSV clock") and "--x 2.000 s should be about 3.000" in found[0]
    )
    assert found[1].startswith("wheel scale: the calibration gives 0.278")
    assert calibration_warnings(late, velocity, None, "speed CSV", 2.0, "--x")[1] == found[:1]


def test_a_wheel_speed_the_calibration_never_saw_is_judged_by_its_ratio_to_the_doppler_speed():
    """A 20-s drive with its speed in km/h kept the scale of 1: the calibration takes only
    Doppler speeds within 10 % of the wheel speed, so it never estimated one (QA round 3)."""
    t_gnss, gnss, velocity = _gnss_of_speed()
    kmh = SensorSeries(T, SPEED.value * 3.6)
    (warning,) = calibration_warnings(kmh, velocity, 1.0, "CAN", 0.0)[1]
    assert warning.startswith(
        "wheel scale: the calibration gives 1.000 from the Doppler speeds within 10 % of the "
        "wheel speed, but over 187 valid GNSS epochs the Doppler speed is the wheel speed times "
        "0.278, beyond 1 ± 0.1"
    )
    assert calibration_warnings(kmh, velocity, None, "CAN", 0.0)[1] == []  # a fixed scale
    assert speed_ratio_warning(SPEED, t_gnss, gnss, 1.0) is None
    assert speed_ratio_warning(kmh, t_gnss[:19], gnss[:19], 1.0) is None  # too few epochs


# A drive at 8 m/s: straight, a left turn of 90° (10–13 s, 30 °/s), straight, a right turn of
# 90° (25–28 s), straight; GNSS course at 10 Hz with 0.5° of noise, gyro at 100 Hz with a bias
# of 0.3 °/s.
T_GNSS = np.arange(0.0, 40.0, 0.1)
T_GYRO = np.arange(-1.0, 41.0, 0.01)
TURN_RATE = np.radians(30.0)


def _true_rate(t: np.ndarray) -> np.ndarray:
    return TURN_RATE * (((t >= 10) & (t < 13)).astype(float) - ((t >= 25) & (t < 28)))


def _true_yaw(t: np.ndarray) -> np.ndarray:
    return TURN_RATE * (np.clip(t - 10, 0, 3) - np.clip(t - 25, 0, 3))


def _drive(course_error=None, gnss_speed=8.0, valid=None):
    """Heading table, conventional velocity, wheel speed and yaw rate of the drive above."""
    noise = np.random.default_rng(3).normal(0.0, np.radians(0.5), T_GNSS.size)
    course = _true_yaw(T_GNSS) + noise + (0.0 if course_error is None else course_error)
    speed = np.broadcast_to(gnss_speed, T_GNSS.shape)
    enu = np.column_stack([speed * np.cos(course), speed * np.sin(course), np.zeros_like(speed)])
    valid = np.ones(T_GNSS.size, bool) if valid is None else valid
    table = plain_heading_table(
        T_GNSS,
        yaw_conv=np.where(valid, course, np.nan),
        conv_valid=valid,
        conv_gnss_valid=valid,
        sigma_conv_gnss=np.where(valid, np.radians(0.5), np.nan),
    )
    wheel = SensorSeries(T_GYRO, np.full_like(T_GYRO, 8.0), "speed", "m/s")
    gyro = SensorSeries(T_GYRO, _true_rate(T_GYRO) + np.radians(0.3), "yaw", "rad/s")
    return table, velocity_solution(T_GNSS, enu, valid), wheel, gyro


def _negated(series: SensorSeries) -> SensorSeries:
    return SensorSeries(series.t, -series.value, series.name, series.unit)


SIGN_SOURCE = VehicleSignalSource(yaw_rate="yaw.csv", yaw_rate_sign_fix="negate the column")


def test_a_yaw_rate_of_the_right_sign_agrees_with_the_doppler_course_over_both_turns():
    table, velocity, wheel, gyro = _drive()
    found = check_yaw_rate_sign(table, velocity, wheel, gyro, SIGN_SOURCE)
    assert found.agreement == 1.0 and found.turns == 2
    assert np.degrees(found.turn_rad) == pytest.approx(180.0, abs=3.0)


def test_a_yaw_rate_of_the_wrong_sign_is_an_error_naming_the_fix():
    table, velocity, wheel, gyro = _drive()
    assert yaw_rate_sign_agreement(table, velocity, wheel, _negated(gyro)).agreement == -1.0
    with pytest.raises(InputError) as info:
        check_yaw_rate_sign(table, velocity, wheel, _negated(gyro), SIGN_SOURCE)
    message = str(info.value)
    assert message.startswith("yaw.csv: wrong sign: over 2 turn(s) totalling 18")
    assert "sign agreement -1.00" in message and message.endswith("; negate the column")


def test_without_enough_turning_there_is_no_verdict():
    table, velocity, wheel, gyro = _drive()
    straight = SensorSeries(gyro.t, np.full_like(gyro.t, np.radians(0.3)))
    flat = plain_heading_table(T_GNSS, conv_gnss_valid=np.ones(T_GNSS.size, bool))
    found = check_yaw_rate_sign(flat, velocity, wheel, straight)  # no turn: no error
    assert found.turns == 0 and np.isnan(found.agreement)
    # one gentle turn of 20° (below the 30° needed) with the wrong sign: no verdict either
    gentle = SensorSeries(gyro.t, _true_rate(gyro.t) * (gyro.t >= 20) / 4.5)  # 25–28 s
    table = plain_heading_table(
        T_GNSS,
        yaw_conv=integral_at(gentle.t, gentle.value, T_GNSS),
        conv_gnss_valid=np.ones(T_GNSS.size, bool),
    )
    found = check_yaw_rate_sign(table, velocity, wheel, _negated(gentle))
    assert found.agreement == -1.0 and np.degrees(found.turn_rad) == pytest.approx(20.0, abs=1)


def test_reflected_courses_in_the_turns_and_at_a_wrong_speed_do_not_count():
    # in both turns the course is mirrored (a reflection): ends inside a turn would see the
    # course turn against the gyro; only the straights before and after a turn count
    in_turn = ((T_GNSS >= 10) & (T_GNSS < 13)) | ((T_GNSS >= 25) & (T_GNSS < 28))
    error = np.where(in_turn, -2.0 * _true_yaw(T_GNSS), 0.0)
    table, velocity, wheel, gyro = _drive(course_error=error)
    assert yaw_rate_sign_agreement(table, velocity, wheel, gyro).agreement == 1.0
    # a course turned by 120° on a straight at half the wheel speed is no turn at all
    wrong = (T_GNSS >= 30) & (T_GNSS < 31)
    table, velocity, wheel, gyro = _drive(
        course_error=np.where(wrong, np.radians(120.0), 0.0),
        gnss_speed=np.where(wrong, 4.0, 8.0),
    )
    found = yaw_rate_sign_agreement(table, velocity, wheel, gyro)
    assert found.agreement == 1.0 and found.turns == 2


def test_a_gyro_bias_beyond_a_car_sensor_is_a_warning():
    assert gyro_bias_warning(np.radians(3.9)) is None
    assert gyro_bias_warning(float("nan")) is None
    warning = gyro_bias_warning(np.radians(-5.9))
    assert warning.startswith("gyro bias: the calibration gives -5.90 °/s, beyond the ±4 °/s")
    assert "counter-clockwise positive" in warning


def test_heading_warnings_gather_the_bias_and_raise_for_the_sign():
    table, velocity, wheel, gyro = _drive()
    table.gyro_bias[:] = np.radians(6.0)
    _, found = heading_warnings(table, velocity, wheel, gyro, SIGN_SOURCE)
    assert [w for w in found if w.startswith("gyro bias: the calibration gives +6.00 °/s")]
    _, fixed = heading_warnings(table, velocity, wheel, gyro, SIGN_SOURCE, bias_calibrated=False)
    assert not [w for w in fixed if w.startswith("gyro bias")]
    with pytest.raises(InputError, match="wrong sign"):
        heading_warnings(table, velocity, wheel, _negated(gyro), SIGN_SOURCE)
