"""``vo-doppler kitti-speed POSES --times TIMES -o speed.csv``: the ``t,speed_mps`` CSV that
gives ``vo-doppler vo --speed`` its metric scale on a KITTI sequence (which has no wheel speed),
from the ground-truth poses."""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

from vo_doppler.commands.output_paths import check_output_files
from vo_doppler.errors import InputError, shown
from vo_doppler.eval.reference_speed import speed_from_poses
from vo_doppler.io.images import read_times
from vo_doppler.io.output_folder import write_files
from vo_doppler.io.sensor_csv import SPEED_COLUMN, write_sensor_csv
from vo_doppler.io.trajectory import read_trajectory


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "kitti-speed",
        help=summary,
        description="Write the speed along a ground-truth trajectory (KITTI poses file with its "
        "times.txt, or TUM) as a t,speed_mps CSV whose integral between poses is the true step "
        "length: the stand-in for wheel speed that scales `vo-doppler vo --speed` on KITTI.",
    )
    parser.add_argument("poses", type=Path, help="ground-truth poses (KITTI, e.g. poses/06.txt)")
    parser.add_argument(
        "--times",
        type=Path,
        help="the sequence's times.txt (one time per pose; required for a KITTI poses file)",
    )
    parser.add_argument("-o", "--output", type=Path, required=True, help="CSV to write")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    check_output_files({"output": args.output}, [args.poses, args.times])
    truth = read_trajectory(args.poses)
    if args.times is not None:
        truth = dataclasses.replace(truth, t=read_times(args.times, len(truth)))
    elif len(truth) > 1 and np.array_equal(truth.t, np.arange(len(truth))):
        raise InputError(
            "a KITTI poses file has no times: pass --times with the sequence's times.txt",
            args.poses,
        )
    speed = speed_from_poses(truth, args.poses)
    write_files([(args.output, lambda path: write_sensor_csv(path, speed, SPEED_COLUMN))])
    print(
        f"wrote {shown(args.output)}: {len(speed)} samples, {truth.path_length:.1f} m over "
        f"{float(truth.t[-1] - truth.t[0]):.1f} s"
    )
    return 0
