"""``vo-doppler heading OBS --nav NAV ...``: tightly coupled Doppler–gyro–wheel heading."""

from __future__ import annotations

import argparse
import logging
from dataclasses import replace
from pathlib import Path

import numpy as np

from vo_doppler.bounds import RECEIVER_RADIUS
from vo_doppler.choices import values
from vo_doppler.commands.arg_types import (
    add_yaw_rate_sign,
    finite_float,
    lever_arm,
    non_negative_float,
    positive_float,
    positive_int,
)
from vo_doppler.commands.heading_method import add_heading_method_option, heading_method_config
from vo_doppler.commands.output_paths import check_output_files
from vo_doppler.commands.satellite_options import (
    add_satellite_options,
    add_selection_options,
    satellite_inputs,
    satellite_states,
)
from vo_doppler.commands.span_options import add_span_options, time_span
from vo_doppler.errors import InputError, VoDopplerError
from vo_doppler.geo import EnuFrame
from vo_doppler.gnss.pipeline import gnss_velocity
from vo_doppler.heading.from_gnss import emulated_canyon, heading_from_gnss
from vo_doppler.heading.integrity import car_checked_velocity
from vo_doppler.heading.pipeline import CalibrationMethod
from vo_doppler.io.can import read_can_motion
from vo_doppler.io.can_report import ShortFrames
from vo_doppler.io.gnss_csv import write_velocity_csv
from vo_doppler.io.heading_csv import write_heading_csv
from vo_doppler.io.output_folder import write_files
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.sensor_csv import read_speed_csv, read_yaw_rate_csv
from vo_doppler.io.trajectory import read_trajectory
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.time_span import trim
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.model.vehicle_source import VehicleSignalSource
from vo_doppler.report.heading_figure import heading_figure
from vo_doppler.report.json_text import json_text
from vo_doppler.report.run_outputs import final_calibration

