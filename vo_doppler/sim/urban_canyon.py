"""Urban-canyon multi-sensor simulator: a car drives a closed loop through a city of tall
buildings; camera, GNSS receiver and CAN bus record it in the formats real sensors write.

Everything is deterministic per seed. The world is the city's ENU frame (x east, y north,
z up, ground at z = 0), anchored at a geodetic origin (default in Shinjuku, Tokyo). Vehicle
frame: x forward, y left, z up, origin on the ground at the rear-axle centre. Times are GPS
seconds; each sensor writes its own clock and ``sequence.yaml`` gives the offsets.

Sequence folder (``simulate_urban_canyon(out_dir, config)``)::

    sequence.yaml            manifest (schema below)
    image_0/000000.png …     grey frames (``camera.fps``, default 15 Hz; .png or .jpg)
    times.txt                one frame time per line, camera clock (s, first frame at 0)
    calib.yaml               camera calibration (write_camera_yaml: intrinsics + camera→vehicle)
                             of the rectified frames: the calibrated pinhole, off the truth by
                             ``calib_focal_error`` / ``calib_principal_offset_px`` (and, with
                             ``camera_effects``, the distortion error the frames were rectified
                             with); true values in ``truth.camera``
    gnss/rover.obs           RINEX 3.04 observations, 20 Hz: C1C D1C S1C, GPS + Galileo
    gnss/brdc.nav            RINEX 3.04 navigation (GPS + Galileo Keplerian, Klobuchar)
    gnss/visibility.csv      truth per epoch: gps_time_s,n_above_mask,n_direct,n_reflected
    can/vehicle.log          candump -l log (Unix time), frames every 12 ms
    can/vehicle.dbc          DBC of the log
    ground_truth.tum         vehicle poses (ENU world, GPS time), 100 Hz

``sequence.yaml`` keys (paths relative to the folder; ``gps = sensor time + time_offset_s``)::

    format: vo-doppler-sequence/1
    name, scenario, seed, duration_s, command
    origin: {lat_deg, lon_deg, height_m}          ENU origin (WGS-84, ellipsoidal height)
    start_gps_s                                   GPS time of the drive start
    camera: {images, image_format, times, calib, fps, width, height, time_offset_s}
    gnss: {obs, nav: [..], rate_hz, systems, time_offset_s, antenna_lever_arm_m (x, y, z m),
           doppler_sign: "range_rate = -wavelength * doppler", visibility}
    can: {log, dbc, period_s, time_offset_s, yaw_rate, yaw_rate_sign, wheel_speed,
          forward_acceleration}
         yaw_rate / wheel_speed / forward_acceleration are MESSAGE.SIGNAL names
    ground_truth: {trajectory, frame, rate_hz}
    truth: generating sensor errors (wheel_scale_error, yaw_rate_bias_dps, …) — evaluation only
    city: {blocks, block_size_m, street_width_m, height_range_m, corner_streets}
    stats: path length, turns, stops, satellite availability (``SimulationStats`` without
           the timings, so the manifest is identical for identical inputs)

The camera images are rendered by ``vo_doppler.sim.render`` from the city's textured ground
and facades (``vo_doppler.sim.scene``), through the realistic camera of
``vo_doppler.sim.camera_effects`` (lens, rolling shutter, motion blur, sensor) with moving
vehicles (``vo_doppler.sim.traffic``) unless ``camera_effects`` is None; the vehicle follows
``loop_route``/``drive`` of ``vo_doppler.sim.vo_sequence``. GNSS: ``gnss_observations``
(model, sign convention) with the ``constellation``; CAN: ``can_bus``.
"""

from __future__ import annotations

import logging
import shutil
import time
from collections.abc import Iterator
from dataclasses import asdict, dataclass, field, replace
from enum import StrEnum
from pathlib import Path

import cv2
import numpy as np
import yaml
from rich.progress import track

