"""``vo-doppler deadreckon``: the low-cost IMU/GPS path mapping (two gyros + GPS) end to end."""

from __future__ import annotations

import argparse

import numpy as np
from rich.console import Console
from rich.table import Table

from vo_doppler.checks import check_standstill_is_still
from vo_doppler.commands.arg_types import (
    non_negative_float,
    number_in,
    positive_float,
    positive_int,
)
from vo_doppler.commands.output_paths import check_output_files
from vo_doppler.geo import EnuFrame
from vo_doppler.io.gps_fixes import read_gps_fixes
from vo_doppler.io.output_folder import check_output_folder
from vo_doppler.io.sensor_csv import read_numeric_csv, read_yaw_rate_csv
from vo_doppler.lowcost.pipeline import DeadReckonConfig, run_deadreckon, smoothed_track_speed
from vo_doppler.report.deadreckon import drift_table_rows, output_files, write_outputs

TABLE_HEADERS = (
    "variant",
    "drift °/min",
    "final error °",
    "loop gap m",
    "loop gap %",
    "end error m",
    "end error %",
    "length m",
)
"""The columns of ``drift_table_rows``; the terminal shows the loop gap on a route that closes,
else the end error (the CSV has both)."""
LOOP_GAP_COLUMNS, END_ERROR_COLUMNS = (3, 4), (5, 6)


_k_number = number_in(0.0, 2.0)


def _k_value(text: str) -> float | None:
    """'auto' (None) or a weight of gyro 2 in [0, 2]."""
    return None if text == "auto" else _k_number(text)


def _tau_value(text: str) -> float | None:
    """'auto' (None) or a bias averaging time > 0 (s)."""
    return None if text == "auto" else positive_float(text)


def _interval(text: str) -> tuple[float, float]:
    try:
        t0, t1 = (float(part) for part in text.split(","))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"expected T0,T1 in seconds, got {text!r}") from exc
    if not (np.isfinite(t0) and np.isfinite(t1)):
        raise argparse.ArgumentTypeError(f"expected finite T0,T1 in seconds, got {text!r}")
    if t1 <= t0:
        raise argparse.ArgumentTypeError(f"the interval must end after it starts: {text!r}")
    return t0, t1


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "deadreckon",
        help=summary,
        description="The low-cost path mapping of [KZ]: combine two yaw-rate sensors (Eq. 7), "
        "remove the static bias (Eq. 5-6), optionally threshold (Eq. 9), thin and interpolate "
        "the GPS (Eq. 10-14), dead-reckon (Eq. 15-17) and report the heading drift in deg/min "
        "per variant.",
    )
    parser.add_argument("--gyro1", required=True, help="CSV t,yaw_rate_rad_s (CCW positive)")
    parser.add_argument("--gyro2", required=True, help="CSV t,yaw_rate_rad_s (CCW positive)")
    parser.add_argument("--gps", required=True, help="CSV t,lat_deg,lon_deg[,speed_mps] or NMEA")
    parser.add_argument(
        "--k", type=_k_value, default=None, help="weight of gyro 2 in [0, 2], or auto (sweep)"
    )
    parser.add_argument(
        "--tau",
        type=_tau_value,
        default=None,
        help="bias averaging time s, or auto: the Allan minimum over a standstill, the whole "
        "window over a straight stretch (never longer than the window)",
    )
    window = parser.add_mutually_exclusive_group()
    window.add_argument(
        "--standstill", type=_interval, help="standstill T0,T1 (s); default: found from speed"
    )
    window.add_argument(
        "--straight",
        type=_interval,
        help="T0,T1 (s) of straight constant-course driving used instead of a standstill for "
        "k and ε0 (a proxy for records without a standstill)",
    )
    parser.add_argument(
        "--wheel-speed", help="CSV t,speed_mps used to find the standstill (optional)"
    )
    parser.add_argument(
        "--threshold",
        type=non_negative_float,
        help="threshold h (rad/s) of [KZ] Eq. 9; default 3σ of the de-biased standstill rate",
    )
    parser.add_argument("--downsample", type=positive_int, default=1, help="keep every M-th fix")
    parser.add_argument(
        "--cluster-m",
        type=non_negative_float,
        default=3.0,
        help="drop fixes closer than this (m)",
    )
    parser.add_argument("-o", "--output", required=True, help="output folder")
    parser.set_defaults(func=run)