log = logging.getLogger(__name__)


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "heading",
        help=summary,
        description="Calibrate wheel scale and gyro bias from the conventional Doppler velocity "
        "([TK18] sec. 3.3-3.4) and estimate the heading from a window of Doppler rows of all "
        "satellites with the calibrated speed and yaw rate ([TK18] sec. 3.5). Writes a CSV row per "
        "GNSS epoch (headings as course, degrees clockwise from north) and a figure.",
    )
    parser.add_argument("obs", type=Path, help="RINEX observation file")
    add_satellite_options(parser)
    add_selection_options(parser)
    sensors = parser.add_argument_group("vehicle sensors (CAN log + DBC, or two CSV files)")
    sensors.add_argument("--can", type=Path, help="candump -l, .asc, .blf or python-can .csv")
    sensors.add_argument("--dbc", type=Path, help="DBC file decoding the CAN log's signals")
    sensors.add_argument("--yaw-rate", help="MESSAGE.SIGNAL of the yaw rate")
    sensors.add_argument("--wheel-speed", help="MESSAGE.SIGNAL[,MESSAGE.SIGNAL...] (averaged)")
    add_yaw_rate_sign(sensors)
    sensors.add_argument("--can-channel", help="only frames of this channel/bus")
    sensors.add_argument(
        "--can-short-frames",
        choices=values(ShortFrames),
        default=ShortFrames.SKIP.value,
        help="frames shorter than their DBC length: skip them or zero-pad them, for logs that "
        "drop trailing zero bytes",
    )
    sensors.add_argument("--yaw-rate-csv", type=Path, help="CSV t,yaw_rate_rad_s (ccw +)")
    sensors.add_argument("--speed-csv", type=Path, help="CSV t,speed_mps")
    sensors.add_argument(
        "--time-offset-can",
        type=finite_float,
        default=0.0,
        help="seconds added to CAN times to give GPS time (a log in Unix time needs the "
        "GPS-Unix offset: -315964800 + leap seconds, e.g. -315964782 in 2017-2026)",
    )
    sensors.add_argument(
        "--time-offset-yaw",
        type=finite_float,
        default=0.0,
        help="extra seconds added to the yaw-rate times",
    )
    sensors.add_argument(
        "--time-offset-speed",
        type=finite_float,
        default=0.0,
        help="extra seconds added to the speed times",
    )
    parser.add_argument(
        "--antenna-lever-arm",
        type=lever_arm(),
        default=(0.0, 0.0),
        help="GNSS antenna X,Y[,Z] m in the vehicle frame (x forward, y left) from the point "
        "whose heading is wanted; the Doppler is then the antenna's in turns",
    )
    parser.add_argument("--window-s", type=positive_float, default=2.0, help="heading window (s)")
    add_heading_method_option(parser)
    parser.add_argument(
        "--no-nlos-rejection",
        action="store_true",
        help="keep every Doppler row: no data snooping for reflected (NLOS) satellites",
    )
    parser.add_argument(
        "--calibration",
        choices=values(CalibrationMethod),
        default=CalibrationMethod.LS.value,
        help="wheel-scale and gyro-bias calibration from the conventional Doppler velocity "
        "([TK18] sec. 3.3-3.4): ls (least squares over a sliding window), kalman, or none",
    )
    parser.add_argument("--gyro-bias", type=finite_float, help="fixed gyro bias (deg/s) instead")
    parser.add_argument("--wheel-scale", type=positive_float, help="fixed wheel scale instead")
    parser.add_argument(
        "--max-sats", type=positive_int, help="emulated canyon: satellites kept per epoch"
    )
    parser.add_argument(
        "--max-sats-after",
        type=non_negative_float,
        default=0.0,
        help="seconds after the first epoch from which --max-sats applies",
    )
    parser.add_argument("--gt", type=Path, help="ground truth TUM (GPS time, z-up world)")
    parser.add_argument("-o", "--output", type=Path, required=True, help="heading CSV")
    parser.add_argument("--figure", type=Path, help="PNG (default: next to the CSV)")
    parser.add_argument(
        "--vel",
        type=Path,
        help="also write the conventional velocity as vel.csv with its valid column after the "
        "car's gyro and wheel tests (docs/outputs.md; not written by default)",
    )
    add_span_options(parser, "first observation epoch")
    parser.add_check(sensor_options_problem)
    defaults = {option: parser.get_default(_dest(option)) for option in CAN_ONLY_OPTIONS}
    parser.add_check(lambda args: can_only_options_problem(args, defaults))
    parser.set_defaults(func=run)


CAN_ONLY_OPTIONS = ("--yaw-rate-sign", "--can-channel", "--can-short-frames", "--time-offset-can")
"""Options that only reading a CAN log uses (``--time-offset-yaw`` and ``--time-offset-speed``
apply to the CAN signals as well as to the CSV files)."""


def _dest(option: str) -> str:
    return option.removeprefix("--").replace("-", "_")


def can_only_options_problem(args: argparse.Namespace, defaults: dict[str, object]) -> str | None:
    """The problem when the sensors are the CSV files and a :data:`CAN_ONLY_OPTIONS` option is
    set to other than its default (``defaults``, by option): it would be ignored."""
    if args.can is not None or args.yaw_rate_csv is None:
        return None
    given = [o for o in CAN_ONLY_OPTIONS if getattr(args, _dest(o)) != defaults[o]]
    if not given:
        return None
    hint = (
        "; the CSV times take --time-offset-yaw and --time-offset-speed"
        if "--time-offset-can" in given
        else ""
    )
    named = " and ".join([", ".join(given[:-1]), given[-1]] if len(given) > 1 else given)
    return (
        f"{named} appl{'ies' if len(given) == 1 else 'y'} to a CAN log (--can) only, "
        f"and the sensors are the CSV files (drop {'it' if len(given) == 1 else 'them'}){hint}"
    )


