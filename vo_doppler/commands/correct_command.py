"""``vo-doppler correct TRAJ --heading heading.csv``: VO heading correction ([TK18] sec. 3.6)."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

import numpy as np

from vo_doppler.commands.arg_types import finite_float, positive_float
from vo_doppler.commands.output_paths import check_output_files
from vo_doppler.commands.time_hints import frame_index_hint, offset_hint, span
from vo_doppler.errors import InputError
from vo_doppler.fusion.correction import (
    CORRECTION_METHODS,
    HEADING_SOURCES,
    REFERENCES,
    CorrectionConfig,
    absolute_heading,
    correct,
)
from vo_doppler.fusion.heading_blend import BlendConfig
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.trajectory import read_trajectory, write_kitti, write_tum
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD
from vo_doppler.report.json_text import json_text
from vo_doppler.vo.frames import WORLDS, camera_trajectory, vehicle_trajectory

log = logging.getLogger(__name__)


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "correct",
        help=summary,
        description="Correct the heading of a VO trajectory (TUM or KITTI, any VO system) with "
        "absolute headings: by the window method (shift to the window's absolute heading and "
        "rotate the positions about the window's oldest position, [TK18] Eq. 11-13) or by "
        "the Kalman blend (a filter and smoother on the VO heading offset whose noise is fitted "
        "to the drive). Output: vehicle (or camera) poses in an ENU-aligned frame with its "
        "origin at the first position.",
    )
    parser.add_argument("trajectory", help="VO trajectory, TUM or KITTI (camera poses)")
    parser.add_argument("--heading", required=True, help="heading.csv from `vo-doppler heading`")
    parser.add_argument("--calib", help="camera calibration (YAML with T_vehicle_camera)")
    parser.add_argument(
        "--format",
        choices=("auto", "tum", "kitti"),
        default="auto",
        help="trajectory file format (auto: from the extension and the number of columns)",
    )
    parser.add_argument("--times", help="timestamps file for a KITTI trajectory (one per line)")
    parser.add_argument(
        "--time-offset",
        type=finite_float,
        default=0.0,
        help="seconds added to trajectory times -> GPS",
    )
    parser.add_argument(
        "--correction",
        choices=CORRECTION_METHODS,
        default=CorrectionConfig().method,
        help="window: the window method of [TK18] (Takeyama & Kojima 2018) Eq. 11-13; kalman: "
        "the adaptive blend",
    )
    parser.add_argument(
        "--causal",
        action="store_true",
        help="kalman: forward filter only (each pose uses the headings up to its time)",
    )
    parser.add_argument(
        "--window-s",
        type=positive_float,
        default=2.0,
        help="window method's W (s), [TK18] Eq. 11-13",
    )
    parser.add_argument(
        "--source",
        choices=HEADING_SOURCES,
        default="tc+conv",
        help="absolute headings used: tightly coupled (usable: reliable and sigma < 2 deg), "
        "conventional, or the former where usable else the latter",
    )
    parser.add_argument(
        "--world",
        choices=WORLDS,
        default="first_camera",
        help="the input's world: the first camera's frame (what VO systems write) or already "
        "level, z up",
    )
    parser.add_argument(
        "--body",
        choices=("vehicle", "camera"),
        default="vehicle",
        help="write vehicle or camera poses",
    )
    parser.add_argument(
        "--max-gap-s",
        type=positive_float,
        default=1.5,
        help="longest gap (s) across which absolute headings are interpolated",
    )
    parser.add_argument(
        "--reference",
        choices=REFERENCES,
        default="course",
        help="compare the absolute heading with the VO's direction of travel (course) or with "
        "its orientation yaw (orientation: [TK18] sec. 3.6 as the paper writes it)",
    )
    parser.add_argument("-o", "--output", required=True, help="corrected trajectory (.tum/.kitti)")
    parser.set_defaults(func=run)


def _times(path: str | None) -> np.ndarray | None:
    if path is None:
        return None
    try:
        return np.loadtxt(path, dtype=float, ndmin=1)
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read times: {exc}", path) from exc


def run(args: argparse.Namespace) -> int:
    check_output_files(
        {"output": args.output}, [args.trajectory, args.heading, args.calib, args.times]
    )
    trajectory = read_trajectory(args.trajectory, args.format, _times(args.times))
    trajectory.t = trajectory.t + args.time_offset
    table = read_heading_csv(args.heading)
    extrinsic = (
        read_camera(args.calib).T_vehicle_camera if args.calib else CAMERA_TO_VEHICLE_FORWARD
    )
    overlap = (trajectory.t[-1] >= table.t[0]) and (trajectory.t[0] <= table.t[-1])
    if len(trajectory) == 0 or not overlap:
        hint = frame_index_hint(trajectory.t - args.time_offset) or (
            "; " + offset_hint(float(trajectory.t[0]), float(table.t[0]), "--time-offset")
            if len(trajectory) and len(table)
            else ""
        )
        raise InputError(
            f"the trajectory's times ({span(trajectory.t)}) do not overlap the heading epochs "
            f"({span(table.t)}, GPS time){hint}",
            args.trajectory,
        )
    config = CorrectionConfig(
        method=args.correction,
        reference=args.reference,
        window_s=args.window_s,
        blend=BlendConfig(smooth=not args.causal, max_gap_s=args.max_gap_s),
    )
    vehicle = vehicle_trajectory(trajectory, extrinsic, args.world)
    result = correct(vehicle, absolute_heading(table, args.source, config), config)
    if not result.has_absolute.any():
        raise InputError(
            f"no usable {args.source} heading within the trajectory's times: nothing to correct "
            "it with (heading.csv's usable epochs, --source, --max-gap-s)",
            args.heading,
        )
    out = result.vehicle if args.body == "vehicle" else camera_trajectory(result.vehicle, extrinsic)
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    if output.suffix.lower() in (".kitti", ".txt"):
        write_kitti(output, out)
    else:
        write_tum(output, out)
    summary = {
        "poses": len(out),
        "poses_with_absolute_heading": int(result.has_absolute.sum()),
        "final_correction_deg": float(np.degrees(result.correction[-1])),
        "correction": args.correction,
        "output": str(output),
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
    log.info("correct: %s", json_text(summary))
    print(json_text(summary))
    return 0
