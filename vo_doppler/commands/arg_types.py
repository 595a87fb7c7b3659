"""Argument types shared by several commands (argparse ``type=`` callables)."""

from __future__ import annotations

import argparse


def positive_int(text: str) -> int:
    """An integer ≥ 1 (e.g. a worker count or a downsampling factor)."""
    try:
        value = int(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"expected an integer ≥ 1, got {text!r}") from exc
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected an integer ≥ 1, got {text!r}")
    return value


def window_size(text: str) -> int:
    """argparse type: a sliding-window length of at least 3 frames."""
    value = int(text)
    if value < 3:
        raise argparse.ArgumentTypeError(f"must be at least 3 frames, got {value}")
    return value