def sensor_options_problem(args: argparse.Namespace) -> str | None:
    """The problem when the sensor options name neither a whole CAN source (--can with --dbc,
    --yaw-rate and --wheel-speed) nor both CSV files, or name both kinds (one would be
    ignored)."""
    can_options = {
        "--can": args.can,
        "--dbc": args.dbc,
        "--yaw-rate": args.yaw_rate,
        "--wheel-speed": args.wheel_speed,
    }
    csv_options = {"--yaw-rate-csv": args.yaw_rate_csv, "--speed-csv": args.speed_csv}
    can_given = [name for name, value in can_options.items() if value is not None]
    csv_given = [name for name, value in csv_options.items() if value is not None]
    if can_given and csv_given:
        return (
            f"give the CAN log or the CSV files, not both ({', '.join(can_given)} and "
            f"{', '.join(csv_given)})"
        )
    if can_given:
        missing = [name for name, value in can_options.items() if value is None]
        return f"{', '.join(can_given)} needs {', '.join(missing)}" if missing else None
    if len(csv_given) == 1:
        missing = next(name for name, value in csv_options.items() if value is None)
        return f"{csv_given[0]} needs {missing}"
    if not csv_given:
        return (
            "no vehicle sensors: give --can LOG --dbc DBC --yaw-rate MSG.SIG --wheel-speed "
            "MSG.SIG, or --yaw-rate-csv FILE --speed-csv FILE"
        )
    return None


def _sensors(args) -> tuple[SensorSeries, SensorSeries, str]:
    """Wheel speed, yaw rate and the yaw rate's declared unit (the DBC's, rad/s for a CSV)."""
    if args.can is not None:
        motion = read_can_motion(
            args.can,
            args.dbc,
            args.yaw_rate,
            args.wheel_speed,
            args.yaw_rate_sign,
            args.time_offset_can + args.time_offset_yaw,
            args.time_offset_can + args.time_offset_speed,
            args.can_channel,
            args.can_short_frames,
        )
        return motion.speed, motion.yaw_rate, motion.report.dbc_units.get(args.yaw_rate.strip(), "")
    return (
        read_speed_csv(args.speed_csv, args.time_offset_speed),
        read_yaw_rate_csv(args.yaw_rate_csv, args.time_offset_yaw),
        "rad/s",
    )


def _signal_source(args: argparse.Namespace, yaw_rate_unit: str) -> VehicleSignalSource:
    """The vehicle signals in the words of this command's options, for the checks' messages
    (``yaw_rate_unit``: the DBC's unit of the yaw-rate signal)."""
    if args.can is not None:
        return VehicleSignalSource(
            sensor="CAN",
            offset_s=args.time_offset_can,
            offset_name="--time-offset-can",
            yaw_rate=f"{args.dbc}: the yaw rate, CAN signal {args.yaw_rate} (--yaw-rate)",
            yaw_rate_unit=yaw_rate_unit,
            yaw_rate_unit_fix="the DBC declares the signal in rad/s: fix the unit (or factor) "
            "in the DBC",
            yaw_rate_sign_fix=f"give --yaw-rate-sign {-args.yaw_rate_sign:g}",
        )
    return VehicleSignalSource(
        sensor="speed CSV",
        offset_s=args.time_offset_speed,
        offset_name="--time-offset-speed",
        yaw_rate_offset_name="--time-offset-yaw",
        yaw_rate=f"{args.yaw_rate_csv} (the yaw rate, --yaw-rate-csv)",
        yaw_rate_unit_fix="its yaw_rate_rad_s column must be in rad/s: convert it (× π/180)",
        yaw_rate_sign_fix="its yaw_rate_rad_s column must be counter-clockwise positive (a left "
        "turn > 0): negate it",
    )


def _local_frame(receiver_ecef: np.ndarray, obs) -> EnuFrame:
    """The ENU frame of the first receiver position used (a sequence folder names its own
    origin; a bare RINEX file has this one), else of the RINEX approximate position."""
    finite = np.flatnonzero(np.all(np.isfinite(receiver_ecef), axis=1))
    if finite.size:
        return EnuFrame.from_ecef(receiver_ecef[finite[0]])
    approx = obs.header.approx_position
    if approx is not None and not RECEIVER_RADIUS.outside(np.linalg.norm(approx)):
        return EnuFrame.from_ecef(approx)
    raise InputError("no receiver position (no SPP fix, no approximate position)", obs.header.path)


