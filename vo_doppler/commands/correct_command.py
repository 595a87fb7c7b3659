"""``vo-doppler correct TRAJ --heading heading.csv``: VO heading correction ([TK18] sec. 3.6)."""

from __future__ import annotations

import argparse
import dataclasses
import logging
from enum import StrEnum
from pathlib import Path

import numpy as np

from vo_doppler.choices import values
from vo_doppler.commands.arg_types import finite_float, positive_float
from vo_doppler.commands.correction_options import add_correction_options, correction_config
from vo_doppler.commands.output_paths import check_output_files
from vo_doppler.errors import InputError, VoDopplerError
from vo_doppler.fusion.correction import (
    HeadingSource,
    absolute_heading,
    correct,
    usable_tight_heading,
)
from vo_doppler.fusion.placement import initial_yaw_offset, turned_about_start
from vo_doppler.geo import wrap_angle
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.output_folder import write_files
from vo_doppler.io.trajectory import (
    AUTO_FORMAT_RULE,
    TrajectoryFormat,
    read_trajectory,
    trajectory_format,
    write_kitti,
    write_tum,
)
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report.json_text import json_text
from vo_doppler.time_hints import FRAME_NUMBER_FIX, time_base_check
from vo_doppler.vo.frames import (
    MAX_ROAD_CLIMB,
    WRONG_WORLD_FRACTION,
    World,
    camera_trajectory,
    steep_path_fraction,
    vehicle_trajectory,
)

log = logging.getLogger(__name__)


class Body(StrEnum):
    """The poses ``--body`` writes: the vehicle's, or the camera's through the extrinsic."""

    VEHICLE = "vehicle"
    CAMERA = "camera"


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "correct",
        help=summary,
        description="Correct the heading of a VO trajectory (TUM or KITTI, any VO system) with "
        "absolute headings: by the window method (shift to the window's absolute heading and "
        "rotate the positions about the window's oldest position, [TK18] Eq. 11-13) or by "
        "the Kalman blend (a filter and smoother on the VO heading offset whose noise is fitted "
        "to the drive). The trajectory is first turned to the absolute headings of its first "
        "seconds, as `run` starts every trajectory. Output: vehicle (or camera) poses in an "
        "ENU-aligned frame with its origin at the first position.",
    )
    parser.add_argument("trajectory", help="VO trajectory, TUM or KITTI (camera poses)")
    parser.add_argument(
        "--heading",
        required=True,
        help="heading.csv from `vo-doppler heading`, or your own absolute heading as a minimal "
        "CSV: gps_time_s, heading_deg or course_deg, sigma_deg[, valid] (docs/formats.md; read "
        "as the conventional heading)",
    )
    parser.add_argument("--calib", help="camera calibration (YAML with T_vehicle_camera)")
    parser.add_argument(
        "--format",
        choices=values(TrajectoryFormat),
        default=TrajectoryFormat.AUTO.value,
        help=f"trajectory file format (auto: {AUTO_FORMAT_RULE}; the extension is not used)",
    )
    parser.add_argument(
        "--times",
        help="timestamps file for a KITTI trajectory (one per line; without it the poses' times "
        "are frame numbers 0, 1, 2, ..., refused unless the heading epochs cover them)",
    )
    parser.add_argument(
        "--time-offset",
        type=finite_float,
        default=0.0,
        help="seconds added to trajectory times -> GPS",
    )
    add_correction_options(parser, window_s=True)
    parser.add_argument(
        "--source",
        choices=values(HeadingSource),
        default=HeadingSource.TC_CONV.value,
        help="absolute headings used: tightly coupled (usable: reliable and sigma < 2 deg), "
        "conventional, or the former where usable else the latter",
    )
    parser.add_argument(
        "--world",
        choices=values(World),
        default=World.FIRST_CAMERA.value,
        help="the input's world: the first camera's frame (what VO systems write) or already "
        "level, z up",
    )
    parser.add_argument(
        "--body",
        choices=values(Body),
        default=Body.VEHICLE.value,
        help="write vehicle or camera poses",
    )
    parser.add_argument(
        "--max-gap-s",
        type=positive_float,
        default=1.5,
        help="longest gap (s) across which absolute headings are interpolated",
    )
    parser.add_argument("-o", "--output", required=True, help="corrected trajectory (.tum/.kitti)")
    parser.add_check(times_of_a_tum_trajectory)
    parser.set_defaults(func=run)


def times_of_a_tum_trajectory(args: argparse.Namespace) -> str | None:
    """The problem of ``--times`` given with a TUM trajectory, which carries its own times and
    keeps them. A trajectory that cannot be read is left to :func:`run` to report."""
    if args.times is None:
        return None
    try:
        fmt = trajectory_format(args.trajectory, args.format)
    except VoDopplerError:
        return None
    if fmt is not TrajectoryFormat.TUM:
        return None
    given = "--format tum" if args.format == TrajectoryFormat.TUM else f"{args.trajectory} is TUM"
    return (
        f"--times applies to a KITTI trajectory only, but {given}: a TUM trajectory carries "
        "its own times (drop --times)"
    )


