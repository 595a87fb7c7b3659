"""``vo-doppler gnss``: Doppler velocity and single-point positions from RINEX files, u-blox UBX
or Android logs (``vo_doppler.io.receiver_file``), with broadcast (``--nav``, or the UBX log's own
subframes) or precise (``--orbits``) satellite states.

Before any solution the satellite states are checked against the observations' epochs: no
ephemeris valid at any epoch, precise orbits or clocks that cover none of them are an error
naming both spans and the files (a file of another day); a partial cover is a warning. The CSV
and the figure are written only when the command succeeds (a failed run leaves none, and an
earlier run's files as they were)."""

from __future__ import annotations

import argparse
import datetime as dt
import logging
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from vo_doppler.choices import values
from vo_doppler.commands.arg_types import band_digits
from vo_doppler.commands.output_paths import check_output_files
from vo_doppler.commands.satellite_options import (
    add_satellite_options,
    add_selection_options,
    satellite_inputs,
    satellite_states,
)
from vo_doppler.commands.span_options import add_span_options, time_span
from vo_doppler.errors import InputError, VoDopplerError, shown
from vo_doppler.gnss.doppler_velocity import doppler_codes
from vo_doppler.gnss.ephemeris import GLONASS_MAX_AGE_S, KEPLER_MAX_AGE_S
from vo_doppler.gnss.pipeline import RangeRateSource, gnss_position, gnss_velocity
from vo_doppler.gnss.satellite_source import satellite_source
from vo_doppler.gnss.signals import carrier_frequency
from vo_doppler.io.gnss_csv import write_spp_csv, write_velocity_csv
from vo_doppler.io.output_folder import write_files
from vo_doppler.io.receiver_file import read_observation_file
from vo_doppler.io.satellite_states import state_problems
from vo_doppler.model.gnss_solutions import SppSolution
from vo_doppler.model.navigation import Navigation
from vo_doppler.model.observations import Observations
from vo_doppler.model.precise_orbits import PreciseOrbits
from vo_doppler.model.time_span import trim
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
    add_span_options(parser, "first observation epoch")


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
        choices=values(RangeRateSource),
        default=RangeRateSource.DOPPLER.value,
        help="'phase': carrier-phase rate instead of the logged Doppler",
    )
    velocity.set_defaults(func=run)
    spp = actions.add_parser("spp", help="per-epoch pseudorange single-point positions")
    _common(spp)
    spp.set_defaults(func=run)


def _check_range_rates(obs: Observations, systems: str, bands: str | None, source: str) -> None:
    """Raise when the file has none of the observables ``--range-rate`` needs for the chosen
    systems and bands (Doppler; carrier phase for 'phase'), naming those it has and, for a
    file without Doppler but with carrier phase, ``--range-rate phase`` (instead of failing
    later at every epoch for want of satellites)."""
    letter, what = ("L", "carrier phase") if source == RangeRateSource.PHASE else ("D", "Doppler")
    if _codes(obs, systems, bands, letter):
        return
    available = [
        f"{system} {' '.join(codes)}"
        for system in sorted(set(obs.system.tolist()))
        if (codes := _codes(obs, system, None, letter))
    ]
    chosen = f"systems {systems!r}" + (f", bands {bands!r}" if bands else "")
    hint = ""
    if source != RangeRateSource.PHASE and _codes(obs, systems, bands, "L"):
        hint = (
            "; it has carrier phase ("
            + " ".join(_codes(obs, systems, bands, "L"))
            + "): --range-rate phase takes the range rate from its rate instead"
        )
    raise InputError(
        f"the file has no {what} of the {chosen}; its {what} observables: "
        + ("; ".join(available) or "none")
        + hint,
        obs.header.path,
    )


def _codes(obs: Observations, systems: str, bands: str | None, letter: str) -> list[str]:
    """The observables of one kind ('D' Doppler, 'L' carrier phase) of the systems and bands."""
    if letter == "D":
        return doppler_codes(obs, systems, bands)
    codes = {c for system in systems for c in obs.codes_of(system) if c.startswith(letter)}
    return sorted(c for c in codes if bands is None or c[1:2] in bands)


def with_phase_doppler_codes(obs: Observations) -> Observations:
    """``obs`` with a Doppler code beside every carrier-phase code that has none ('L1' → 'D1'),
    so that ``--range-rate phase`` works on a file that logged no Doppler (a RINEX 2 with
    C1 L1 S1): ``carrier_phase_doppler`` makes phase-rate rows only for the Doppler codes a
    file has."""
    missing = [f"D{c[1:]}" for c in obs.codes if c.startswith("L") and f"D{c[1:]}" not in obs.codes]
    return replace(obs, codes=obs.codes + tuple(dict.fromkeys(missing))) if missing else obs


