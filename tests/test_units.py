"""units: the unit a configuration field's name ends in, and its value in people units."""

from __future__ import annotations

import dataclasses
import importlib
import math
import pkgutil
import types
import typing
from enum import Enum

import pytest

import vo_doppler
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
        ("clock_bias_walk_m_per_sqrt_s", "m/√s"),
        ("clock_drift_walk_mps_per_sqrt_s", "m/s/√s"),
        ("yaw_rate_bias_dps", "deg/s"),
        ("yaw_bias_walk_dps_per_sqrt_s", "deg/s/√s"),
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


UNITLESS: dict[str, str] = {
    # counts
    "window_size": "frames",
    "max_features": "corners",
    "min_features": "corners",
    "grid_rows": "cells",
    "grid_cols": "cells",
    "klt_levels": "pyramid levels",
    "init_min_points": "points",
    "pnp_min_inliers": "points",
    "keyframe_max_gap": "frames",
    "ba_every_keyframes": "keyframes",
    "ba_max_iterations": "iterations",
    "ba_threads": "threads",
    "ba_fixed_oldest": "poses",
    "min_samples": "samples",
    "min_fit_measurements": "measurements",
    "start_measurements": "measurements",
    "min_window_equations": "equations",
    "min_obs": "observations",
    "grid_size": "grid points",
    "gauss_newton_iterations": "iterations",
    "robust_passes": "passes",
    "redescending_passes": "passes",
    "outlier_passes": "passes",
    "passes": "passes",
    "huber_passes": "passes",
    "cauchy_passes": "passes",
    "min_support": "agreeing windows (Σ w_j/n_j)",
    "max_variance_factor": "ratio of residual scale to σ",
    "reliability_epochs": "epochs",
    "reliability_min_epochs": "epochs",
    "min_neighbours": "epochs",
    "min_tested_for_scale": "epochs",
    "degree": "a polynomial's degree",
    "downsample": "keep every n-th fix",
    "blocks": "street blocks (x, y)",
    "buildings_per_side": "buildings",
    "corner_streets": "street indices",
    "window_facades": "facade tiles",
    "textures": "textures",
    "stops_per_lap": "stops",
    "seed": "a random seed",
    "jpeg_quality": "JPEG quality 0-100",
    "leap_seconds": "a count of leap seconds (GPS - UTC)",
    # ratios, fractions and scale factors
    "calibration_max_speed_mismatch_ratio": "a fraction of the wheel speed",
    "prior_wheel_scale_sigma": "σ of a scale factor",
    "tight_scale_max_sigma": "σ of a scale factor",
    "scale_sigma": "σ of a scale factor",
    "fixed_wheel_scale": "a scale factor",
    "wheel_scale_error": "a scale factor's error",
    "calib_focal_error": "a fraction of the focal length",
    "measurement_scale": "s of (B2), a factor on σ",
    "sigma_turn": "σ_ψ of (B1), rad per √rad: a relative yaw-scale error, no degree form",
    "default_sigma_turn": "σ_ψ of (B1)",
    "min_sigma_turn": "σ_ψ of (B1)",
    "grade_sigma": "σ of a road grade (rise over run)",
    "min_sigma": "σ of a road grade (rise over run)",
    "vertical_ratio": "vertical σ over horizontal σ",
    "anchor_weight": "a relative weight",
    "observability_ratio": "an eigenvalue ratio",
    "corner_quality": "a fraction of the best corner's score",
    "replenish_below": "a fraction of max_features",
    "reliability_agreement": "a fraction of the earlier headings",
    "testable_redundancy": "a redundancy number",
    "outlier_fraction": "ε of (B3″)",
    "nlos_reflective_fraction": "a fraction of the surfaces",
    "ground_contrast": "a fraction of the facades' contrast",
    "vignetting": "a fraction of the brightness",
    "light_variation": "σ of log ambient light",
    "exposure_rate": "a fraction of the exposure error per frame",
    "gain_range": "camera gains",
    "k": "[KZ]'s weight of gyro 2",
    "ba_function_tolerance": "a relative cost change",
    # probabilities and tuning constants in units of σ
    "false_alarm": "a probability",
    "outlier_alpha": "a probability",
    "identification_odds": "a likelihood ratio",
    "huber_k": "in σ of the residuals",
    "cauchy_c": "in σ of the residuals",
    "student_dof": "degrees of freedom",
    "noise_model_dof": "degrees of freedom",
    "ambiguity_chi2": "a χ² value",
    "reliability_n_sigma": "in σ",
    # names, letters and units in the name itself
    "systems": "RINEX system letters (choices.checked_letters)",
    "channel": "a CAN interface name",
    "fps": "frames per second: the unit is the name",
    "origin": "geodetic latitude and longitude (deg) and height (m), as in sequence.yaml",
}
"""Configuration fields without a unit, by name, with what they count or compare (the rule of
docs/design.md, "Choices and units"). Flags (``bool``), choices (``StrEnum``) and nested
configurations need no entry."""


def _configurations() -> dict[str, type]:
    """Every dataclass of the package whose name ends in ``Config``."""
    found = {}
    for info in pkgutil.walk_packages(vo_doppler.__path__, "vo_doppler."):
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if (
                isinstance(value, type)
                and dataclasses.is_dataclass(value)
                and name.endswith("Config")
                and value.__module__ == module.__name__
            ):
                found[f"{module.__name__}.{name}"] = value
    return found


def _needs_no_unit(kind) -> bool:
    """A flag, a choice or a nested dataclass (alone or or-None)."""
    kinds = typing.get_args(kind) if isinstance(kind, types.UnionType) else (kind,)
    kinds = [k for k in kinds if k is not type(None)]
    return all(
        k is bool or (isinstance(k, type) and (issubclass(k, Enum) or dataclasses.is_dataclass(k)))
        for k in kinds
    )


def test_every_configuration_field_has_a_unit_rule():
    configurations = _configurations()
    assert {"vo_doppler.run_stages.RunConfig", "vo_doppler.sim.can_bus.CanSimConfig"} <= set(
        configurations
    )
    assert len(configurations) >= 19
    without, used = [], set()
    for path, config in configurations.items():
        kinds = typing.get_type_hints(config)
        for field in dataclasses.fields(config):
            if unit_of(field.name) is not None or _needs_no_unit(kinds[field.name]):
                continue
            if field.name in UNITLESS:
                used.add(field.name)
            else:
                without.append(f"{path}.{field.name}")
    assert without == [], "fields with neither a unit suffix nor an entry in UNITLESS"
    assert set(UNITLESS) - used == set(), "UNITLESS entries no configuration has (left over)"


def test_a_unitless_name_has_no_unit_suffix():
    assert [name for name in UNITLESS if unit_of(name) is not None] == []
