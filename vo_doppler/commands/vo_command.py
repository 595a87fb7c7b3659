"""``vo-doppler vo IMAGES --calib CALIB``: monocular VO over an image folder."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path

import numpy as np
from rich.progress import Progress

from vo_doppler.commands.arg_types import frame_rate, window_size
from vo_doppler.commands.span_options import add_span_options, time_span
from vo_doppler.errors import InputError
from vo_doppler.eval.metrics import NO_MATCH, evaluate_by_time
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.images import (
    check_image_size,
    find_times_file,
    list_images,
    prefetch_images,
    read_times,
    times_from_fps,
)
from vo_doppler.io.output_folder import check_output_folder, open_output_folder
from vo_doppler.io.sensor_csv import SPEED_COLUMN, read_sensor_csv
from vo_doppler.io.trajectory import read_trajectory, write_kitti, write_tum
from vo_doppler.model.time_span import trim
from vo_doppler.report.json_text import json_text
from vo_doppler.report.plots import plot_top_view
from vo_doppler.report.run_report import number_or_dash
from vo_doppler.time_hints import span
from vo_doppler.vo.batch import MIN_VO_FRAMES, run_visual_odometry
from vo_doppler.vo.config import VoConfig

log = logging.getLogger(__name__)

CAMERA_UP = np.array([0.0, -1.0, 0.0])


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "vo",
        help=summary,
        description="Track corners, initialise from two views and refine poses and points by "
        "Levenberg–Marquardt bundle adjustment over a sliding window. Writes camera poses in "
        "the first camera's frame (OpenCV axes), one per image.",
    )
    parser.add_argument("images", type=Path, help="folder of PNG/JPG images (sorted by name)")
    parser.add_argument("--calib", type=Path, required=True, help="KITTI calib.txt or YAML")
    timing = parser.add_mutually_exclusive_group()
    timing.add_argument(
        "--times",
        type=Path,
        help="times.txt or CSV with a t column (default: times.txt beside the image folder, "
        "if there is one, else --fps)",
    )
    timing.add_argument(
        "--fps",
        type=frame_rate,
        help="fixed frame rate (Hz)",
    )
    parser.add_argument("--speed", type=Path, help="CSV t,speed_mps for metric scale")
    parser.add_argument(
        "--window",
        type=window_size,
        default=VoConfig().window_size,
        help="bundle-adjustment window (frames, >= 3)",
    )
    parser.add_argument("--gt", type=Path, help="ground truth (KITTI poses or TUM) to evaluate")
    parser.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    add_span_options(parser, "first image", " in the image times' time base")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    check_output_folder(
        args.output, "vo", [args.images, args.calib, args.times, args.speed, args.gt]
    )
    files = list_images(args.images)
    camera = read_camera(args.calib)
    check_image_size(camera, files, args.calib)
    if args.fps is not None:
        times = times_from_fps(args.fps, len(files))
    else:
        times_path = args.times or find_times_file(args.images)
        if times_path is None:
            raise InputError("no timestamps: give --times FILE or --fps F", args.images)
        if args.times is None:
            log.info("image times from %s (found beside the images; --times overrides)", times_path)
        times = read_times(times_path, len(files))
    # Read before the VO (the long part): a missing or bad file stops the command first.
    truth = None if args.gt is None else read_trajectory(args.gt, times=times)
    speed = series = None
    if args.speed is not None:
        series = read_sensor_csv(args.speed, SPEED_COLUMN)
    part = time_span(args)
    if not part.whole:
        interval = part.resolve(times, "images")
        inside = interval.mask(times)
        files = [file for file, keep in zip(files, inside, strict=True) if keep]
        times, truth, series = times[inside], trim(truth, interval), trim(series, interval)
    if series is not None:
        if len(series) < 2:
            raise InputError("speed CSV needs at least two samples", args.speed)
        speed = (series.t, series.value)
    config = VoConfig(window_size=args.window)
    decoded = [0]

    def images():
        for image in prefetch_images(files):
            decoded[0] += image is not None
            yield image

    with Progress(transient=True) as progress:
        task = progress.add_task("visual odometry", total=len(files))
        output = run_visual_odometry(
            images(),
            times,
            camera,
            config,
            speed,
            on_frame=lambda _: progress.advance(task),
        )
    if decoded[0] < MIN_VO_FRAMES:
        raise InputError(
            f"only {decoded[0]} of the {len(files)} images could be decoded", args.images
        )
    open_output_folder(args.output, "vo")
    write_tum(args.output / "trajectory.tum", output.trajectory)
    write_kitti(args.output / "trajectory.kitti", output.trajectory)
    stats = output.stats.to_dict()
    stats["metric_scale"] = output.metric
    stats["flagged_frames"] = [
        {**flag, "file": files[flag["index"]].name} for flag in stats["flagged_frames"]
    ]
    curves = {"VO" if output.metric else "VO (arbitrary scale)": output.trajectory}
    if truth is not None:
        errors = evaluate_by_time(output.trajectory, truth, "start", CAMERA_UP)
        if errors is None:
            stats["evaluation_skipped"] = (
                f"not evaluated against {args.gt}: {NO_MATCH} (images {span(times)}, ground "
                f"truth {span(truth.t)})"
            )
            log.warning("%s", stats["evaluation_skipped"])
        else:
            stats["evaluation"] = errors.to_dict()
            for text in errors.notes:
                log.warning("%s", text)
        curves["ground truth"] = truth
    (args.output / "vo_stats.json").write_text(json_text(stats, indent=2))
    plot_top_view(curves, args.output / "trajectory.png", ("x", "z"), "Top view (camera frame)")
    print(
        f"{stats['frames']} frames, {stats['keyframes']} keyframes, {stats['fps']:.1f} fps, "
        f"{len(stats['flagged_frames'])} flagged; "
        + ("metric scale from speed" if output.metric else "scale is arbitrary (no --speed)")
    )
    if "evaluation" in stats:
        figures = stats["evaluation"]
        print(
            f"final error {figures['final_position_error_m']:.3f} m "
            f"({number_or_dash(figures['final_drift_pct'], '{:.2f}')} % of path), end yaw error "
            f"{figures['end_yaw_error_deg']:.3f} deg, ATE {figures['ate_rmse_m']:.3f} m"
        )
    print(f"wrote {args.output}/trajectory.tum, trajectory.kitti, vo_stats.json, trajectory.png")
    return 0