def gps_date(t: float) -> str:
    """'2019-04-28 04:44:09' of a GPS time (s since 1980-01-06, GPS time scale)."""
    when = dt.datetime(1980, 1, 6) + dt.timedelta(seconds=round(float(t)))
    return when.strftime("%Y-%m-%d %H:%M:%S")


def _dates(start: float, end: float) -> str:
    return f"{gps_date(start)} to {gps_date(end)} GPS time"


def _covered(epochs: np.ndarray, start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """Per epoch, whether it lies in one of the intervals [start, end]."""
    if start.size == 0:
        return np.zeros(epochs.size, dtype=bool)
    order = np.argsort(start)
    reach = np.maximum.accumulate(end[order])
    index = np.searchsorted(start[order], epochs, side="right") - 1
    return (index >= 0) & (reach[np.maximum(index, 0)] >= epochs)


def _names(paths: Sequence[Path | None]) -> str:
    return ", ".join(str(p) for p in paths if p is not None) or "the observation file"


def check_coverage(
    obs: Observations, source, systems: str, files: Sequence[Path | None] = ()
) -> None:
    """Raise an :class:`InputError` naming both spans and the files when the satellite states
    ``source`` hold nothing at any of the observations' epochs (broadcast: no ephemeris of
    ``systems`` within its validity, 4 h Keplerian, 30 min GLONASS; precise: orbit or clock
    epochs that do not reach the observations); warn with the count when they cover only part
    of the epochs. ``files`` are the navigation files (``source.path`` names precise ones)."""
    epochs = obs.epoch_time
    if epochs.size == 0:
        return
    spans: list[tuple[str, Sequence[Path | None], np.ndarray, np.ndarray, str, str]] = []
    if isinstance(source, PreciseOrbits):
        spans.append(
            ("precise orbits", [source.path], source.t[:1], source.t[-1:], "epochs", "orbit")
        )
        if source.clocks is not None and source.clocks.t.size:
            clocks = source.clocks
            spans.append(
                ("clock file", [clocks.path], clocks.t[:1], clocks.t[-1:], "epochs", "clock")
            )
    elif isinstance(source, Navigation):
        start, end = [], []
        for records, age in (
            (source.kepler, KEPLER_MAX_AGE_S),
            (source.glonass, GLONASS_MAX_AGE_S),
        ):
            ref = records["toe"] if records is source.kepler and len(records) else records.toc
            chosen = np.isin(records.system, list(systems))
            start.append(ref[chosen] - age)
            end.append(ref[chosen] + age)
        what = "navigation file" + ("s" if len(files) > 1 else "")
        spans.append(
            (
                what,
                files,
                np.concatenate(start),
                np.concatenate(end),
                "ephemerides valid",
                "ephemeris",
            )
        )
    for what, paths, start, end, held, item in spans:
        subject = f"the {what} {_names(paths)}"
        observed = f"the observations {obs.header.path} run {_dates(epochs[0], epochs[-1])}"
        if not start.size:
            raise InputError(f"{subject}: no ephemeris of the systems {systems!r}; {observed}")
        covered = _covered(epochs, start, end)
        holds = f"{subject}: {held} {_dates(start.min(), end.max())}; {observed}"
        if not covered.any():
            raise InputError(
                f"{holds}: no {item} at any observation epoch (a {what.rstrip('s')} of another "
                "day or hour?)"
            )
        if not covered.all():
            outside = np.flatnonzero(~covered)
            log.warning(
                "%s: %d of the %d observation epochs (the first at %s) have no %s: they get no "
                "satellite state",
                holds,
                outside.size,
                epochs.size,
                gps_date(epochs[outside[0]]),
                item,
            )


def _glonass_dropped(obs: Observations, source, systems: str, bands: str | None) -> str:
    """Warn once when GLONASS Doppler rows are dropped for want of a frequency channel (neither
    the observation file's GLONASS SLOT / FRQ # nor a navigation record gives it), with the
    count and the satellites. Returns the chosen systems the file has, less GLONASS when all of
    its rows are dropped (the figure's title)."""
    present = "".join(s for s in systems if s in set(obs.system.tolist()))
    if "R" not in present:
        return present
    channels = {**satellite_source(source).glonass_channels(), **obs.header.glonass_channels}
    fdma = [
        obs.codes.index(code)
        for code in doppler_codes(obs, "R", bands)
        if carrier_frequency("R", code, None, obs.header.version) is None
    ]
    rows = (
        (obs.system == "R")
        & np.isin(obs.code, fdma)
        & np.isfinite(obs.value)
        & ~np.isin(obs.prn, list(channels))
    )
    if not rows.any():
        return present
    slots = np.unique(obs.prn[rows])
    all_glonass = not ((obs.system == "R") & np.isin(obs.code, fdma) & ~rows).any()
    log.warning(
        "GLONASS: %d Doppler rows of %s dropped: their frequency channel is unknown (not in "
        "the observation file's GLONASS SLOT / FRQ # record nor in a GLONASS navigation "
        "record); give a navigation file with GLONASS records",
        int(rows.sum()),
        ", ".join(f"R{int(p):02d}" for p in slots),
    )
    return present.replace("R", "") if all_glonass else present


def _systems_solved(solution: SppSolution, systems: str) -> str:
    """The systems of ``systems`` whose receiver clock the SPP estimated at some epoch, for the
    figure's title. Pseudoranges need no GLONASS frequency channel, so ``spp`` keeps GLONASS
    satellites whose Doppler rows ``velocity`` drops (:func:`_glonass_dropped`)."""
    clocks = solution.clock_bias_m
    solved = "".join(s for s in systems if s in clocks and np.isfinite(clocks[s]).any())
    return solved or "no system solved"


def run(args: argparse.Namespace) -> int:
    figure = args.figure or args.output.with_suffix(".png")
    check_output_files(
        {"output": args.output, "figure": figure}, [args.obs, *satellite_inputs(args)]
    )
    obs, embedded = read_observation_file(args.obs)
    part = time_span(args)
    if not part.whole:
        obs = trim(obs, part.resolve(obs.epoch_time, "observation epochs"))
    range_rate = getattr(args, "range_rate", RangeRateSource.DOPPLER)
    if args.gnss_command == "velocity":
        _check_range_rates(obs, args.systems, args.bands, range_rate)
        if range_rate == RangeRateSource.PHASE:
            obs = with_phase_doppler_codes(obs)
    nav = satellite_states(args) if args.nav or args.orbits else embedded
    if nav is None:
        raise InputError(
            "no satellite states: give --nav or --orbits (of the files this command reads, only "
            "a UBX log with GPS subframes carries its own; a GSDC file's satellite states are "
            "for the library only, docs/formats.md)",
            args.obs,
        )
    check_coverage(obs, nav, args.systems, args.nav or [args.obs])
    mask = np.deg2rad(args.elev_mask)
    bands = getattr(args, "bands", None)
    if args.gnss_command == "spp":
        solution = gnss_position(obs, nav, args.systems, mask)
        valid = solution.valid
        title = f"{shown(args.obs.name)} ({_systems_solved(solution, args.systems)})"
        outputs = [
            (args.output, lambda path: write_spp_csv(path, solution)),
            (figure, lambda path: spp_figure(path, solution, title)),
        ]
    else:
        title = f"{shown(args.obs.name)} ({_glonass_dropped(obs, nav, args.systems, bands)})"
        result = gnss_velocity(obs, nav, args.systems, mask, args.bands, range_rate)
        velocity = result.velocity
        valid = velocity.valid
        rows = result.rows
        if rows.n_no_ephemeris:
            log.warning(
                "%d Doppler rows skipped without ephemeris (the satellites above)",
                rows.n_no_ephemeris,
            )
        if valid.any():
            speed = velocity.speed_mps[valid]
            log.info(
                "speed median %.3f m/s, 95th percentile %.3f m/s",
                np.median(speed),
                np.percentile(speed, 95),
            )
        outputs = [
            (args.output, lambda path: write_velocity_csv(path, velocity)),
            (figure, lambda path: velocity_figure(path, velocity, title)),
        ]
    problems = len(obs.problems) + len(state_problems(nav))
    summary = (
        f"{int(valid.sum())} of {valid.size} epochs valid (the others: too few satellites, "
        "failing the residual test"
        + (
            " or inconsistent with their neighbours carried along the Doppler velocities)"
            if args.gnss_command == "spp"
            else ")"
        )
        + (f"; {problems} input problems (warned above)" if problems else "")
    )
    if not valid.any():
        raise VoDopplerError(
            f"no epoch could be solved (too few satellites with ephemerides): {summary}; "
            f"nothing written ({args.output} and {figure} left as they were)"
        )
    write_files(outputs)
    log.log(
        logging.INFO if valid.all() else logging.WARNING,
        "%s; wrote %s and %s",
        summary,
        args.output,
        figure,
    )
    return 0