def run(args: argparse.Namespace) -> int:
    figure = args.figure or args.output.with_suffix(".png")
    sensor_files = (args.can, args.dbc, args.yaw_rate_csv, args.speed_csv, args.gt)
    outputs = {"output": args.output, "figure": figure}
    if args.vel is not None:
        outputs["vel"] = args.vel
    check_output_files(
        outputs,
        [args.obs, *satellite_inputs(args), *sensor_files],
    )
    speed, yaw_rate, yaw_rate_unit = _sensors(args)
    obs = read_obs(args.obs)
    truth = read_trajectory(args.gt) if args.gt else None
    part = time_span(args)
    if not part.whole:
        interval = part.resolve(obs.epoch_time, "observation epochs")
        obs, speed, yaw_rate, truth = (trim(x, interval) for x in (obs, speed, yaw_rate, truth))
    nav = satellite_states(args)
    systems, mask = args.systems, np.radians(args.elev_mask)
    if args.max_sats is None:
        gnss = gnss_velocity(obs, nav, systems, mask)
        rows, conventional = gnss.rows, gnss.velocity
    else:
        start = obs.epoch_time[0] + args.max_sats_after
        rows, conventional = emulated_canyon(obs, nav, args.max_sats, start, systems, mask)
    # auto resolved first, so that --window-s and --no-nlos-rejection change the settings
    # that run (for_rate would otherwise replace them with the robust ones)
    method = heading_method_config(args.heading_method).for_rate(obs.epoch_time)
    tight = replace(method.tight, window_s=args.window_s)
    if args.no_nlos_rejection:
        tight = replace(tight, outlier_passes=0)
    config = replace(
        method,
        calibration=args.calibration,
        tight=tight,
        fixed_gyro_bias_rad_s=None if args.gyro_bias is None else np.radians(args.gyro_bias),
        fixed_wheel_scale=args.wheel_scale,
    )
    table = heading_from_gnss(
        obs.epoch_time,
        rows,
        conventional,
        VehicleSignals(speed, yaw_rate, source=_signal_source(args, yaw_rate_unit)),
        _local_frame(rows.receiver_ecef, obs),
        config,
        args.antenna_lever_arm,
    )
    warnings = table.warnings
    if not table.tc_available.any() and not table.conv_valid.any():
        raise VoDopplerError(
            f"no heading could be computed at any epoch: nothing written ({args.output} and "
            f"{figure} left as they were)"
        )
    truth_yaw = truth.yaw_at(table.t) if truth is not None else None
    files = [
        (args.output, lambda path: write_heading_csv(path, table)),
        (figure, lambda path: heading_figure(path, table, truth_yaw, args.obs.name)),
    ]
    if args.vel is not None:
        velocity = car_checked_velocity(conventional, table)
        files.append((args.vel, lambda path: write_velocity_csv(path, velocity)))
    write_files(files)
    final = final_calibration(table)
    summary = {
        "epochs": len(table),
        "tc_available": float(table.tc_available.mean()),
        "tc_reliable": float(table.tc_reliable.mean()),
        "conv_valid": float(table.conv_valid.mean()),
        "conv_velocity_valid": float(np.mean(table.conv_velocity_valid)),
        "rejected_rows": int(table.rejected_rows.sum()),
        "epochs_with_rejection": int(np.count_nonzero(table.rejected_rows)),
        "tc_verifiable": float(table.tc_verifiable.mean()),
        "method": table.method,
        "gyro_bias_dps": final["final_gyro_bias_dps"],
        "wheel_scale": final["final_wheel_scale"],
        "calibration": None if table.calibration is None else table.calibration.to_dict(),
        "output": str(args.output),
        "figure": str(figure),
        "vel": None if args.vel is None else str(args.vel),
        "warnings": warnings,
    }
    print(json_text(summary))
    return 0
