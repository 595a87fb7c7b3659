"""``vo-doppler gnss``: Doppler velocity and single-point positions from RINEX files, u-blox UBX
or Android logs (``vo_doppler.io.receiver_file``), with broadcast (``--nav``, or the UBX log's own
subframes) or precise (``--orbits``) satellite states."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

import numpy as np

from vo_doppler.commands.arg_types import band_digits
from vo_doppler.commands.output_paths import check_output_files
from vo_doppler.commands.satellite_options import (
    add_satellite_options,
    add_selection_options,
    satellite_inputs,
    satellite_states,
)
from vo_doppler.errors import InputError, VoDopplerError
from vo_doppler.gnss.doppler_velocity import doppler_codes
from vo_doppler.gnss.pipeline import RANGE_RATE_SOURCES, gnss_velocity
from vo_doppler.gnss.spp import solve_spp
from vo_doppler.io.gnss_csv import write_spp_csv, write_velocity_csv
from vo_doppler.io.receiver_file import read_observation_file
from vo_doppler.io.satellite_states import state_problems
from vo_doppler.model.observations import Observations
from vo_doppler.report.gnss import spp_figure, velocity_figure

log = logging.getLogger(__name__)


def _common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "obs",
        type=Path,
        help="observations: RINEX 2/3 (.gz / Hatanaka ok), u-blox UBX, Android GnssLogger "
        "or GSDC device_gnss.csv (recognised by content)",
    )
    add_satellite_options(parser, required=False)
    add_selection_options(parser)
    parser.add_argument("-o", "--output", type=Path, required=True, help="CSV to write")
    parser.add_argument("--figure", type=Path, help="PNG (default: next to the CSV)")


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "gnss",
        help=summary,
    )
    actions = parser.add_subparsers(dest="gnss_command", metavar="ACTION", required=True)
    velocity = actions.add_parser(
        "velocity",
        help="per-epoch receiver velocity and clock drift from Doppler",
        description="Weighted least squares of ENU velocity and clock drift per epoch from the "
        "Doppler of the chosen systems, with chi-square fault exclusion. Epochs with fewer "
        "than four satellites are written with valid = 0.",
    )
    _common(velocity)
    velocity.add_argument(
        "--bands", type=band_digits, help="RINEX band digits to use, e.g. 12 (default all)"
    )
    velocity.add_argument(
        "--range-rate",
        choices=RANGE_RATE_SOURCES,
        default="doppler",
        help="'phase': carrier-phase rate instead of the logged Doppler",
    )
    velocity.set_defaults(func=run)
    spp = actions.add_parser("spp", help="per-epoch pseudorange single-point positions")
    _common(spp)
    spp.set_defaults(func=run)


def _check_doppler(obs: Observations, systems: str, bands: str | None) -> None:
    """Raise when the file has no Doppler of the chosen systems and bands, naming those it has
    (instead of failing later at every epoch for want of satellites)."""
    if doppler_codes(obs, systems, bands):
        return
    available = [
        f"{system} {' '.join(codes)}"
        for system in sorted(set(obs.system.tolist()))
        if (codes := doppler_codes(obs, system))
    ]
    chosen = f"systems {systems!r}" + (f", bands {bands!r}" if bands else "")
    raise InputError(
        f"the file has no Doppler of the {chosen}; its Doppler observables: "
        + ("; ".join(available) or "none"),
        obs.header.path,
    )


def run(args: argparse.Namespace) -> int:
    figure = args.figure or args.output.with_suffix(".png")
    check_output_files(
        {"output": args.output, "figure": figure}, [args.obs, *satellite_inputs(args)]
    )
    obs, embedded = read_observation_file(args.obs)
    if args.gnss_command == "velocity":
        _check_doppler(obs, args.systems, args.bands)
    nav = satellite_states(args) if args.nav or args.orbits else embedded
    if nav is None:
        raise InputError(
            "no satellite states: give --nav or --orbits (of the files this command reads, only "
            "a UBX log with GPS subframes carries its own; a GSDC file's satellite states are "
            "for the library only, docs/formats.md)",
            args.obs,
        )
    mask = np.deg2rad(args.elev_mask)
    title = f"{args.obs.name} ({args.systems})"
    if args.gnss_command == "spp":
        solution = solve_spp(obs, nav, args.systems, mask)
        write_spp_csv(args.output, solution)
        spp_figure(figure, solution, title)
        valid = solution.valid
    else:
        result = gnss_velocity(obs, nav, args.systems, mask, args.bands, args.range_rate)
        solution = result.velocity
        write_velocity_csv(args.output, solution)
        velocity_figure(figure, solution, title)
        valid = solution.valid
        rows = result.rows
        if rows.n_no_ephemeris:
            log.warning(
                "%d Doppler rows skipped without ephemeris (the satellites above)",
                rows.n_no_ephemeris,
            )
        if valid.any():
            speed = solution.speed_mps[valid]
            log.info(
                "speed median %.3f m/s, 95th percentile %.3f m/s",
                np.median(speed),
                np.percentile(speed, 95),
            )
    problems = len(obs.problems) + len(state_problems(nav))
    log.log(
        logging.INFO if valid.all() else logging.WARNING,
        "%d of %d epochs valid (the others: too few satellites or failing the residual test); "
        "wrote %s and %s%s",
        int(valid.sum()),
        valid.size,
        args.output,
        figure,
        f"; {problems} input problems (warned above)" if problems else "",
    )
    if not valid.any():
        raise VoDopplerError("no epoch could be solved (too few satellites with ephemerides)")
    return 0
