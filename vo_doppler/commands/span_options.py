"""``--start`` / ``--end``: part of a recording, for ``run``, ``heading``, ``gnss`` and ``vo``
(:mod:`vo_doppler.model.time_span`)."""

from __future__ import annotations

import argparse

from vo_doppler.model.time_span import GPS_PREFIX, SpanBound, TimeSpan


def span_bound(text: str) -> SpanBound:
    """argparse type: seconds from the first epoch, or ``gps:T``."""
    try:
        return SpanBound.parse(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_span_options(
    parser: argparse.ArgumentParser, first: str = "first GNSS epoch", gps_base: str = ""
) -> None:
    """Add ``--start`` and ``--end``; ``first`` names what the seconds count from, ``gps_base``
    (if any) the time base a ``gps:`` time is read in."""
    group = parser.add_argument_group(
        "part of the recording (both bounds inclusive; default: all of it)"
    )
    group.add_argument(
        "--start",
        type=span_bound,
        metavar="T",
        help=f"process from T on: seconds (e.g. 30) from the {first}, or a GPS time written "
        f"{GPS_PREFIX}SECONDS (e.g. {GPS_PREFIX}1425953430.5){gps_base}; must lie inside the "
        "recording",
    )
    group.add_argument(
        "--end",
        type=span_bound,
        metavar="T",
        help="process up to T (the same two forms), after --start",
    )
    parser.add_check(lambda args: time_span(args).problem())


def time_span(args: argparse.Namespace) -> TimeSpan:
    """The :class:`TimeSpan` of the parsed ``--start`` / ``--end``."""
    return TimeSpan(args.start, args.end)
