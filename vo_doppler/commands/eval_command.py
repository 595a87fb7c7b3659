"""``vo-doppler eval EST GT``: KITTI-style segment errors, drift, end yaw error and ATE;
``vo-doppler eval gnss --truth TRUTH [--vel F] [--heading F] [--pos F]``: GNSS outputs scored
against ground truth (:mod:`vo_doppler.eval.gnss_scores`)."""

from __future__ import annotations

import argparse
import logging
import math
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.table import Table

from vo_doppler.choices import values
from vo_doppler.commands.arg_types import positive_float
from vo_doppler.commands.help_format import OptionsParser
from vo_doppler.commands.output_paths import check_output_files
from vo_doppler.errors import InputError
from vo_doppler.eval.alignment import Alignment
from vo_doppler.eval.gnss_scores import (
    HOLD_BELOW_MPS,
    MOVING_MPS,
    STANDSTILL_MPS,
    ErrorStats,
    GnssScores,
    Thresholds,
    score_gnss,
)
from vo_doppler.eval.metrics import (
    NO_MATCH,
    TrajectoryErrors,
    evaluate,
    evaluate_by_time,
    segment_lengths_note,
)
from vo_doppler.geo import EnuFrame
from vo_doppler.io.gnss_results_csv import read_position_csv, read_velocity_csv
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.trajectory import AUTO_FORMAT_RULE, TrajectoryFormat, read_trajectory
from vo_doppler.io.truth_csv import (
    AUTO_TRUTH_RULE,
    TruthFormat,
    read_ground_truth,
    sequence_origin,
)
from vo_doppler.model.gpstime import time_of_week
from vo_doppler.report.json_text import json_text
from vo_doppler.report.run_report import number_or_dash

log = logging.getLogger(__name__)

UP_AXES = {"z": (0.0, 0.0, 1.0), "-y": (0.0, -1.0, 0.0), "y": (0.0, 1.0, 0.0)}
GNSS_MODE = "gnss"
"""The first word after ``eval`` that selects the GNSS scoring (a trajectory file named so is
given as ``./gnss``)."""


