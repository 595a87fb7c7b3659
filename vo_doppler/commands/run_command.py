"""``vo-doppler run SEQUENCE_DIR -o OUT``: the whole pipeline on one sequence folder."""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.markup import escape
from rich.progress import Progress
from rich.table import Table

from vo_doppler.commands.arg_types import window_size
from vo_doppler.commands.correction_options import add_correction_options, correction_config
from vo_doppler.commands.heading_method import add_heading_method_option, heading_method_config
from vo_doppler.commands.satellite_options import add_selection_options
from vo_doppler.commands.span_options import add_span_options, time_span
from vo_doppler.errors import InputError, shown
from vo_doppler.eval.pipelines import PIPELINE_LABELS
from vo_doppler.heading.pipeline import HeadingMethod
from vo_doppler.io.output_folder import RUN, check_output_folder, staged_output, untouched
from vo_doppler.io.sequence import manifest_inputs
from vo_doppler.job import require_tight_heading, run_recording
from vo_doppler.model.sequence import Sequence
from vo_doppler.report.run_report import TABLE_COLUMNS, table_cell
from vo_doppler.run import RunConfig, RunResult
from vo_doppler.vo.config import VoConfig

log = logging.getLogger(__name__)


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "run",
        help=summary,
        description="Run the main job on a sequence folder (sequence.yaml): monocular VO with "
        "metric scale from the calibrated wheel speed, wheel-scale and gyro-bias calibration "
        "from Doppler, tightly coupled Doppler heading, VO heading correction; evaluates "
        "against the ground truth when the folder has one.",
    )
    parser.add_argument("sequence", type=Path, help="folder with sequence.yaml")
    parser.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    add_run_options(parser)
    parser.add_argument(
        "--allow-outside-paths",
        action="store_true",
        help="accept manifest paths outside the sequence folder (absolute or ../)",
    )
    parser.add_argument(
        "--heading",
        type=Path,
        metavar="FILE",
        help="an absolute heading of your own (dual-antenna receiver, INS, an earlier run's "
        "heading.csv) used instead of computing the tightly coupled heading from GNSS: a "
        "heading.csv, or a minimal CSV gps_time_s, heading_deg or course_deg, sigma_deg[, "
        "valid] (docs/formats.md); the corrected pipelines then run on a recording without "
        "GNSS too",
    )
    add_span_options(
        parser,
        "recording's first GNSS epoch (without GNSS: its first image, else its first "
        "yaw-rate sample)",
    )
    parser.add_check(heading_method_problem)
    parser.set_defaults(func=run)


def heading_method_problem(args: argparse.Namespace) -> str | None:
    """``--heading-method`` chooses how the tight heading is computed: with ``--heading FILE``
    none is computed, and a method other than the default would be ignored."""
    if args.heading is not None and args.heading_method != HeadingMethod.AUTO.value:
        return (
            f"--heading-method {args.heading_method} has no effect with --heading: the heading "
            "is the file's, not computed from GNSS (drop one of them)"
        )
    return None


def add_run_options(parser: argparse.ArgumentParser) -> None:
    """The main job's options (shared by ``run`` and ``batch``); see :func:`run_config`."""
    add_selection_options(parser)
    parser.add_argument(
        "--window",
        type=window_size,
        default=VoConfig().window_size,
        help="VO window (frames, >= 3)",
    )
    add_correction_options(parser)
    add_heading_method_option(parser)


def run_config(args: argparse.Namespace) -> RunConfig:
    """The :class:`RunConfig` of the options :func:`add_run_options` added (radians inside)."""
    return RunConfig(
        systems=args.systems.upper(),
        elevation_mask_rad=np.radians(args.elev_mask),
        heading=heading_method_config(args.heading_method),
        vo=VoConfig(window_size=args.window),
        correction=correction_config(args),
    )


def run(args: argparse.Namespace) -> int:
    check_output_folder(args.output, RUN, run_inputs(args), replace=True)
    try:
        result = run_and_write(args)
    except BaseException:
        log.error("%s", untouched(args.output))
        raise
    require_tight_heading(result, args.sequence, args.output)
    return 0