from vo_doppler.choices import check_fields
from vo_doppler.geo import EnuFrame
from vo_doppler.io.calibration import write_camera_yaml
from vo_doppler.io.output_folder import open_output_folder
from vo_doppler.io.rinex_write import write_nav, write_obs
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.camera import Camera
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.sim.camera_effects import CameraEffects, EffectsCamera
from vo_doppler.sim.can_bus import (
    DBC_PATH,
    FORWARD_ACCELERATION_SIGNAL,
    WHEEL_SPEED_SIGNALS,
    YAW_RATE_SIGNAL,
    CanSimConfig,
    CanSimulation,
    gps_to_unix_offset,
    simulate_can,
    write_candump,
)
from vo_doppler.sim.constellation import (
    KLOBUCHAR,
    REFERENCE_EPOCH,
    broadcast_ephemerides,
    navigation_from_records,
)
from vo_doppler.sim.gnss_observations import (
    Boxes,
    GnssSimConfig,
    GnssSimulation,
    simulate_gnss,
)
from vo_doppler.sim.scene import city_scene
from vo_doppler.sim.traffic import TrafficConfig, add_traffic
from vo_doppler.sim.vo_sequence import (
    ImageFormat,
    VehicleMotion,
    VoPlan,
    drive,
    loop_route,
    remove_stale_frames,
    render_frames,
    synthetic_camera,
)
from vo_doppler.vo.batch import MIN_VO_FRAMES

log = logging.getLogger(__name__)


class Scenario(StrEnum):
    """``simulate --scenario``: the drives the simulator knows."""

    URBAN_CANYON = "urban-canyon"
    """A closed loop through a city of tall buildings (module docstring)."""


DEFAULT_START_GPS_S = REFERENCE_EPOCH + 2 * 3600.0 + 600.0
"""2025-03-14 02:10:00 GPST."""
SHINJUKU = (35.69380, 139.70340, 77.0)
"""Default ENU origin: latitude, longitude (deg), ellipsoidal height (m)."""
GROUND_TRUTH_RATE_HZ = 100.0
TRAFFIC_STREAM = 0x7AFF1C
"""Second seed word of the traffic's random stream (GNSS and CAN streams stay as they were)."""
CAMERA_START_DELAY_S = 0.02
"""The camera's first frame comes this long after the drive starts (s)."""


def camera_frame_count(duration_s: float, fps: float) -> int:
    """Frames the camera takes in a drive of ``duration_s`` at ``fps`` (its first frame
    ``CAMERA_START_DELAY_S`` into the drive, its last at or before the end)."""
    return int(np.floor((duration_s - CAMERA_START_DELAY_S) * fps + 1e-9)) + 1


def too_few_frames(
    duration_s: float, fps: float, names: tuple[str, str] = ("duration_s", "fps")
) -> str | None:
    """The problem when a drive of ``duration_s`` at ``fps`` gives fewer camera frames than a
    VO trajectory needs (:data:`~vo_doppler.vo.batch.MIN_VO_FRAMES`), naming the two settings
    by ``names`` and the least of each that would do, else None."""
    frames = camera_frame_count(duration_s, fps)
    if frames >= MIN_VO_FRAMES:
        return None
    duration_name, fps_name = names
    needed = [f"{duration_name} ≥ {_round_up((MIN_VO_FRAMES - 1) / fps + CAMERA_START_DELAY_S)} s"]
    if duration_s > CAMERA_START_DELAY_S:
        least_fps = (MIN_VO_FRAMES - 1) / (duration_s - CAMERA_START_DELAY_S)
        needed.append(f"{fps_name} ≥ {_round_up(least_fps)} Hz")
    return (
        f"{fps_name} {fps:g} with {duration_name} {duration_s:g} gives {max(frames, 0)} camera "
        f"frame{'' if frames == 1 else 's'} (the first {CAMERA_START_DELAY_S:g} s into the "
        f"drive), and visual odometry needs at least {MIN_VO_FRAMES}: give "
        f"{' or '.join(needed)}"
    )


def _round_up(value: float, digits: int = 5) -> str:
    """``value`` rounded up to ``digits`` significant digits (a bound that still holds)."""
    quantum = 10.0 ** (np.floor(np.log10(value)) - digits + 1)
    return f"{np.ceil(value / quantum - 1e-9) * quantum:.{digits}g}"


