"""``vo-doppler simulate --scenario urban-canyon``: write a complete synthetic sequence folder."""

from __future__ import annotations

import argparse
import datetime as dt
import shlex
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from rich.console import Console
from rich.table import Table

from vo_doppler.choices import values
from vo_doppler.commands.arg_types import (
    finite_float,
    frame_rate,
    int_in,
    lever_arm,
    non_negative_float,
    number_in,
    positive_float,
    positive_int,
    system_letters,
)
from vo_doppler.errors import InputError
from vo_doppler.io.output_folder import check_output_folder
from vo_doppler.model.gpstime import calendar_to_gps_seconds
from vo_doppler.sim.camera_effects import CameraEffects
from vo_doppler.sim.canyon_realism import RealismLevel, real_canyon_config
from vo_doppler.sim.urban_canyon import (
    MAX_DURATION_S,
    CityConfig,
    Scenario,
    UrbanCanyonConfig,
    simulate_urban_canyon,
    too_few_frames,
)
from vo_doppler.sim.vo_sequence import ImageFormat
from vo_doppler.vo.batch import MIN_VO_FRAMES


def _numbers(text: str, count: int, kind: Callable[[str], Any] = finite_float) -> tuple:
    """``count`` comma-separated values, each parsed by the argparse type ``kind``."""
    parts = text.split(",")
    if len(parts) != count:
        raise argparse.ArgumentTypeError(f"{text!r}: expected {count} comma-separated numbers")
    try:
        return tuple(kind(v) for v in parts)
    except (ValueError, argparse.ArgumentTypeError) as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: {exc}") from exc


def _positive_pair(text: str) -> tuple:
    return _numbers(text, 2, positive_float)


def _heights(text: str) -> tuple:
    low, high = _positive_pair(text)
    if high < low:
        raise argparse.ArgumentTypeError(f"{text!r}: expected MIN,MAX with MIN ≤ MAX")
    return low, high


def _int_pair(text: str) -> tuple:
    return _numbers(text, 2, positive_int)


def _loop(text: str) -> tuple:
    i0, j0, i1, j1 = _numbers(text, 4, int_in(0))
    return ((i0, j0), (i1, j1))


def _triple(text: str) -> tuple:
    return _numbers(text, 3)


MAX_ROAD_SPEED_KMH = 300.0
"""Upper bound of the speed options: faster than any road car (the route is laid out for
max speed × duration, so an absurd speed would exhaust the memory)."""
_road_speed = number_in(0.0, MAX_ROAD_SPEED_KMH, low_open=True, unit="km/h")
_latitude = number_in(-90.0, 90.0, unit="degrees")
_longitude = number_in(-180.0, 180.0, unit="degrees")


def _origin(text: str) -> tuple:
    lat, lon, height = _triple(text)
    try:
        return _latitude(str(lat)), _longitude(str(lon)), height
    except argparse.ArgumentTypeError as exc:
        raise argparse.ArgumentTypeError(f"{text!r}: LAT,LON,H: {exc}") from exc


SWITCHES = {
    "distortion": "lens distortion",
    "rolling-shutter": "rolling shutter (global shutter)",
    "motion-blur": "motion blur (instant exposure)",
    "sensor-noise": "shot and read noise",
    "exposure-changes": "changing light, auto exposure and vignetting",
    "traffic": "moving vehicles",
    "repetitive-facades": "window-grid facades",
    "asphalt": "low-contrast asphalt (full-contrast ground)",
}
"""Effects of the realistic camera and city that ``--no-NAME`` switches off."""


def _attr(flag: str) -> str:
    return "no_" + flag.replace("-", "_")


def _joined(values) -> str:
    return ",".join(f"{v:.10g}" if isinstance(v, float) else str(v) for v in values)


def _calib_error(args: argparse.Namespace) -> tuple[float, float, float]:
    if args.calib_error is not None:
        return tuple(args.calib_error)
    if args.clean:
        return (0.0, 0.0, 0.0)
    defaults = UrbanCanyonConfig()
    return (defaults.calib_focal_error, *defaults.calib_principal_offset_px)


def _effects(args: argparse.Namespace, defaults: CameraEffects) -> CameraEffects | None:
    """The camera effects the options ask for (None with --clean)."""
    if args.clean:
        return None
    effects = replace(
        defaults,
        distortion_error=(args.distortion_error, *defaults.distortion_error[1:]),
        readout_s=0.0 if args.no_rolling_shutter else args.readout_ms * 1e-3,
        exposure_s=0.0 if args.no_motion_blur else args.exposure_ms * 1e-3,
        noise=not args.no_sensor_noise,
    )
    if args.no_distortion:
        effects = replace(effects, distortion=(0.0,) * 5, distortion_error=(0.0,) * 5)
    if args.no_exposure_changes and effects.sensor is not None:
        sensor = replace(effects.sensor, vignetting=0.0, light_variation=0.0, exposure_rate=0.0)
        effects = replace(effects, sensor=sensor)
    return effects