class EvalParser(OptionsParser):
    """``eval``'s parser: ``eval gnss ...`` goes to :attr:`gnss_parser`, anything else is the
    trajectory evaluation ``eval EST GT``."""

    gnss_parser: argparse.ArgumentParser

    def parse_known_args(self, args: Sequence[str] | None = None, namespace=None):
        words = sys.argv[1:] if args is None else list(args)
        if words and words[0] == GNSS_MODE:
            return self.gnss_parser.parse_args(words[1:], namespace), []  # its own usage
        return super().parse_known_args(words, namespace)


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "eval",
        help=summary,
        description="KITTI-devkit segment errors (translation in %, rotation in deg per 100 m) "
        "over KITTI's 100-800 m segments (those shorter than the path; on a path shorter than "
        "100 m, 10-80 m segments, said so in the output), final drift in % of path length, yaw "
        "error at the end and ATE RMSE.",
        epilog="vo-doppler eval gnss --truth TRUTH [--vel vel.csv] [--heading heading.csv] "
        "[--pos pos.csv] scores GNSS outputs against ground truth instead (vo-doppler eval gnss "
        "--help).",
    )
    parser.__class__ = EvalParser  # the sub-parsers action made it; only parsing changes
    parser.gnss_parser = gnss_parser(f"{parser.prog} {GNSS_MODE}")
    parser.add_argument("estimate", help="estimated trajectory (TUM or KITTI)")
    parser.add_argument("ground_truth", help="ground-truth trajectory (TUM or KITTI)")
    parser.add_argument(
        "--format",
        choices=values(TrajectoryFormat),
        default=TrajectoryFormat.AUTO.value,
        help=f"trajectory file format (auto: {AUTO_FORMAT_RULE}; the extension is not used)",
    )
    parser.add_argument(
        "--align",
        choices=values(Alignment),
        default=Alignment.START.value,
        help="how the estimate is aligned to the ground truth before the final error, end yaw "
        "error and ATE (segment errors are relative: a rigid alignment leaves them as they are, "
        "sim3 scales the estimate and so changes the translation errors)",
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
    kitti_rows = args.format == TrajectoryFormat.KITTI or (
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
        title=f"Segment errors (KITTI devkit: relative poses; {segment_alignment_note(errors)})",
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
            end_section=s is errors.segments[-1],
        )
    table.add_row(
        "mean of all",
        number_or_dash(errors.mean_translation_pct, "{:.3f}"),
        number_or_dash(errors.mean_rotation_deg_per_100m, "{:.4f}"),
        str(sum(s.count for s in errors.segments)),
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


def segment_alignment_note(errors: TrajectoryErrors) -> str:
    """How the alignment bears on the segment errors: a rigid one (``none``, ``start``,
    ``se2``) leaves relative poses as they are; ``sim3`` scales the estimate first, which
    changes the translation errors (not the rotation errors)."""
    if errors.alignment == "sim3":
        return (
            "the estimate scaled by the sim3 alignment first, which changes the translation "
            "errors, not the rotation errors"
        )
    return f"unchanged by the rigid {errors.alignment} alignment"


def origin_value(text: str) -> tuple[float, float, float]:
    """argparse type: ``LAT,LON,H`` (degrees, degrees, metres)."""
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if (
        len(values) != 3
        or not all(math.isfinite(v) for v in values)
        or abs(values[0]) > 90.0
        or abs(values[1]) > 180.0
    ):
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected LAT,LON,H (degrees in [-90, 90] and [-180, 180], metres)"
        )
    return values[0], values[1], values[2]


def gnss_parser(prog: str) -> OptionsParser:
    """The parser of ``vo-doppler eval gnss``."""
    parser = OptionsParser(
        prog=prog,
        description="Score GNSS outputs against ground truth over the time the truth covers "
        "(epochs outside its span or in a gap of it are left out and counted): vel.csv's "
        "availability over the moving epochs, horizontal speed and course errors of its valid "
        "epochs (median, p95, max, counts beyond 5 and 15 deg) and its valid speeds at "
        "standstill; heading.csv's tight heading (available and reliable) and conventional "
        "heading (conv_valid), the same figures; pos.csv's horizontal and vertical errors. "
        "Truth velocity: central differences of its positions in local ENU; truth course: the "
        "file's own heading where it has one, else the velocity's, held through stops below "
        f"{HOLD_BELOW_MPS:g} m/s.",
    )
    parser.add_argument(
        "--truth",
        help="ground truth: TUM (ENU of --origin or --sequence's origin), a lat/lon CSV or a "
        "GSDC ground_truth.csv (--truth-format; default: the --sequence's ground_truth)",
    )
    parser.add_argument(
        "--truth-format",
        choices=values(TruthFormat),
        default=TruthFormat.AUTO.value,
        help=f"format of --truth (auto: {AUTO_TRUTH_RULE})",
    )
    where = parser.add_mutually_exclusive_group()
    where.add_argument(
        "--origin",
        type=origin_value,
        metavar="LAT,LON,H",
        help="geodetic origin of a TUM truth's ENU frame (needed to score --pos)",
    )
    where.add_argument(
        "--sequence",
        metavar="DIR",
        help="a sequence folder: the origin of its sequence.yaml (and its ground truth when "
        "--truth is not given)",
    )
    parser.add_argument("--vel", help="vel.csv of vo-doppler gnss velocity")
    parser.add_argument("--heading", help="heading.csv of vo-doppler heading or run")
    parser.add_argument("--pos", help="pos.csv of vo-doppler gnss spp")
    parser.add_argument(
        "--moving-mps",
        type=positive_float,
        default=MOVING_MPS,
        help="moving: truth horizontal speed above this (m/s)",
    )
    parser.add_argument(
        "--standstill-mps",
        type=positive_float,
        default=STANDSTILL_MPS,
        help="standstill: truth horizontal speed below this (m/s); valid speeds above it are "
        "counted",
    )
    parser.add_argument("--json", metavar="OUT", help="also write the figures as JSON to OUT")
    parser.add_check(
        lambda a: (
            None
            if any((a.vel, a.heading, a.pos))
            else "give at least one of --vel, --heading, --pos"
        )
    )
    parser.add_check(
        lambda a: None if a.truth or a.sequence else "give --truth (or --sequence DIR)"
    )
    parser.add_check(
        lambda a: (
            None
            if a.standstill_mps <= a.moving_mps
            else f"--standstill-mps {a.standstill_mps:g} is above --moving-mps {a.moving_mps:g}"
        )
    )
    parser.set_defaults(func=run_gnss)
    return parser


def run_gnss(args: argparse.Namespace) -> int:
    """``vo-doppler eval gnss``: read the truth and the outputs, score, print, write JSON."""
    origin, truth_path = None, args.truth
    if args.sequence:
        origin, manifest_truth = sequence_origin(args.sequence)
        if truth_path is None and manifest_truth is None:
            raise InputError(
                "the manifest names no ground_truth.trajectory: give --truth", args.sequence
            )
        truth_path = truth_path or manifest_truth
    elif args.origin:
        lat, lon, height = args.origin
        origin = EnuFrame(math.radians(lat), math.radians(lon), height)
    inputs = {"velocity": args.vel, "heading": args.heading, "positions": args.pos}
    check_output_files({"JSON": args.json}, [truth_path, *inputs.values()])
    truth = read_ground_truth(truth_path, args.truth_format, origin)
    if args.pos and truth.frame is None:
        raise InputError(
            "a TUM ground truth is in the ENU frame of an origin it does not hold: give --origin "
            "LAT,LON,H or --sequence DIR to score --pos",
            truth_path,
        )
    scores = score_gnss(
        truth,
        read_velocity_csv(args.vel) if args.vel else None,
        read_heading_csv(args.heading) if args.heading else None,
        read_position_csv(args.pos) if args.pos else None,
        Thresholds(args.moving_mps, args.standstill_mps),
    )
    for name in scores.without_overlap():
        coverage = getattr(scores, name).coverage
        own = gps_span(coverage.first_s, coverage.last_s)
        span = gps_span(scores.truth_first_s, scores.truth_last_s)
        raise InputError(
            f"none of its {coverage.epochs} epochs ({own}) lies within the ground truth's span "
            f"({span}, {truth_path}) outside its gaps: nothing to score",
            inputs[name],
        )
    print_gnss_scores(scores, {**inputs, "truth": truth_path})
    if args.json:
        Path(args.json).parent.mkdir(parents=True, exist_ok=True)
        files = {name: None if path is None else str(path) for name, path in inputs.items()}
        document = {**scores.to_dict(), "files": {**files, "truth": str(truth_path)}}
        Path(args.json).write_text(json_text(document, indent=2) + "\n")
    return 0


def gps_span(first_s: float | None, last_s: float | None) -> str:
    """A GPS time span for people: ``GPS week W, seconds of week A-B`` (weeks both ends when
    they differ)."""
    if first_s is None or last_s is None:
        return "no epochs"
    (w0, s0), (w1, s1) = (time_of_week(v) for v in (first_s, last_s))
    if w0 == w1:
        return f"GPS week {int(w0)}, seconds of week {float(s0):.1f}-{float(s1):.1f}"
    return f"GPS week {int(w0)} {float(s0):.1f} s - week {int(w1)} {float(s1):.1f} s"


def _stats_cells(stats: ErrorStats, fmt: str, unit: str) -> list[str]:
    beyond = ", ".join(f"> {limit:g}{unit}: {n}" for limit, n in stats.beyond.items())
    return [
        str(stats.count),
        number_or_dash(stats.median, fmt),
        number_or_dash(stats.p95, fmt),
        number_or_dash(stats.max, fmt),
        beyond or "—",
    ]


def print_gnss_scores(scores: GnssScores, files: dict[str, str | None]) -> None:
    """The scores as one table, and per input what was left out."""
    console = Console(width=None if sys.stdout.isatty() else 120)
    th = scores.thresholds
    table = Table(
        title=f"GNSS outputs against ground truth ({escape(str(files['truth']))}: "
        f"{scores.truth_source}, {gps_span(scores.truth_first_s, scores.truth_last_s)})",
        caption=f"moving: truth speed > {th.moving_mps:g} m/s, standstill: < "
        f"{th.standstill_mps:g} m/s; availability: share of the moving epochs (pos.csv: of the "
        "scored ones); epochs: those the figures are over (valid, and moving or standing)",
    )
    for column in ("input", "figure", "availability", "epochs", "median", "p95", "max", "beyond"):
        table.add_column(column, justify="left" if column in ("input", "figure") else "right")

    def share(value: float | None) -> str:
        return "—" if value is None else f"{value:.1%}"

    rows: list[tuple[str, str, str, ErrorStats, str, str]] = []
    if scores.velocity is not None:
        v, avail = scores.velocity, share(scores.velocity.availability)
        rows += [
            ("vel.csv", "speed error [m/s]", avail, v.speed_error_mps, "{:.3f}", ""),
            ("", "course error [°]", avail, v.course_error_deg, "{:.2f}", "°"),
            ("", "speed at standstill [m/s]", "", v.standstill_speed_mps, "{:.3f}", " m/s"),
        ]
    if scores.heading is not None:
        tight, conv = scores.heading.tight, scores.heading.conventional
        rows += [
            ("heading.csv", "tight, reliable [°]", share(tight.availability), tight.error_deg),
            ("", "conventional, conv_valid [°]", share(conv.availability), conv.error_deg),
        ]
        rows[-2:] = [(*row, "{:.2f}", "°") for row in rows[-2:]]
    if scores.positions is not None:
        p, avail = scores.positions, share(scores.positions.availability)
        rows += [
            ("pos.csv", "horizontal error [m]", avail, p.horizontal_m, "{:.2f}", ""),
            ("", "vertical error [m]", avail, p.vertical_m, "{:.2f}", ""),
        ]
    for source, label, availability, stats, fmt, unit in rows:
        table.add_row(source, escape(label), availability, *_stats_cells(stats, fmt, unit))
    console.print(table)
    for name, result in (
        ("velocity", scores.velocity),
        ("heading", scores.heading),
        ("positions", scores.positions),
    ):
        if result is None:
            continue
        c = result.coverage
        left_out = f", {c.outside} outside the truth's span or in its gaps" if c.outside else ""
        console.print(
            f"{escape(str(files[name]))}: {c.epochs} epochs, {c.scored} scored{left_out}; "
            f"{c.moving} moving, {c.standstill} at standstill"
        )
