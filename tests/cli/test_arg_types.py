"""Shared argparse types."""

from __future__ import annotations

import argparse

import pytest
from hypothesis import given
from hypothesis import strategies as st

from vo_doppler.commands.arg_types import positive_int, window_size


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