def register(subparsers, summary: str) -> None:
    defaults = UrbanCanyonConfig()
    city = defaults.city
    parser = subparsers.add_parser(
        "simulate",
        help=summary,
        description="Drive a car around a closed loop through a city of tall buildings and "
        "write camera images, RINEX 3 observations + navigation, a candump CAN log + DBC, "
        "ground truth and sequence.yaml (deterministic per seed).",
    )
    parser.add_argument(
        "--scenario",
        choices=values(Scenario),
        default=Scenario.URBAN_CANYON.value,
        help="the drive",
    )
    parser.add_argument(
        "--duration",
        type=number_in(0.0, MAX_DURATION_S, low_open=True, unit="s"),
        default=defaults.duration_s,
        help=f"seconds (at most {MAX_DURATION_S:g}: the drive is held in memory, about 0.25 MB/s)",
    )
    parser.add_argument("--seed", type=int, default=0, help="random seed (same seed, same data)")
    parser.add_argument("-o", "--output", required=True, help="sequence folder to write")
    parser.add_argument(
        "--fps",
        type=frame_rate,
        default=defaults.fps,
        help=f"camera rate (Hz); over --duration at least {MIN_VO_FRAMES} frames (VO needs them)",
    )
    parser.add_argument("--size", type=_int_pair, default=defaults.image_size_px, help="W,H px")
    parser.add_argument(
        "--image-format",
        choices=values(ImageFormat),
        default=defaults.image_format.value,
        help="images",
    )
    parser.add_argument(
        "--jpeg-quality",
        type=int_in(1, 100),
        default=defaults.jpeg_quality,
        help="JPEG quality (1-100)",
    )
    parser.add_argument("--no-images", action="store_true", help="skip rendering (fast)")
    parser.add_argument(
        "--calib-error",
        type=_triple,
        default=None,
        help="written-calibration error FOCAL_FRACTION,DCX_PX,DCY_PX (default "
        f"{_joined((defaults.calib_focal_error, *defaults.calib_principal_offset_px))}; "
        "0,0,0 with --clean; 0,0,0 with --distortion-error 0 for an exact calibration)",
    )
    effects = defaults.camera_effects
    parser.add_argument(
        "--distortion-error",
        type=finite_float,
        default=effects.distortion_error[0],
        help="error of the calibrated radial coefficient k1 (true lens k1 "
        f"{effects.distortion[0]:g}, k2 {effects.distortion[1]:g}; default %(default)g)",
    )
    parser.add_argument(
        "--readout-ms",
        type=non_negative_float,
        default=effects.readout_s * 1e3,
        help="rolling-shutter readout time, first to last row (default %(default)g ms)",
    )
    parser.add_argument(
        "--exposure-ms",
        type=non_negative_float,
        default=effects.exposure_s * 1e3,
        help="exposure time, for the motion blur (default %(default)g ms)",
    )
    parser.add_argument(
        "--traffic",
        type=non_negative_float,
        default=defaults.traffic.vehicles_per_km,
        help="moving vehicles per km of lane (default %(default)g)",
    )
    for flag, what in SWITCHES.items():
        parser.add_argument(f"--no-{flag}", action="store_true", help=f"render without {what}")
    parser.add_argument(
        "--clean",
        action="store_true",
        help="the clean rendering of earlier versions: pinhole frames exactly as rendered plus "
        f"Gaussian noise ({defaults.image_noise_grey:g} grey levels), no traffic, no repetitive "
        "facades, full-contrast ground, exact calibration unless --calib-error is given",
    )
    parser.add_argument("--blocks", type=_int_pair, default=city.blocks, help="NX,NY blocks")
    parser.add_argument(
        "--block-size", type=_positive_pair, default=city.block_size_m, help="X,Y m"
    )
    parser.add_argument(
        "--street-width", type=positive_float, default=city.street_width_m, help="m"
    )
    parser.add_argument(
        "--heights",
        type=_heights,
        default=city.height_range_m,
        help="building heights MIN,MAX m",
    )
    parser.add_argument(
        "--loop",
        type=_loop,
        default=city.corner_streets,
        help="street lines I0,J0,I1,J1 of the loop's corners",
    )
    parser.add_argument(
        "--max-speed",
        type=_road_speed,
        default=defaults.max_speed_mps * 3.6,
        help=f"km/h (at most {MAX_ROAD_SPEED_KMH:g})",
    )
    parser.add_argument(
        "--initial-speed",
        type=number_in(0.0, MAX_ROAD_SPEED_KMH, unit="km/h"),
        default=0.0,
        help="km/h at the start (0: from rest)",
    )
    parser.add_argument(
        "--stops-per-lap",
        type=int_in(0),
        default=defaults.stops_per_lap,
        help="standstills per lap",
    )
    parser.add_argument(
        "--gnss-rate", type=positive_float, default=defaults.gnss.rate_hz, help="Hz"
    )
    parser.add_argument(
        "--systems", type=system_letters("GE"), default=defaults.gnss.systems, help="G, E or GE"
    )
    parser.add_argument(
        "--nlos",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="signals of blocked satellites received by single facade reflections, as in a real "
        "street canyon (--no-nlos: direct signals only)",
    )
    parser.add_argument("--no-noise", action="store_true", help="noise-free GNSS observations")
    parser.add_argument(
        "--canyon-realism",
        choices=values(RealismLevel),
        default=RealismLevel.GEOMETRIC.value,
        help="geometric: direct rays and specular facade reflections; real: the "
        "canyon measured on a u-blox M8T in Hong Kong (diffraction over the roofs, diffuse "
        "scattering whose Doppler error grows with speed and weakness, C/N0 22-44 dB-Hz, a "
        "clock drift jumping 0.17 m/s per 1-Hz epoch; replaces --nlos's specular reflections)",
    )
    parser.add_argument(
        "--wheel-scale-error",
        type=number_in(-1.0, low_open=True),
        default=defaults.can.wheel_scale_error,
        help="wheel speed scale error (fraction, 0.02: the wheels read 2 %% fast)",
    )
    parser.add_argument(
        "--yaw-bias", type=finite_float, default=defaults.can.yaw_rate_bias_dps, help="deg/s"
    )
    parser.add_argument(
        "--start",
        type=_iso_time,
        default=None,
        help="GPS start time YYYY-MM-DDTHH:MM:SS (default 2025-03-14T02:10)",
    )
    parser.add_argument("--origin", type=_origin, default=defaults.origin, help="LAT,LON,H")
    parser.add_argument(
        "--antenna-lever-arm",
        type=lever_arm((3,)),
        default=defaults.antenna_lever_arm_m,
        help="GNSS antenna X,Y,Z m in the vehicle frame (x forward, y left, z up) from the "
        "rear-axle centre on the ground",
    )
    parser.add_check(too_few_camera_frames)
    parser.set_defaults(func=run)


