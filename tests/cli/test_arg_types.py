"""Shared argparse types."""

from __future__ import annotations

import argparse

import pytest
from hypothesis import given
from hypothesis import strategies as st

from vo_doppler.commands.arg_types import (
    band_digits,
    elevation_mask_deg,
    finite_float,
    frame_rate,
    int_in,
    lever_arm,
    non_negative_float,
    number_in,
    positive_float,
    positive_int,
    system_letters,
    window_size,
)


@given(st.integers(min_value=1, max_value=10**9))
def test_positive_int_accepts_every_integer_from_one(value):
    assert positive_int(str(value)) == value


@pytest.mark.parametrize("text", ["0", "-3", "2.5", "two", ""])
def test_positive_int_rejects_with_the_text_named(text):
    with pytest.raises(argparse.ArgumentTypeError, match="integer ≥ 1"):
        positive_int(text)


@pytest.mark.parametrize(("text", "value"), [("3", 3), ("30", 30)])
def test_window_size_accepts_three_frames_and_more(text, value):
    assert window_size(text) == value


def test_window_size_rejects_two_frames():
    with pytest.raises(argparse.ArgumentTypeError, match="at least 3 frames, got 2"):
        window_size("2")


@pytest.mark.parametrize(
    ("kind", "good", "bad"),
    [
        (finite_float, ["-3.5", "0", "1e300"], ["nan", "inf", "-inf", "x", ""]),
        (positive_float, ["1e-9", "2"], ["0", "-1", "nan", "inf"]),
        (non_negative_float, ["0", "3"], ["-1e-9", "nan"]),
        (elevation_mask_deg, ["0", "10", "89.9"], ["90", "95", "-10", "nan"]),
        (frame_rate, ["1e-3", "10", "1000"], ["0", "1000.001", "1e9", "nan", "inf"]),
        (number_in(-1.0, low_open=True), ["-0.5"], ["-1", "-2"]),
        (number_in(0.0, 5.0, unit="s"), ["0", "5"], ["5.0001", "-0.1"]),
    ],
)
def test_number_types_accept_their_domain_and_reject_the_rest(kind, good, bad):
    for text in good:
        assert kind(text) == float(text)
    for text in bad:
        with pytest.raises(argparse.ArgumentTypeError, match=f"got {text!r}"):
            kind(text)


def test_number_messages_give_the_domain_and_unit():
    with pytest.raises(argparse.ArgumentTypeError, match=r"a number ≥ 0 and < 90 \(degrees\)"):
        elevation_mask_deg("90")
    with pytest.raises(argparse.ArgumentTypeError, match="expected a number > 0, got '-1'"):
        positive_float("-1")


def test_int_in_bounds():
    quality = int_in(1, 100)
    assert quality("1") == 1 and quality("100") == 100
    for text in ("0", "101", "2.5"):
        with pytest.raises(argparse.ArgumentTypeError, match="integer ≥ 1 and ≤ 100"):
            quality(text)
    assert int_in(0)("0") == 0


def test_band_digits_and_system_letters():
    assert band_digits("15") == "15"
    for text in ("x", "0", "1a", ""):
        with pytest.raises(argparse.ArgumentTypeError, match="band digits 1-9"):
            band_digits(text)
    systems = system_letters("GE")
    assert systems("ge") == "GE"
    for text in ("XZ", "GR", ""):
        with pytest.raises(argparse.ArgumentTypeError, match="letters of GE"):
            systems(text)


def test_a_lever_arm_is_metres_a_vehicle_can_hold():
    parse = lever_arm()
    assert parse("1.5,0") == (1.5, 0.0)
    assert parse("1.5,0,1.6") == (1.5, 0.0, 1.6)
    assert parse("19.9,0,0") == (19.9, 0.0, 0.0)
    for text, message in (
        ("1000,0,0", "beyond any road vehicle"),
        ("1,2,3,4", "expected X,Y or X,Y,Z"),
        ("1,nan", "expected X,Y or X,Y,Z"),
        ("a,b", "expected X,Y or X,Y,Z"),
    ):
        with pytest.raises(argparse.ArgumentTypeError, match=message):
            parse(text)
    with pytest.raises(argparse.ArgumentTypeError, match="expected X,Y,Z"):
        lever_arm((3,))("1,2")