MAX_DURATION_S = 3600.0
"""Longest drive simulated (s). The whole drive is held in memory until written, and its peak
grows with the duration, so that an hour already needs over a gigabyte (docs/benchmarks.md,
"Memory", the simulator's peaks); a longer one would still grow without bound before writing
anything."""


@dataclass(frozen=True)
class CityConfig:
    """Street grid and buildings (``vo_doppler.sim.scene.city_scene``)."""

    blocks: tuple[int, int] = (5, 4)
    block_size_m: tuple[float, float] = (45.0, 45.0)
    street_width_m: float = 20.0
    height_range_m: tuple[float, float] = (20.0, 60.0)
    buildings_per_side: tuple[int, int] = (1, 3)
    corner_streets: tuple[tuple[int, int], tuple[int, int]] = ((1, 1), (4, 3))
    corner_radius_m: float = 9.0
    window_facades: int = 4
    """Repetitive window-grid facade tiles added to the six corner-rich ones (0: none)."""
    ground_contrast: float = 0.35
    """Contrast of the ground texture: worn asphalt, a third of the facades' (1: the
    full-contrast ground of earlier versions)."""


@dataclass(frozen=True)
class UrbanCanyonConfig:
    """Everything a simulation depends on (besides the seed)."""

    duration_s: float = 120.0
    seed: int = 0
    city: CityConfig = field(default_factory=CityConfig)
    max_speed_mps: float = 13.5
    max_lateral_accel_mps2: float = 2.5
    initial_speed_mps: float = 0.0
    stops_per_lap: int = 1
    stop_duration_s: float = 4.0
    fps: float = 15.0
    image_size_px: tuple[int, int] = (640, 360)
    image_format: ImageFormat = ImageFormat.PNG
    jpeg_quality: int = 90
    image_noise_grey: float = 2.0
    """Gaussian pixel noise (grey levels) of the clean rendering (``camera_effects`` None)."""
    calib_focal_error: float = -0.005
    calib_principal_offset_px: tuple[float, float] = (2.0, -1.5)
    camera_effects: CameraEffects | None = field(default_factory=CameraEffects)
    """Lens, rolling shutter and sensor (None: the clean pinhole rendering of earlier versions,
    frames exactly as rendered plus ``image_noise_grey``)."""
    traffic: TrafficConfig = field(default_factory=TrafficConfig)
    render: bool = True
    start_gps_s: float = DEFAULT_START_GPS_S
    origin: tuple[float, float, float] = SHINJUKU
    antenna_lever_arm_m: tuple[float, float, float] = (0.0, 0.0, 1.6)
    """GNSS antenna in the vehicle frame (x forward, y left, z up) from the rear-axle centre."""
    leap_seconds: int = 18
    gnss: GnssSimConfig = field(default_factory=GnssSimConfig)
    can: CanSimConfig = field(default_factory=CanSimConfig)

    def __post_init__(self) -> None:
        check_fields(self, image_format=ImageFormat)


@dataclass(frozen=True)
class SimulationStats:
    """Measured figures of a generated sequence."""

    path_length_m: float
    turns: int
    stops: int
    max_speed_kmh: float
    epochs: int
    visible_min: int
    visible_median: float
    visible_max: int
    fraction_epochs_lt4: float
    fraction_epochs_lt4_moving: float
    longest_lt4_s: float
    reflected_fraction: float
    frames: int
    can_frames: int
    seconds: dict[str, float]


@dataclass
class UrbanCanyonSimulation:
    """In-memory result: configuration, ENU frame, the vehicle (``vehicle(t_gps)`` →
    :class:`VehicleMotion`), GNSS and CAN output, stats and the written files."""

    config: UrbanCanyonConfig
    frame: EnuFrame
    vehicle: VehicleDrive
    gnss: GnssSimulation
    can: CanSimulation
    stats: SimulationStats
    files: dict[str, str]


