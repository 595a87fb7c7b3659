"""``vo-doppler run SEQUENCE_DIR -o OUT``: the whole pipeline on one sequence folder."""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.progress import Progress
from rich.table import Table

from vo_doppler.checks import (
    check_yaw_rate_unit,
    clock_warning,
    estimate_clock_offset,
    origin_warning,
)
from vo_doppler.commands.vo_command import window_size
from vo_doppler.errors import InputError
from vo_doppler.eval.pipelines import PIPELINE_LABELS, evaluate_pipelines
from vo_doppler.fusion.correction import CORRECTION_METHODS, CorrectionConfig
from vo_doppler.fusion.heading_blend import BlendConfig
from vo_doppler.io.heading_csv import write_heading_csv
from vo_doppler.io.output_folder import check_output_folder, staged_output, untouched
from vo_doppler.io.sequence import InputReport, read_sequence_with_report
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.sequence import Sequence
from vo_doppler.report.heading_figure import heading_figure
from vo_doppler.report.run_report import (
    TABLE_COLUMNS,
    error_per_100m_figure,
    trajectories_figure,
    write_html_report,
)
from vo_doppler.run import Pipeline, RunConfig, RunResult, run_sequence
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
    parser.add_argument("--systems", default="GREJC", help="GNSS systems to use")
    parser.add_argument("--elev-mask", type=float, default=10.0, help="degrees")
    parser.add_argument("--window", type=window_size, default=30, help="VO window (frames, >= 3)")
    parser.add_argument(
        "--reference",
        choices=("course", "orientation"),
        default="course",
        help="heading correction compares the absolute heading with the VO's course (default) "
        "or its orientation yaw ([TK18] sec. 3.6 as written)",
    )
    parser.add_argument(
        "--correction",
        choices=CORRECTION_METHODS,
        default=CorrectionConfig().method,
        help="heading correction: window ([TK18] Eq. 11-13) or kalman (adaptive blend, "
        "filter and smoother on the VO heading offset); default %(default)s",
    )
    parser.add_argument(
        "--causal",
        action="store_true",
        help="kalman: forward filter only (each pose uses the headings up to its time)",
    )
    parser.add_argument(
        "--allow-outside-paths",
        action="store_true",
        help="accept manifest paths outside the sequence folder (absolute or ../)",
    )
    parser.set_defaults(func=run)


def input_warnings(inputs: Sequence, report: InputReport) -> list[str]:
    """Errors raised and warnings listed before the long work: the yaw rate against its DBC
    unit, the origin against the RINEX approximate position, each sensor's time order."""
    check_yaw_rate_unit(inputs.yaw_rate, inputs.wheel_speed, report.yaw_rate_dbc_unit)
    found = report.warnings()
    origin = origin_warning(inputs.enu, inputs.observations.header.approx_position)
    return found + ([origin] if origin else [])


def result_warnings(inputs: Sequence, report: InputReport, result: RunResult) -> dict:
    """The CAN clock against the GNSS Doppler speed: the estimate and a warning beyond 0.2 s."""
    velocity = result.gnss.velocity
    horizontal = np.where(
        velocity.valid, np.linalg.norm(velocity.velocity_enu[:, :2], axis=1), np.nan
    )
    estimate = estimate_clock_offset(inputs.wheel_speed, velocity.t, horizontal)
    warning = clock_warning("CAN", estimate, report.can_time_offset_s)
    return {
        "can_clock_residual_offset_s": None if estimate is None else estimate.residual_s,
        "warnings": [warning] if warning else [],
    }


def run(args: argparse.Namespace) -> int:
    check_output_folder(args.output)
    try:
        result = run_and_write(args)
    except BaseException:
        log.error("%s", untouched(args.output))
        raise
    if not result.heading.tc_available.any():
        raise InputError(
            "the tightly coupled heading was unavailable at every epoch (the other results are "
            f"in {args.output})",
            args.sequence,
        )
    return 0


def run_and_write(args: argparse.Namespace) -> RunResult:
    """Read, check, run and write the outputs in place (all or nothing)."""
    inputs, report = read_sequence_with_report(args.sequence, args.allow_outside_paths)
    warnings = input_warnings(inputs, report)
    for text in warnings:
        log.warning("%s", text)
    config = RunConfig(
        systems=args.systems.upper(),
        elevation_mask=np.radians(args.elev_mask),
        vo=VoConfig(window_size=args.window),
        correction=CorrectionConfig(
            method=args.correction,
            reference=args.reference,
            blend=BlendConfig(smooth=not args.causal),
        ),
    )
    console = Console(width=None if sys.stdout.isatty() else 150)
    console.print(
        f"{inputs.name}: {len(inputs.image_paths)} images, "
        f"{len(inputs.observations.epoch_time)} GNSS epochs, {len(inputs.wheel_speed)} wheel "
        f"and {len(inputs.yaw_rate)} yaw-rate samples"
    )
    with Progress(console=console, transient=True) as progress:
        task = progress.add_task("visual odometry", total=len(inputs.image_paths))
        result = run_sequence(inputs, config, lambda _: progress.advance(task))
    clock = result_warnings(inputs, report, result)
    for text in clock["warnings"]:
        log.warning("%s", text)
    checks = {
        "warnings": warnings + clock["warnings"],
        "can_clock_residual_offset_s": clock["can_clock_residual_offset_s"],
        "time_order": {r.sensor: r.as_dict() for r in report.time_order},
    }
    with staged_output(args.output) as out:
        write_results(out, args, inputs, result, console, checks)
    console.print(f"wrote {args.output}/report.html and the trajectories, heading.csv, figures")
    return result


