"""units: the unit a configuration field's name ends in, and its value in people units."""

from __future__ import annotations

import math

import pytest

from vo_doppler.units import UNITS, in_people_units, unit_of


@pytest.mark.parametrize(
    ("name", "symbol"),
    [
        ("window_s", "s"),
        ("max_yaw_drift_rad_s", "rad/s"),
        ("gate_rad", "rad"),
        ("sigma_distance_rad_per_sqrt_m", "rad/√m"),
        ("angle_random_walk_rad_per_sqrt_s", "rad/√s"),
        ("bias_walk_rad_per_s_sqrt_s", "rad/s/√s"),
        ("max_window_m", "m"),
        ("min_speed_mps", "m/s"),
        ("max_speed_drift_mps2", "m/s²"),
        ("yaw_rate_bias_dps", "deg/s"),
        ("cn0_zenith_dbhz", "dB-Hz"),
        ("nlos_loss_db", "dB"),
    ],
)
def test_the_longest_suffix_names_the_unit(name, symbol):
    assert unit_of(name).symbol == symbol


@pytest.mark.parametrize("name", ["huber_k", "min_samples", "window_size", "passes", "smooth"])
def test_a_name_without_a_unit_suffix_has_none(name):
    assert unit_of(name) is None


def test_every_suffix_is_distinct_and_only_angles_change_for_people():
    suffixes = [unit.suffix for unit in UNITS]
    assert len(set(suffixes)) == len(suffixes)
    converted = {unit.suffix for unit in UNITS if unit.people_suffix is not None}
    assert converted == {
        "_rad",
        "_rad_s",
        "_rad_per_sqrt_m",
        "_rad_per_sqrt_s",
        "_rad_per_s_sqrt_s",
    }


def test_angles_are_shown_in_degrees_with_their_name():
    assert in_people_units("gate_rad", math.pi / 36) == ("gate_deg", pytest.approx(5.0), "deg")
    name, value, symbol = in_people_units("prior_gyro_bias_sigma_rad_s", math.radians(0.5))
    assert (name, symbol) == ("prior_gyro_bias_sigma_deg_s", "deg/s")
    assert value == pytest.approx(0.5, rel=1e-12)
    unset = ("fixed_gyro_bias_deg_s", None, "deg/s")
    assert in_people_units("fixed_gyro_bias_rad_s", None) == unset
    assert in_people_units("window_s", 2.0) == ("window_s", 2.0, "s")
    assert in_people_units("huber_k", 1.345) == ("huber_k", 1.345, "")
