"""choices: a value outside its choice set is refused naming the field and the allowed values;
a configuration holds members, which compare equal to their strings."""

from __future__ import annotations

from dataclasses import dataclass, replace
from enum import StrEnum

import pytest

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
from vo_doppler.model.signals import DEFAULT_SYSTEMS, SatelliteSystem
from vo_doppler.run import RunConfig


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