def write_results(
    out: Path,
    args: argparse.Namespace,
    inputs: Sequence,
    result: RunResult,
    console: Console,
    checks: dict,
) -> None:
    """Trajectories, heading table, figures, the summary (with the ``checks``: warnings, clock
    estimate, time order per sensor) and the HTML report into ``out``."""
    write_tum(out / "trajectory_vo.tum", result.trajectories[Pipeline.VO])
    write_tum(out / "trajectory_corrected.tum", result.trajectories[Pipeline.VO_GPS_TC])
    for name in (Pipeline.VO_GPS_CONV, Pipeline.DR_GPS_TC):
        if name in result.trajectories:
            write_tum(out / f"trajectory_{name}.tum", result.trajectories[name])
    write_heading_csv(out / "heading.csv", result.heading)
    summary = summarise(result)
    summary["heading_correction"] = args.correction + (" (causal)" if args.causal else "")
    summary.update(checks)
    figures = [out / "trajectories.png", out / "heading.png"]
    truth = inputs.truth
    errors = {}
    shown = result.trajectories
    if truth is not None:
        errors, per_100m, shown = evaluate_pipelines(
            result.trajectories, result.heading, result.tc_usable, truth
        )
        summary["evaluation"] = {name: e.to_dict() for name, e in errors.items()}
        error_per_100m_figure(out / "error_per_100m.png", per_100m, inputs.name)
        figures.append(out / "error_per_100m.png")
    truth_yaw = truth.yaw_at(result.heading.t) if truth is not None else None
    trajectories_figure(figures[0], shown, truth, inputs.name)
    heading_figure(figures[1], result.heading, truth_yaw, inputs.name)
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    facts = readable_facts(summary)
    write_html_report(out / "report.html", f"vo-doppler run: {inputs.name}", facts, errors, figures)
    print_summary(console, summary, errors)


FACT_FORMATS = {
    "gnss_epochs": ("GNSS epochs", "{:d}"),
    "conventional_heading_availability": ("conventional heading available", "{:.1%}"),
    "tight_heading_availability": ("tightly coupled heading available", "{:.1%}"),
    "tight_heading_reliable": ("tightly coupled heading reliable (gyro-consistent)", "{:.1%}"),
    "tight_heading_used": ("tightly coupled heading used by the correction", "{:.1%}"),
    "tight_heading_rejected_rows": ("Doppler rows rejected by the NLOS tests", "{:d}"),
    "tight_heading_epochs_with_rejection": ("epochs with a rejection", "{:d}"),
    "final_wheel_scale": ("wheel scale at the end", "{:.4f}"),
    "final_gyro_bias_dps": ("gyro bias at the end", "{:+.3f} deg/s"),
    "vo_frames": ("VO frames", "{:d}"),
    "vo_flagged_frames": ("VO frames flagged", "{:d}"),
    "vo_fps": ("VO speed", "{:.1f} frames/s"),
    "heading_correction": ("heading correction", "{}"),
}


def readable_facts(summary: dict) -> dict[str, str]:
    """The summary's scalars with labels and units for people (the report's list)."""
    facts = {}
    for key, value in summary.items():
        if key in ("evaluation", "time_order", "warnings"):
            continue
        label, fmt = FACT_FORMATS.get(key, (key, "{}"))
        facts[label] = fmt.format(value)
    return facts


def summarise(result: RunResult) -> dict:
    table = result.heading
    return {
        "gnss_epochs": len(table),
        "conventional_heading_availability": float(np.mean(table.conv_valid)),
        "tight_heading_availability": float(np.mean(table.tc_available)),
        "tight_heading_reliable": float(np.mean(table.tc_reliable)),
        "tight_heading_used": float(np.mean(result.tc_usable)),
        "tight_heading_rejected_rows": int(table.rejected_rows.sum()),
        "tight_heading_epochs_with_rejection": int(np.count_nonzero(table.rejected_rows)),
        "final_wheel_scale": float(table.wheel_scale[-1]),
        "final_gyro_bias_dps": float(np.degrees(table.gyro_bias[-1])),
        "vo_frames": result.vo.stats.frames,
        "vo_flagged_frames": len(result.vo.stats.flagged_frames),
        "vo_fps": result.vo.stats.fps,
    }


def print_summary(console: Console, summary: dict, errors: dict) -> None:
    console.print(
        f"heading available: conventional {summary['conventional_heading_availability']:.0%}, "
        f"tightly coupled {summary['tight_heading_availability']:.0%} of "
        f"{summary['gnss_epochs']} epochs ({summary['tight_heading_rejected_rows']} Doppler rows "
        "rejected by the NLOS tests); "
        f"wheel scale {summary['final_wheel_scale']:.4f}, "
        f"gyro bias {summary['final_gyro_bias_dps']:+.3f} deg/s; VO {summary['vo_frames']} "
        f"frames ({summary['vo_flagged_frames']} flagged)"
    )
    if not errors:
        return
    table = Table(title="against ground truth")
    table.add_column("pipeline")
    for _, label, _ in TABLE_COLUMNS:
        table.add_column(label, justify="right")
    for name, row in errors.items():
        values = row.to_dict()
        table.add_row(
            PIPELINE_LABELS.get(name, name),
            *(fmt.format(values[key]) for key, _, fmt in TABLE_COLUMNS),
        )
    console.print(table)
