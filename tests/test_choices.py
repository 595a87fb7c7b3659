"""choices: a value outside its choice set is refused naming the field and the allowed values;
a configuration holds members, which compare equal to their strings; the library's entry points
check their choices before any work."""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import StrEnum
from pathlib import Path

import numpy as np
import pytest

from vo_doppler.batch import run_batch
from vo_doppler.choices import (
    ChoiceError,
    allowed,
    check_fields,
    checked,
    checked_letters,
    kind_of,
    values,
)
from vo_doppler.errors import InputError
from vo_doppler.fusion.placement import initial_yaw_offset, yaw_offset
from vo_doppler.io.kitti_raw_import import import_kitti_raw
from vo_doppler.io.rosbag_import import RosbagOptions, RosClock, StampSource
from vo_doppler.io.trajectory import read_trajectory
from vo_doppler.io.truth_csv import read_ground_truth
from vo_doppler.model.signals import DEFAULT_SYSTEMS, SatelliteSystem
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.run import RunConfig
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig
from vo_doppler.sim.vo_sequence import ImageFormat, generate_vo_sequence
from vo_doppler.vo.frames import vehicle_trajectory


class RoadSurface(StrEnum):
    ASPHALT = "asphalt"
    GRAVEL = "gravel"


@dataclass(frozen=True)
class _Config:
    surface: RoadSurface = RoadSurface.ASPHALT

    def __post_init__(self) -> None:
        check_fields(self, surface=RoadSurface)


def test_the_choice_set_in_words_and_its_values_in_order():
    assert kind_of(RoadSurface) == "road surface"
    assert values(RoadSurface) == ("asphalt", "gravel")
    assert all(type(value) is str for value in values(RoadSurface))
    assert allowed(RoadSurface) == "asphalt, gravel"


def test_a_string_becomes_its_member_and_still_equals_the_string():
    config = _Config("gravel")
    assert config.surface is RoadSurface.GRAVEL
    assert config.surface == "gravel" and f"{config.surface}" == "gravel"
    assert replace(config, surface="asphalt").surface is RoadSurface.ASPHALT


@pytest.mark.parametrize("bad", ["Gravel", "", None, 1])
def test_a_value_outside_the_set_names_the_field_and_the_choices(bad):
    with pytest.raises(ChoiceError) as raised:
        _Config(bad)
    assert str(raised.value) == (
        f"_Config.surface: unknown road surface {bad!r}; choose from asphalt, gravel"
    )
    assert isinstance(raised.value, InputError) and isinstance(raised.value, ValueError)


def test_checked_names_the_argument_it_is_given():
    assert checked(RoadSurface, "asphalt", "surface") is RoadSurface.ASPHALT
    with pytest.raises(ChoiceError, match=r"^surface: unknown road surface 'ice'; choose from"):
        checked(RoadSurface, "ice", "surface")


def test_gnss_systems_are_letters_of_the_satellite_systems():
    assert checked_letters(SatelliteSystem, "GE", "systems") == "GE"
    assert RunConfig().systems == DEFAULT_SYSTEMS == "GREJC"
    assert "".join(SatelliteSystem) == "GRECJSI"
    with pytest.raises(
        ChoiceError,
        match=r"^RunConfig.systems = 'Gx': unknown satellite system 'x'; choose from G, R, E, C, "
        r"J, S, I$",
    ):
        RunConfig(systems="Gx")
    with pytest.raises(ChoiceError, match=r"^RunConfig.systems: expected letters among G, R"):
        RunConfig(systems="")


def _trajectory():
    return Trajectory.from_matrices(np.zeros(1), np.eye(4)[None])


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: read_trajectory("a.txt", "csv"), "fmt: unknown trajectory format 'csv'"),
        (lambda: read_ground_truth("a.txt", "kml"), "fmt: unknown truth format 'kml'"),
        (lambda: vehicle_trajectory(_trajectory(), world="up"), "world: unknown world 'up'"),
        (lambda: run_batch([], Path("out"), executor="slurm"), "executor: unknown executor"),
        (lambda: import_kitti_raw("d", "o", "image_04"), "camera: unknown kitti camera"),
        (lambda: generate_vo_sequence("o", image_format="gif"), "image_format: unknown image"),
        (lambda: UrbanCanyonConfig(image_format="gif"), "UrbanCanyonConfig.image_format: "),
        (lambda: RosbagOptions(stamps="now"), "RosbagOptions.stamps: unknown stamp source 'now'"),
        (lambda: RosbagOptions(clock="tai"), "RosbagOptions.clock: unknown ros clock 'tai'"),
        (lambda: initial_yaw_offset(None, None, None, source="gps"), "source: unknown heading"),
        (
            lambda: yaw_offset(_trajectory(), np.zeros(1), np.zeros(1), "yaw"),
            "reference: unknown heading reference 'yaw'; choose from course, orientation$",
        ),
    ],
)
def test_the_librarys_choices_are_checked_before_any_work(call, message, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ChoiceError, match=f"^{message}"):
        call()
    assert list(tmp_path.iterdir()) == []


def test_a_configuration_holds_the_members_of_its_strings():
    assert UrbanCanyonConfig(image_format="jpg").image_format is ImageFormat.JPG
    options = RosbagOptions(stamps="receive", clock="gnss")
    assert (options.stamps, options.clock) == (StampSource.RECEIVE, RosClock.GNSS)