def run_inputs(args: argparse.Namespace) -> list[Path]:
    """What the output must not hold: the sequence's inputs and the ``--heading`` file."""
    return sequence_inputs(args.sequence) + ([args.heading] if args.heading else [])


def sequence_inputs(sequence: Path) -> list[Path]:
    """What the output must not hold: the manifest's inputs, or only the sequence folder when
    the manifest cannot be read (which reading the sequence then reports)."""
    try:
        return manifest_inputs(sequence)
    except InputError:
        return [sequence]


def run_and_write(args: argparse.Namespace) -> RunResult:
    """Read, check, run and write the outputs in place (all or nothing:
    :func:`vo_doppler.job.run_recording` into a staged output), showing the inputs, the VO's
    progress and the figures on the console."""
    console = Console(width=None if sys.stdout.isatty() else 150)

    @contextmanager
    def progress(inputs: Sequence) -> Iterator[Callable[[int], None]]:
        epochs = len(inputs.observations.epoch_time) if inputs.has_gnss else "no"
        console.print(
            f"{inputs.name}: {len(inputs.image_paths)} images, {epochs} GNSS epochs, "
            f"{len(inputs.wheel_speed)} wheel and {len(inputs.yaw_rate)} yaw-rate samples"
        )
        with Progress(console=console, transient=True) as bar:
            task = bar.add_task("visual odometry", total=len(inputs.image_paths))
            yield lambda _: bar.advance(task)

    job = run_recording(
        args.sequence,
        run_config(args),
        lambda: staged_output(args.output, RUN, run_inputs(args)),
        time_span(args),
        args.heading,
        args.allow_outside_paths,
        progress,
    )
    if job.result.vo is None:
        console.print(f"{job.sequence.name} has no camera: only the non-visual pipelines ran")
    print_summary(console, job.summary)
    console.print(
        f"wrote {shown(args.output)}/report.html (open it in a browser) and the trajectories, "
        "figures"
    )
    return job.result


def print_summary(console: Console, summary: dict) -> None:
    """The run's figures with the report's words: "available" (the estimator produced a
    heading) and "used" (it corrected the VO)."""
    vo = (
        f"VO {summary['vo_frames']} frames ({summary['vo_flagged_frames']} flagged)"
        if "vo_frames" in summary
        else "no camera"
    )
    if "heading_source" in summary:
        console.print(
            f"absolute heading {summary['heading_source']}; used by the tightly coupled "
            f"correction at {summary['tight_heading_used']:.0%} of its rows; "
            f"{summary['gnss_epochs']} GNSS epochs; {vo}"
        )
    elif "gnss" in summary:  # no GNSS: the heading figures do not exist
        console.print(f"GNSS {summary['gnss']}; {vo}")
    else:
        console.print(
            f"of {summary['gnss_epochs']} GNSS epochs, heading available: conventional "
            f"{summary['conventional_heading_availability']:.0%}, tightly coupled "
            f"{summary['tight_heading_availability']:.0%}; tightly coupled used by the "
            f"correction {summary['tight_heading_used']:.0%} "
            f"({summary['tight_heading_rejected_rows']} Doppler rows rejected by the NLOS "
            f"tests); wheel scale {summary['final_wheel_scale']:.4f}, "
            f"gyro bias {summary['final_gyro_bias_dps']:+.3f} deg/s; {vo}"
        )
    errors = summary.get("evaluation")
    if not errors:
        return
    table = Table(title="against ground truth (definitions in report.html)")
    table.add_column("pipeline")
    for _, label, _ in TABLE_COLUMNS:
        table.add_column(escape(label), justify="right")
    for name, values in errors.items():
        table.add_row(
            PIPELINE_LABELS.get(name, name),
            *(table_cell(name, key, values[key], fmt) for key, _, fmt in TABLE_COLUMNS),
        )
    console.print(table)