def _times(path: str | None) -> np.ndarray | None:
    if path is None:
        return None
    try:
        return np.loadtxt(path, dtype=float, ndmin=1)
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read times: {exc}", path) from exc


def _frame_number_fix(args: argparse.Namespace) -> str:
    """What gives a trajectory whose times are frame numbers its times, by where they came
    from: a KITTI file read without ``--times``, a ``--times`` file, or a TUM file's column."""
    if args.times is not None:
        return f"{args.times} holds frame numbers, not the images' times: give the times file"
    if trajectory_format(args.trajectory, args.format) is TrajectoryFormat.KITTI:
        return FRAME_NUMBER_FIX
    return (
        "a TUM trajectory keeps its own times: write the images' times in its first column "
        "(or give the poses as KITTI with --times)"
    )


OTHER_WORLD = {
    World.FIRST_CAMERA: "already level, z up (e.g. ENU, as run's trajectory_*.tum): give "
    "--world level",
    World.LEVEL: "camera poses in the first camera's frame (what VO systems write): give "
    "--world first_camera",
}


def world_warnings(vehicle: Trajectory, world: str) -> list[str]:
    """A warning when the vehicle poses in ``--world`` climb or fall steeper than any road
    along much of the path (:func:`vo_doppler.vo.frames.steep_path_fraction`): the correction
    only turns the heading, so in a wrong world its result is wrong."""
    fraction = steep_path_fraction(vehicle)
    if fraction <= WRONG_WORLD_FRACTION:
        return []
    return [
        f"with --world {world} the vehicle climbs or falls more steeply than "
        f"{np.degrees(MAX_ROAD_CLIMB):.0f} deg along {fraction:.0%} of its path, which no road "
        f"does: the trajectory's world is probably {OTHER_WORLD[world]}"
    ]


def run(args: argparse.Namespace) -> int:
    check_output_files(
        {"output": args.output}, [args.trajectory, args.heading, args.calib, args.times]
    )
    trajectory = read_trajectory(args.trajectory, args.format, _times(args.times))
    trajectory = dataclasses.replace(trajectory, t=trajectory.t + args.time_offset)
    table = read_heading_csv(args.heading)
    extrinsic = (
        read_camera(args.calib).T_vehicle_camera if args.calib else CAMERA_TO_VEHICLE_FORWARD
    )
    time_base = time_base_check(
        trajectory.t,
        table.t,
        "trajectory",
        "heading epochs",
        "--time-offset",
        _frame_number_fix(args),
    )
    if time_base.error:
        raise InputError(time_base.error, args.trajectory)
    config = correction_config(args, max_gap_s=args.max_gap_s)
    vehicle = vehicle_trajectory(trajectory, extrinsic, args.world)
    warnings = ([time_base.warning] if time_base.warning else []) + world_warnings(
        vehicle, args.world
    )
    for text in warnings:
        log.warning("%s", text)
    # The starting heading as `run` sets it: before its first absolute heading (and through
    # the window method's first window) the trajectory would stay in the VO's own frame.
    usable = usable_tight_heading(table, config.tc_max_sigma_rad)
    start_turn = initial_yaw_offset(
        table, usable, vehicle, source=args.source, reference=config.reference
    )
    vehicle = turned_about_start(vehicle, start_turn)
    result = correct(vehicle, absolute_heading(table, args.source, config), config)
    if not result.has_absolute.any():
        raise InputError(
            f"no usable {args.source} heading within the trajectory's times: nothing to correct "
            "it with (heading.csv's usable epochs, --source, --max-gap-s"
            + (
                "; a minimal heading CSV is read as the conventional heading: give --source "
                "conv or tc+conv)"
                if args.source == "tc" and not table.tc_available.any()
                else ")"
            ),
            args.heading,
        )
    out = (
        result.vehicle
        if args.body == Body.VEHICLE
        else camera_trajectory(result.vehicle, extrinsic)
    )
    output = Path(args.output)
    writer = write_kitti if output.suffix.lower() in (".kitti", ".txt") else write_tum
    write_files([(output, lambda path: writer(path, out))])
    summary = {
        "poses": len(out),
        "poses_with_absolute_heading": int(result.has_absolute.sum()),
        "initial_turn_deg": float(np.degrees(start_turn)),
        "final_correction_deg": float(np.degrees(wrap_angle(start_turn + result.correction[-1]))),
        "correction": args.correction,
        "output": str(output),
        "warnings": warnings,
    }
    if args.correction == "kalman":
        summary["fitted_noise"] = result.noise.fitted
        summary["sigma_distance_deg_per_sqrt_100m"] = float(
            np.degrees(result.noise.sigma_distance) * 10.0
        )
        summary["sigma_turn"] = result.noise.sigma_turn
        summary["heading_sigma_scale"] = result.noise.scale
        summary["outlier_fraction"] = result.noise.outlier_fraction
        summary["correlation_floor_s"] = result.noise.correlation_floor_s
    print(json_text(summary))  # once, on stdout (the warnings in it were logged above)
    return 0