class VehicleDrive:
    """The vehicle on its route, sampled at any GPS times (``drive`` of the VO sequence)."""

    def __init__(self, config: UrbanCanyonConfig, layout):
        city = config.city
        one_lap = loop_route(layout, city.corner_streets, corner_radius_m=city.corner_radius_m)
        laps = int(np.ceil(config.max_speed_mps * config.duration_s / one_lap.length)) + 1
        self.route = loop_route(
            layout, city.corner_streets, corner_radius_m=city.corner_radius_m, laps=laps
        )
        n_stops = config.stops_per_lap * laps
        self.stops_m = tuple(one_lap.length * (np.arange(n_stops) + 0.55) / config.stops_per_lap)
        self.start = config.start_gps_s
        self.options = {
            "max_speed": config.max_speed_mps,
            "max_lateral_accel": config.max_lateral_accel_mps2,
            "initial_speed": config.initial_speed_mps,
            "stops_m": self.stops_m,
            "stop_duration_s": config.stop_duration_s,
        }

    def __call__(self, t_gps: np.ndarray) -> VehicleMotion:
        elapsed = np.maximum(np.asarray(t_gps, dtype=float) - self.start, 0.0)
        motion = drive(self.route, elapsed, **self.options)
        motion.t = np.asarray(t_gps, dtype=float)
        return motion


def build_city(config: UrbanCanyonConfig):
    """The city scene of a configuration (``vo_doppler.sim.scene.city_scene``), untextured when
    it renders no image."""
    city = config.city
    return city_scene(
        config.seed,
        blocks_x=city.blocks[0],
        blocks_y=city.blocks[1],
        block_size=city.block_size_m,
        street_width=city.street_width_m,
        height_range=city.height_range_m,
        buildings_per_side=city.buildings_per_side,
        window_facades=city.window_facades,
        ground_contrast=city.ground_contrast,
        textured=config.render,
    )


