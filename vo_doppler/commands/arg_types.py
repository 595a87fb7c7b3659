"""Argument types shared by several commands (argparse ``type=`` callables), and the options
that several commands define alike."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from vo_doppler.bounds import lever_arm_problem
from vo_doppler.gnss.signals import bands_problem


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


def number_in(
    low: float | None = None,
    high: float | None = None,
    *,
    low_open: bool = False,
    high_open: bool = False,
    unit: str = "",
) -> Callable[[str], float]:
    """argparse type: a finite number within ``[low, high]`` (a bound None is absent, an open
    bound excluded). NaN and infinities are refused: no option of a physical quantity means
    anything with them, and they pass every comparison a later check would make."""
    bounds = []
    if low is not None:
        bounds.append(f"{'>' if low_open else '≥'} {low:g}")
    if high is not None:
        bounds.append(f"{'<' if high_open else '≤'} {high:g}")
    wanted = "a number " + " and ".join(bounds) if bounds else "a finite number"
    wanted += f" ({unit})" if unit else ""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        inside = math.isfinite(value)
        if inside and low is not None:
            inside = value > low if low_open else value >= low
        if inside and high is not None:
            inside = value < high if high_open else value <= high
        if not inside:
            raise argparse.ArgumentTypeError(f"expected {wanted}, got {text!r}")
        return value

    parse.__name__ = wanted
    return parse


finite_float = number_in()
"""A finite number (an offset, a bias: any sign)."""
positive_float = number_in(0.0, low_open=True)
"""A number > 0 (a duration, a rate, a scale)."""
non_negative_float = number_in(0.0)
"""A number ≥ 0 (a distance or threshold where 0 switches the step off)."""
elevation_mask_deg = number_in(0.0, 90.0, high_open=True, unit="degrees")
"""An elevation mask: 0 keeps every satellite above the horizon, 90 none."""
MAX_FPS = 1000.0
"""Upper bound of a camera frame rate (Hz): beyond any camera a VO could track with."""
frame_rate = number_in(0.0, MAX_FPS, low_open=True, unit="Hz")
"""A camera frame rate in (0, MAX_FPS] Hz (``vo --fps``, ``simulate --fps``)."""


def int_in(low: int, high: int | None = None) -> Callable[[str], int]:
    """argparse type: an integer within ``[low, high]`` (no upper bound when None)."""
    wanted = f"an integer ≥ {low}" + ("" if high is None else f" and ≤ {high}")

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(f"expected {wanted}, got {text!r}") from exc
        if value < low or (high is not None and value > high):
            raise argparse.ArgumentTypeError(f"expected {wanted}, got {text!r}")
        return value

    parse.__name__ = wanted
    return parse


def band_digits(text: str) -> str:
    """argparse type: RINEX band digits (1-9), e.g. ``12`` for L1 and L2."""
    problem = bands_problem(text)
    if problem:
        raise argparse.ArgumentTypeError(problem)
    return text


def system_letters(allowed: str) -> Callable[[str], str]:
    """argparse type: GNSS system letters (RINEX: G, R, E, C, J, ...) among ``allowed``, upper
    case, e.g. ``GE``."""

    def parse(text: str) -> str:
        letters = text.upper()
        if not letters or set(letters) - set(allowed):
            raise argparse.ArgumentTypeError(f"systems are letters of {allowed}, got {text!r}")
        return letters

    parse.__name__ = f"letters of {allowed}"
    return parse


def lever_arm(components: tuple[int, ...] = (2, 3)) -> Callable[[str], tuple[float, ...]]:
    """argparse type: a GNSS antenna lever arm ``X,Y[,Z]`` in metres (as many components as
    ``components`` allows), finite and no longer than a vehicle
    (:func:`vo_doppler.bounds.lever_arm_problem`, as for sequence.yaml)."""
    shape = " or ".join(",".join("XYZ"[:n]) for n in components)

    def parse(text: str) -> tuple[float, ...]:
        try:
            values = tuple(float(v) for v in text.split(","))
        except ValueError as exc:
            raise argparse.ArgumentTypeError(f"{text!r}: expected {shape} (m)") from exc
        if len(values) not in components or not all(math.isfinite(v) for v in values):
            raise argparse.ArgumentTypeError(f"{text!r}: expected {shape} (m)")
        problem = lever_arm_problem(values)
        if problem:
            raise argparse.ArgumentTypeError(f"{text!r}: {problem}")
        return values

    return parse


def add_yaw_rate_sign(group) -> None:
    """``--yaw-rate-sign`` (+1 or −1, default +1) of a CAN yaw-rate signal: −1 makes a bus that
    reports clockwise-positive yaw rate counter-clockwise positive, as the project's yaw is."""
    group.add_argument(
        "--yaw-rate-sign",
        type=float,
        choices=(1.0, -1.0),
        default=1.0,
        help="-1 when the bus reports clockwise-positive yaw rate",
    )