def _speed_source(args, fixes):
    """(t, speed) from the wheel-speed CSV, else the GPS speed, with the source's name."""
    if args.wheel_speed:
        columns, _ = read_numeric_csv(args.wheel_speed, ("t", "speed_mps"))
        return (columns["t"], columns["speed_mps"]), "wheel speed"
    if np.mean(np.isfinite(fixes.speed)) > 0.9:
        good = np.isfinite(fixes.speed)
        return (fixes.t[good], fixes.speed[good]), "GPS speed"
    return None, ""


def _track_speed(fixes) -> tuple[np.ndarray, np.ndarray]:
    """(t, speed) of the fixes from their positions (for the standstill check when the file
    gives no speed)."""
    good = np.isfinite(fixes.lat) & np.isfinite(fixes.lon)
    t, lat, lon = fixes.t[good], fixes.lat[good], fixes.lon[good]
    if t.size < 2:
        return t, np.zeros_like(t)
    enu = EnuFrame(float(lat[0]), float(lon[0]), 0.0).geodetic_to_enu(lat, lon, 0.0)
    return t, smoothed_track_speed(t, enu[:, 0], enu[:, 1])


def run(args: argparse.Namespace) -> int:
    inputs = (args.gyro1, args.gyro2, args.gps, args.wheel_speed)
    check_output_folder(args.output, "deadreckon", list(inputs))
    check_output_files(output_files(args.output), inputs)
    gyro1 = read_yaw_rate_csv(args.gyro1)
    gyro2 = read_yaw_rate_csv(args.gyro2)
    fixes = read_gps_fixes(args.gps)
    config = DeadReckonConfig(
        k=args.k,
        tau_s=args.tau,
        standstill_s=args.standstill or args.straight,
        window_is_standstill=args.straight is None,
        threshold_rad_s=args.threshold,
        downsample=args.downsample,
        cluster_m=args.cluster_m,
    )
    speed, source = _speed_source(args, fixes)
    if args.standstill:
        measured = speed if speed is not None else _track_speed(fixes)
        check_standstill_is_still(args.standstill, *measured, source or "GPS track speed")
    result = run_deadreckon(
        (gyro1.t, gyro1.value), (gyro2.t, gyro2.value), fixes.as_tuple(), config, speed
    )
    paths = write_outputs(args.output, result)

    model = result.model
    window = "standstill" if args.straight is None else "straight stretch"
    console = Console()
    table = Table(title=f"Heading drift (reference: {result.reference_source})")
    closed = bool(result.rows) and result.rows[0].gap.closed
    hidden = END_ERROR_COLUMNS if closed else LOOP_GAP_COLUMNS
    shown = [i for i in range(len(TABLE_HEADERS)) if i not in hidden]
    for i in shown:
        table.add_column(TABLE_HEADERS[i], justify="left" if i == 0 else "right", no_wrap=i == 0)
    for row in drift_table_rows(result.rows):
        table.add_row(*(str(row[i]) for i in shown))
    console.print(table)
    if not closed:
        console.print(
            "the GPS route does not close (it ends more than 5 % of its length and 10 m from "
            "its start): no loop gap; the end error is the distance from the GPS track's end"
        )
    choices = ", ".join(f"{c.method} {c.k:.3f}" for c in model.k_choices.as_list())
    console.print(
        f"k used {model.k:.3f} ({choices}); τ {model.tau:.3g} s; "
        f"ε0 combined {np.degrees(model.eps0['combined']):.4g} deg/s; "
        f"h {np.degrees(model.h):.3g} deg/s; {window} "
        f"{result.prepared.standstill[0]:.2f}–{result.prepared.standstill[1]:.2f} s"
    )
    start = result.initial_heading
    if start is None:
        console.print("initial heading: the first GPS course (too little track to fit one)")
    else:
        course = start.to_dict()
        console.print(
            f"initial heading: course {course['course_deg']:.2f} ± {course['sigma_deg']:.2f} deg "
            f"(1σ), the path fitted to {start.fixes} GPS fixes of {start.t0:.2f}–{start.t1:.2f} s"
        )
    skipped = gyro1.n_skipped + gyro2.n_skipped
    console.print(
        f"skipped input rows: gyros {skipped}, GPS {fixes.n_skipped}; GPS gaps "
        f"{result.prepared.report.n_gaps}, duplicate GPS times "
        f"{result.prepared.report.n_duplicate_times}"
    )
    console.print(f"wrote {', '.join(str(p) for p in paths.values())}")
    return 0