def simulate_urban_canyon(
    out_dir: str | Path, config: UrbanCanyonConfig, command: str = "", progress: bool = False
) -> UrbanCanyonSimulation:
    """Generate a complete sequence folder (layout in the module docstring); a ValueError,
    before anything is written, when the drive gives too few camera frames for VO."""
    problem = too_few_frames(config.duration_s, config.fps)
    if problem:
        raise ValueError(problem)
    out = open_output_folder(out_dir, "simulate")
    for sub in ("gnss", "can"):
        (out / sub).mkdir(parents=True, exist_ok=True)
    seconds: dict[str, float] = {}
    clock = time.perf_counter()
    rng = np.random.default_rng(config.seed)
    gnss_rng, can_rng = (np.random.default_rng(s) for s in rng.integers(0, 2**63, 2))
    scene = build_city(config)
    vehicle = VehicleDrive(config, scene.layout)
    frame = EnuFrame(np.radians(config.origin[0]), np.radians(config.origin[1]), config.origin[2])
    t0, t1 = config.start_gps_s, config.start_gps_s + config.duration_s
    seconds["city_and_route"] = time.perf_counter() - clock

    clock = time.perf_counter()
    records = broadcast_ephemerides(t0, t1, config.gnss.systems)
    nav = navigation_from_records(records)
    write_nav(out / "gnss" / "brdc.nav", records, config.leap_seconds, KLOBUCHAR)

    def antenna(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return antenna_motion(vehicle(t), config.antenna_lever_arm_m)

    n_epochs = int(np.floor(config.duration_s * config.gnss.rate_hz + 1e-9)) + 1
    epoch_time = t0 + np.arange(n_epochs) / config.gnss.rate_hz
    gnss = simulate_gnss(
        nav,
        frame,
        epoch_time,
        antenna,
        Boxes.from_buildings(scene.buildings),
        config.gnss,
        gnss_rng,
    )
    start_ecef = frame.enu_to_ecef(antenna(np.array([t0]))[0][0])
    write_obs(
        out / "gnss" / "rover.obs",
        gnss.obs_epochs(),
        start_ecef,
        1.0 / config.gnss.rate_hz,
        marker_name=f"URBAN_CANYON_{config.seed}",
        antenna_height_m=config.antenna_lever_arm_m[2],
    )
    np.savetxt(
        out / "gnss" / "visibility.csv",
        np.column_stack([epoch_time, gnss.n_above_mask, gnss.n_direct, gnss.n_reflected]),
        fmt=["%.3f", "%d", "%d", "%d"],
        delimiter=",",
        header="gps_time_s,n_above_mask,n_direct,n_reflected",
        comments="",
    )
    seconds["gnss"] = time.perf_counter() - clock

    clock = time.perf_counter()
    can = simulate_can(vehicle, t0, t1, config.can, can_rng, config.leap_seconds)
    write_candump(out / "can" / "vehicle.log", can)
    shutil.copyfile(DBC_PATH, out / "can" / "vehicle.dbc")
    seconds["can"] = time.perf_counter() - clock

    clock = time.perf_counter()
    t_truth = t0 + np.arange(int(np.floor(config.duration_s * GROUND_TRUTH_RATE_HZ)) + 1) / (
        GROUND_TRUTH_RATE_HZ
    )
    truth = vehicle(t_truth)
    write_tum(out / "ground_truth.tum", Trajectory.from_matrices(t_truth, truth.T_world_vehicle))
    camera = synthetic_camera(*config.image_size_px)
    n_frames = camera_frame_count(config.duration_s, config.fps)
    camera_clock = np.arange(n_frames) / config.fps
    camera_offset = t0 + CAMERA_START_DELAY_S
    np.savetxt(out / "times.txt", camera_clock, fmt="%.6f")
    write_camera_yaml(out / "calib.yaml", written_camera(camera, config))
    if config.render:
        _render(out, config, scene, camera, vehicle, camera_clock + camera_offset, progress)
    seconds["camera"] = time.perf_counter() - clock

    stats = _stats(config, truth, gnss, n_frames, len(can.lines), seconds)
    files = _write_manifest(out, config, command, camera, camera_offset, stats)
    log.info("wrote %s in %.1f s", out, sum(seconds.values()))
    return UrbanCanyonSimulation(config, frame, vehicle, gnss, can, stats, files)


def antenna_motion(
    motion: VehicleMotion, lever_arm_m: tuple[float, float, float]
) -> tuple[np.ndarray, np.ndarray]:
    """ENU position and velocity (N, 3) of an antenna at ``lever_arm_m`` (vehicle frame) on the
    vehicle: p = p_v + R(ψ)·r and v = v_v + ω × r, ω = (0, 0, ψ̇) (the vehicle stays level), so
    in the vehicle frame the antenna moves at (s − ψ̇·r_y, ψ̇·r_x, 0)."""
    rx, ry, rz = lever_arm_m
    cos_yaw, sin_yaw = np.cos(motion.yaw), np.sin(motion.yaw)
    position = np.column_stack(
        [
            motion.xy[:, 0] + cos_yaw * rx - sin_yaw * ry,
            motion.xy[:, 1] + sin_yaw * rx + cos_yaw * ry,
            np.full(len(motion.t), rz),
        ]
    )
    along = motion.speed - motion.yaw_rate * ry
    across = motion.yaw_rate * rx
    velocity = np.column_stack(
        [
            cos_yaw * along - sin_yaw * across,
            sin_yaw * along + cos_yaw * across,
            np.zeros(len(motion.t)),
        ]
    )
    return position, velocity


def written_camera(camera: Camera, config: UrbanCanyonConfig) -> Camera:
    """The calibration as written to ``calib.yaml``: the rendering camera with the configured
    calibration error (focal lengths × (1 + error), principal point shifted), as a real
    calibration is never exact; ``sequence.yaml`` keeps the true values under ``truth``."""
    dx, dy = config.calib_principal_offset_px
    scale = 1.0 + config.calib_focal_error
    return replace(
        camera, fx=camera.fx * scale, fy=camera.fy * scale, cx=camera.cx + dx, cy=camera.cy + dy
    )


def camera_frames(config, scene, camera, vehicle: VehicleDrive, times: np.ndarray) -> Iterator:
    """The camera frames at GPS ``times``: clean renders plus Gaussian noise, or frames through
    :class:`EffectsCamera` with the scene's traffic (vehicle clock: seconds since the start)."""
    if config.camera_effects is None:
        motion = vehicle(times)
        T_world_camera = motion.T_world_vehicle @ camera.T_vehicle_camera
        plan = VoPlan(
            scene, camera, times, motion, T_world_camera, config.image_noise_grey, config.seed
        )
        return render_frames(plan)
    ego = vehicle(times)
    vehicles = add_traffic(
        scene,
        config.traffic,
        np.random.default_rng([config.seed, TRAFFIC_STREAM]),
        times - config.start_gps_s,
        ego.xy,
    )
    effects = EffectsCamera(
        scene,
        camera,
        written_camera(camera, config),
        config.camera_effects,
        times,
        config.seed,
        vehicles,
    )
    band_times = effects.band_times(times)
    band_motion = vehicle(band_times.ravel())
    band_poses = (band_motion.T_world_vehicle @ camera.T_vehicle_camera).reshape(
        *band_times.shape, 4, 4
    )
    elapsed = band_times - config.start_gps_s
    return (effects.frame(k, band_poses[k], elapsed[k]) for k in range(len(times)))


def _render(out: Path, config, scene, camera, vehicle, times: np.ndarray, progress: bool) -> None:
    image_dir = out / "image_0"
    image_dir.mkdir(exist_ok=True)
    frames = camera_frames(config, scene, camera, vehicle, times)
    if progress:
        frames = track(frames, total=len(times), description="rendering")
    suffix = f".{config.image_format}"
    params = [cv2.IMWRITE_JPEG_QUALITY, config.jpeg_quality] if suffix == ".jpg" else []
    names = set()
    for k, image in enumerate(frames):
        path = image_dir / f"{k:06d}{suffix}"
        if not cv2.imwrite(str(path), image, params):
            raise OSError(f"cannot write {path}")
        names.add(path.name)
    remove_stale_frames(image_dir, names)


def _runs(flags: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Start indices and lengths of the runs of True in a boolean array."""
    padded = np.concatenate([[0], flags.astype(np.int8), [0]])
    edges = np.flatnonzero(np.diff(padded))
    return edges[::2], edges[1::2] - edges[::2]


def _stats(config, truth: VehicleMotion, gnss: GnssSimulation, frames, can_frames, seconds):
    step = np.hypot(*np.diff(truth.xy, axis=0).T)
    yaw_change = abs(float(truth.yaw[-1] - truth.yaw[0]))
    moving = truth.speed > 0.1
    stand_start, stand_length = _runs(~moving)
    visible = gnss.n_visible
    low = visible < 4
    epoch_moving = np.interp(gnss.epoch_time, truth.t, moving.astype(float)) > 0.5
    _, runs = _runs(low)
    return SimulationStats(
        path_length_m=float(step.sum()),
        turns=int(np.floor(yaw_change / (np.pi / 2) + 0.25)),
        stops=int(np.sum((stand_start > 0) & (stand_length >= GROUND_TRUTH_RATE_HZ))),
        max_speed_kmh=float(truth.speed.max() * 3.6),
        epochs=len(visible),
        visible_min=int(visible.min()),
        visible_median=float(np.median(visible)),
        visible_max=int(visible.max()),
        fraction_epochs_lt4=float(low.mean()),
        fraction_epochs_lt4_moving=float(low[epoch_moving].mean()) if epoch_moving.any() else 0.0,
        longest_lt4_s=float(runs.max() / config.gnss.rate_hz) if runs.size else 0.0,
        reflected_fraction=float(gnss.reflected.mean()) if gnss.reflected.size else 0.0,
        frames=frames,
        can_frames=can_frames,
        seconds={k: round(v, 2) for k, v in seconds.items()},
    )


def _write_manifest(out: Path, config, command, camera, camera_offset, stats) -> dict[str, str]:
    suffix = config.image_format.value
    files = {
        "images": "image_0",
        "times": "times.txt",
        "calib": "calib.yaml",
        "obs": "gnss/rover.obs",
        "nav": "gnss/brdc.nav",
        "visibility": "gnss/visibility.csv",
        "can_log": "can/vehicle.log",
        "dbc": "can/vehicle.dbc",
        "ground_truth": "ground_truth.tum",
    }
    camera_section = {
        "images": files["images"],
        "image_format": suffix,
        "times": files["times"],
        "calib": files["calib"],
        "fps": config.fps,
        "width": config.image_size_px[0],
        "height": config.image_size_px[1],
        "time_offset_s": camera_offset,
    }
    city = config.city
    manifest = {
        "format": "vo-doppler-sequence/1",
        "name": out.name,
        "scenario": Scenario.URBAN_CANYON.value,
        "seed": config.seed,
        "duration_s": config.duration_s,
        "command": command,
        "origin": dict(zip(("lat_deg", "lon_deg", "height_m"), config.origin, strict=True)),
        "start_gps_s": config.start_gps_s,
        **({"camera": camera_section} if config.render else {}),
        "gnss": {
            "obs": files["obs"],
            "nav": [files["nav"]],
            "rate_hz": config.gnss.rate_hz,
            "systems": config.gnss.systems,
            "time_offset_s": 0.0,
            "antenna_lever_arm_m": [float(v) for v in config.antenna_lever_arm_m],
            "doppler_sign": "range_rate = -wavelength * doppler",
            "visibility": files["visibility"],
        },
        "can": {
            "log": files["can_log"],
            "dbc": files["dbc"],
            "period_s": config.can.period_s,
            "time_offset_s": -gps_to_unix_offset(config.leap_seconds),
            "yaw_rate": YAW_RATE_SIGNAL,
            "yaw_rate_sign": 1,
            "wheel_speed": WHEEL_SPEED_SIGNALS,
            "forward_acceleration": FORWARD_ACCELERATION_SIGNAL,
        },
        "ground_truth": {
            "trajectory": files["ground_truth"],
            "frame": "vehicle poses in the ENU world (x forward, y left, z up; rear-axle centre "
            "on the ground)",
            "rate_hz": GROUND_TRUTH_RATE_HZ,
        },
        "truth": {
            "camera": {
                "fx": camera.fx,
                "fy": camera.fy,
                "cx": camera.cx,
                "cy": camera.cy,
                "focal_error": config.calib_focal_error,
                "principal_offset_px": list(config.calib_principal_offset_px),
                "image_noise_grey_levels": config.image_noise_grey,
                "effects": None
                if config.camera_effects is None
                else _plain(asdict(config.camera_effects)),
                "calibration_written": "rectified pinhole: the frames are resampled from the "
                "distorted raw frames with the calibrated (wrong) intrinsics and distortion"
                if config.camera_effects is not None
                else "the rendering pinhole with the calibration error",
            },
            "traffic": _plain(asdict(config.traffic)) if config.camera_effects else None,
            "wheel_scale_error": config.can.wheel_scale_error,
            "yaw_rate_bias_dps": config.can.yaw_rate_bias_dps,
            "yaw_bias_walk_dps_per_sqrt_s": config.can.yaw_bias_walk_dps_per_sqrt_s,
            "yaw_rate_noise_dps": config.can.yaw_rate_noise_dps,
            "long_accel_bias_mps2": config.can.long_accel_bias_mps2,
            "long_accel_noise_mps2": config.can.long_accel_noise_mps2,
            "gnss": _gnss_truth(config.gnss),
        },
        "city": {
            "blocks": list(city.blocks),
            "block_size_m": list(city.block_size_m),
            "street_width_m": city.street_width_m,
            "height_range_m": list(city.height_range_m),
            "corner_streets": [list(p) for p in city.corner_streets],
            "window_facades": city.window_facades,
            "ground_contrast": city.ground_contrast,
        },
        "stats": _plain({k: v for k, v in asdict(stats).items() if k != "seconds"}),
    }
    with open(out / "sequence.yaml", "w") as stream:
        yaml.safe_dump(manifest, stream, sort_keys=False)
    return files


def _gnss_truth(gnss: GnssSimConfig) -> dict:
    """The GNSS settings for the manifest's ``truth`` (``canyon`` only for the real canyon, so
    the geometric canyon's manifest is what it was before the option existed)."""
    settings = _plain(asdict(gnss))
    if gnss.canyon is None:
        del settings["canyon"]
    return settings


def _plain(value):
    """numpy scalars and tuples → plain YAML types."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value