def too_few_camera_frames(args: argparse.Namespace) -> str | None:
    """The problem when ``--fps`` × ``--duration`` gives fewer frames than VO needs."""
    return too_few_frames(args.duration, args.fps, ("--duration", "--fps"))


def _iso_time(text: str) -> str:
    """argparse type: an ISO date and time (kept as written, for the command line)."""
    try:
        dt.datetime.fromisoformat(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(f"{text!r} is not an ISO date and time") from exc
    return text


def _start_gps(text: str | None, default: float) -> float:
    if text is None:
        return default
    when = dt.datetime.fromisoformat(text)
    seconds = when.second + when.microsecond * 1e-6
    return float(
        calendar_to_gps_seconds(when.year, when.month, when.day, when.hour, when.minute, seconds)
    )


def _command_line(args: argparse.Namespace) -> str:
    """The full command that regenerates the sequence (every option spelled out)."""
    joined = _joined
    words = ["vo-doppler", "simulate", "--scenario", args.scenario]
    words += ["--duration", f"{args.duration:g}", "--seed", str(args.seed)]
    words += ["--fps", f"{args.fps:g}", "--size", joined(args.size)]
    words += ["--image-format", args.image_format, "--jpeg-quality", str(args.jpeg_quality)]
    words += ["--calib-error", joined(_calib_error(args))]
    if args.clean:
        words.append("--clean")
    else:
        words += ["--distortion-error", f"{args.distortion_error:g}"]
        words += ["--readout-ms", f"{args.readout_ms:g}", "--exposure-ms", f"{args.exposure_ms:g}"]
        words += ["--traffic", f"{args.traffic:g}"]
        words += [f"--no-{flag}" for flag in SWITCHES if getattr(args, _attr(flag))]
    words += ["--blocks", joined(args.blocks), "--block-size", joined(args.block_size)]
    words += ["--street-width", f"{args.street_width:g}", "--heights", joined(args.heights)]
    words += ["--loop", joined([*args.loop[0], *args.loop[1]])]
    words += ["--max-speed", f"{args.max_speed:g}", "--initial-speed", f"{args.initial_speed:g}"]
    words += ["--stops-per-lap", str(args.stops_per_lap)]
    words += ["--gnss-rate", f"{args.gnss_rate:g}", "--systems", args.systems]
    words += ["--wheel-scale-error", f"{args.wheel_scale_error:g}"]
    words += ["--yaw-bias", f"{args.yaw_bias:g}", "--origin", joined(args.origin)]
    if tuple(args.antenna_lever_arm) != UrbanCanyonConfig().antenna_lever_arm_m:
        words += ["--antenna-lever-arm", joined(args.antenna_lever_arm)]
    if args.start is not None:
        words += ["--start", args.start]
    words.append("--nlos" if args.nlos else "--no-nlos")
    for flag in ("no_images", "no_noise"):
        if getattr(args, flag):
            words.append("--" + flag.replace("_", "-"))
    if args.canyon_realism != RealismLevel.GEOMETRIC:
        words += ["--canyon-realism", args.canyon_realism]
    return shlex.join([*words, "-o", str(args.output)])


def run(args: argparse.Namespace) -> int:
    check_output_folder(args.output, "simulate")
    defaults = UrbanCanyonConfig()
    gnss = replace(
        defaults.gnss,
        rate_hz=args.gnss_rate,
        systems=args.systems,
        nlos=args.nlos,
        noise=not args.no_noise,
    )
    if args.canyon_realism == RealismLevel.REAL:
        gnss = real_canyon_config(gnss)
    config = replace(
        defaults,
        duration_s=args.duration,
        seed=args.seed,
        city=CityConfig(
            blocks=args.blocks,
            block_size_m=args.block_size,
            street_width_m=args.street_width,
            height_range_m=args.heights,
            corner_streets=args.loop,
            window_facades=0
            if args.clean or args.no_repetitive_facades
            else defaults.city.window_facades,
            ground_contrast=1.0 if args.clean or args.no_asphalt else defaults.city.ground_contrast,
        ),
        max_speed_mps=args.max_speed / 3.6,
        initial_speed_mps=args.initial_speed / 3.6,
        stops_per_lap=args.stops_per_lap,
        fps=args.fps,
        image_size_px=args.size,
        image_format=args.image_format,
        jpeg_quality=args.jpeg_quality,
        render=not args.no_images,
        calib_focal_error=_calib_error(args)[0],
        calib_principal_offset_px=_calib_error(args)[1:],
        camera_effects=_effects(args, defaults.camera_effects),
        traffic=replace(
            defaults.traffic,
            vehicles_per_km=0.0 if args.clean or args.no_traffic else args.traffic,
        ),
        start_gps_s=_start_gps(args.start, defaults.start_gps_s),
        origin=args.origin,
        antenna_lever_arm_m=args.antenna_lever_arm,
        gnss=gnss,
        can=replace(
            defaults.can, wheel_scale_error=args.wheel_scale_error, yaw_rate_bias_dps=args.yaw_bias
        ),
    )
    try:
        result = simulate_urban_canyon(args.output, config, _command_line(args), progress=True)
    except ValueError as exc:
        raise InputError(str(exc)) from exc
    stats = result.stats
    table = Table(title=f"urban-canyon sequence → {args.output}")
    table.add_column("figure")
    table.add_column("value", justify="right")
    rows = [
        ("path length", f"{stats.path_length_m:.0f} m"),
        ("turns / stops", f"{stats.turns} / {stats.stops}"),
        ("max speed", f"{stats.max_speed_kmh:.1f} km/h"),
        (
            "camera frames",
            f"none rendered (--no-images; {stats.frames} times written)"
            if args.no_images
            else str(stats.frames),
        ),
        ("GNSS epochs", str(stats.epochs)),
        (
            "satellites min / median / max",
            f"{stats.visible_min} / {stats.visible_median:g} / {stats.visible_max}",
        ),
        ("epochs with < 4 satellites", f"{100 * stats.fraction_epochs_lt4:.1f} %"),
        ("longest stretch < 4", f"{stats.longest_lt4_s:.1f} s"),
        ("CAN frames", str(stats.can_frames)),
        ("seconds", ", ".join(f"{k} {v:.1f}" for k, v in stats.seconds.items())),
    ]
    for name, value in rows:
        table.add_row(name, value)
    Console().print(table)
    return 0
