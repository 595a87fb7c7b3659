"""``--heading-method``: the tight heading's settings as a named choice (``run``, ``batch``,
``heading``)."""

from __future__ import annotations

import argparse

from vo_doppler.choices import values
from vo_doppler.heading.pipeline import HeadingMethod, HeadingPipelineConfig


def add_heading_method_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--heading-method",
        choices=values(HeadingMethod),
        default=HeadingMethod.AUTO.value,
        help="tight heading: snooping (2-s windows, reflected satellites detected and named; "
        "tuned at 10-20 Hz), robust (noise model measured from the data, robust fit, windows "
        "and reliability in seconds, the windows smoothed through the gyro; for 1-Hz "
        "receivers in street canyons) or auto: robust below 10 Hz GNSS, else snooping",
    )


def heading_method_config(method: str) -> HeadingPipelineConfig:
    """The heading stage's configuration of ``--heading-method``."""
    chosen = HeadingMethod(method)
    if chosen is HeadingMethod.ROBUST:
        return HeadingPipelineConfig.robust()
    if chosen is HeadingMethod.AUTO:
        return HeadingPipelineConfig.auto()
    return HeadingPipelineConfig()
