"""``vo-doppler eval EST GT``: KITTI-style segment errors, drift, end yaw error and ATE."""

from __future__ import annotations

import argparse
import logging
import sys

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from vo_doppler.errors import InputError
from vo_doppler.eval.alignment import ALIGNMENTS
from vo_doppler.eval.metrics import (
    NO_MATCH,
    TrajectoryErrors,
    evaluate,
    evaluate_by_time,
    segment_lengths_note,
)
from vo_doppler.io.trajectory import AUTO_FORMAT_RULE, TRAJECTORY_FORMATS, read_trajectory
from vo_doppler.report.json_text import json_text
from vo_doppler.report.run_report import number_or_dash

log = logging.getLogger(__name__)

UP_AXES = {"z": (0.0, 0.0, 1.0), "-y": (0.0, -1.0, 0.0), "y": (0.0, 1.0, 0.0)}


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "eval",
        help=summary,
        description="KITTI-devkit segment errors (translation in %, rotation in deg per 100 m) "
        "over KITTI's 100-800 m segments (those shorter than the path; on a path shorter than "
        "100 m, 10-80 m segments, said so in the output), final drift in % of path length, yaw "
        "error at the end and ATE RMSE.",
    )
    parser.add_argument("estimate", help="estimated trajectory (TUM or KITTI)")
    parser.add_argument("ground_truth", help="ground-truth trajectory (TUM or KITTI)")
    parser.add_argument(
        "--format",
        choices=TRAJECTORY_FORMATS,
        default="auto",
        help=f"trajectory file format (auto: {AUTO_FORMAT_RULE}; the extension is not used)",
    )
    parser.add_argument(
        "--align",
        choices=ALIGNMENTS,
        default="start",
        help="how the estimate is aligned to the ground truth before the final error, end yaw "
        "error and ATE (segment errors are relative and do not depend on it)",
    )
    parser.add_argument(
        "--up",
        choices=("auto", *UP_AXES),
        default="auto",
        help="world up axis for yaw and SE(2) alignment (auto: -y for KITTI camera poses, else z)",
    )
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    estimate = read_trajectory(args.estimate, args.format)
    truth = read_trajectory(args.ground_truth, args.format)
    kitti_rows = args.format == "kitti" or (
        np.array_equal(estimate.t, np.arange(len(estimate)))
        and np.array_equal(truth.t, np.arange(len(truth)))
    )
    if kitti_rows:
        if len(estimate) != len(truth):
            raise InputError(
                f"{len(estimate)} estimated poses but {len(truth)} ground-truth poses "
                "(KITTI rows are matched one to one)",
                args.estimate,
            )
        errors = evaluate(estimate, truth, args.align, up(args.up, kitti_rows))
    else:
        errors = evaluate_by_time(estimate, truth, args.align, up(args.up, kitti_rows))
        if errors is None:
            raise InputError(NO_MATCH, args.estimate)
    for text in errors.notes:
        log.warning("%s", text)
    if args.json:
        print(json_text(errors.to_dict(), indent=2))
    else:
        print_errors(errors)
    return 0


def up(name: str, kitti_rows: bool) -> np.ndarray:
    """The world up axis of ``--up`` (auto: -y for KITTI camera poses, else z)."""
    return np.array(UP_AXES[name if name != "auto" else ("-y" if kitti_rows else "z")])


def print_errors(errors: TrajectoryErrors) -> None:
    console = Console(width=None if sys.stdout.isatty() else 120)
    lengths = tuple(s.length_m for s in errors.segments)
    if not lengths:
        console.print(
            f"Segment errors: none, {segment_lengths_note(lengths, errors.path_length_m)}"
        )
    table = Table(
        title="Segment errors (KITTI devkit: relative poses, independent of the alignment)",
        caption=segment_lengths_note(lengths, errors.path_length_m),
    )
    for column in ("length [m]", "translation [%]", "rotation [deg/100 m]"):
        table.add_column(escape(column), justify="right")
    table.add_column("segments", justify="right")
    for s in errors.segments:
        table.add_row(
            f"{s.length_m:.0f}",
            f"{s.translation_pct:.3f}",
            f"{s.rotation_deg_per_100m:.4f}",
            str(s.count),
        )
    if lengths:
        console.print(table)
    evaluated = ""
    if errors.coverage is not None:
        evaluated = (
            f" | evaluated {errors.coverage.evaluated_s:.1f} s of the estimate's "
            f"{errors.coverage.estimate_s:.1f} s ({errors.coverage.fraction:.0%})"
        )
    console.print(
        f"{errors.alignment} alignment: path {errors.path_length_m:.1f} m | final error "
        f"{number_or_dash(errors.final_position_error_m, '{:.3f}')} m "
        f"({number_or_dash(errors.final_drift_pct, '{:.3f}')} % of path) | end yaw error "
        f"{number_or_dash(errors.end_yaw_error_deg, '{:.3f}')} deg | ATE RMSE "
        f"{number_or_dash(errors.ate_rmse_m, '{:.3f}')} m{evaluated}"
    )
