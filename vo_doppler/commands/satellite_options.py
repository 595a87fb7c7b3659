"""The satellite options of the GNSS commands: ``--nav``, or ``--orbits`` + ``--clocks``, and
which satellites to use (``--systems``, ``--elev-mask``)."""

from __future__ import annotations

import argparse
from pathlib import Path

from vo_doppler.commands.arg_types import elevation_mask_deg, system_letters
from vo_doppler.io.rinex_obs import SYSTEMS
from vo_doppler.io.satellite_states import read_satellite_states
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.precise_orbits import PreciseOrbits
from vo_doppler.model.signals import DEFAULT_SYSTEMS


def add_satellite_options(parser: argparse.ArgumentParser, required: bool = True) -> None:
    """``--nav`` or ``--orbits`` (one of them unless the observation file may carry its own
    ephemerides, ``required=False``)."""
    choice = parser.add_mutually_exclusive_group(required=required)
    choice.add_argument(
        "--nav",
        type=Path,
        action="append",
        help="RINEX navigation file (repeat)"
        + (
            ""
            if required
            else "; optional only for a UBX log with GPS subframes (a GnssLogger or GSDC "
            "device_gnss.csv file needs it or --orbits: the GSDC file's own satellite states "
            "are for the library only)"
        ),
    )
    choice.add_argument("--orbits", type=Path, help="SP3-c/d precise orbits (instead of --nav)")
    parser.add_argument("--clocks", type=Path, help="RINEX clock file beside --orbits")


def add_selection_options(parser: argparse.ArgumentParser) -> None:
    """``--systems`` (RINEX letters) and ``--elev-mask`` (degrees), checked as usage errors."""
    parser.add_argument(
        "--systems",
        type=system_letters(SYSTEMS),
        default=DEFAULT_SYSTEMS,
        help="GNSS systems to use (RINEX letters: G, R, E, J, C)",
    )
    parser.add_argument(
        "--elev-mask", type=elevation_mask_deg, default=10.0, help="degrees in [0, 90)"
    )


def satellite_inputs(args: argparse.Namespace) -> list[Path]:
    """The satellite-state files the options name (for the output checks)."""
    return [*(args.nav or ()), *(p for p in (args.orbits, args.clocks) if p is not None)]


def satellite_states(args: argparse.Namespace) -> Navigation | PreciseOrbits:
    """The navigation files or the precise orbits (+ clocks) the options name."""
    return read_satellite_states(args.nav, args.orbits, args.clocks)
