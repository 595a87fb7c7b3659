"""Synthetic monocular VO sequences: a car driving a loop through the synthetic city.

The route is a closed loop along street centre lines (right-hand lane), straight stretches
joined by circular quarter turns; the speed profile respects a top speed, a lateral
acceleration limit in turns, longitudinal acceleration/braking limits and optional stops. The
vehicle frame (x forward, y left, z up) sits on the ground; the camera is mounted by the
camera → vehicle extrinsic of the calibration (default: forward-looking, 1.5 m above ground).

Files written by :func:`generate_vo_sequence` (``out_dir``):
``image_0/000000.png …`` grey frames (or ``.jpg``); ``times.txt`` (one time in seconds per line);
``calib.yaml`` (camera YAML, :func:`~vo_doppler.io.calibration.write_camera_yaml`);
``ground_truth_camera.kitti`` and
``ground_truth_camera.tum`` (camera poses in the frame of the first camera, OpenCV axes — the
convention of the VO output); ``ground_truth.tum`` (vehicle poses in the ENU world frame of the
city); ``speed.csv`` (``t,speed_mps`` at the frame times).
"""

from __future__ import annotations

import argparse
import logging
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path

import cv2
import numpy as np
from rich.progress import track

from vo_doppler.choices import checked, values
from vo_doppler.io.calibration import write_camera_yaml
from vo_doppler.io.trajectory import write_kitti, write_tum
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD, Camera
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.sim.render import Renderer
from vo_doppler.sim.scene import CityLayout, Scene, city_scene

log = logging.getLogger(__name__)

CAMERA_HEIGHT_M = 1.5


class ImageFormat(StrEnum):
    """The image files a simulation writes (also their suffix)."""

    PNG = "png"
    """Lossless."""
    JPG = "jpg"
    """Smaller; its quality is the writer's setting."""


def synthetic_camera(width: int = 640, height: int = 360) -> Camera:
    """The synthetic pinhole camera: 77° horizontal field of view (fx = fy = 0.625·width),
    principal point at the image centre, no distortion, forward-looking 1.5 m above the
    vehicle origin on the ground."""
    focal = 0.625 * width
    extrinsic = CAMERA_TO_VEHICLE_FORWARD.copy()
    extrinsic[2, 3] = CAMERA_HEIGHT_M
    return Camera(
        focal, focal, (width - 1) / 2.0, (height - 1) / 2.0, width, height, np.zeros(5), extrinsic
    )


@dataclass(frozen=True)
class _Segment:
    s0: float
    length: float
    curvature: float
    x0: float
    y0: float
    yaw0: float


@dataclass
class Route:
    """A planar path of straight and circular segments, evaluated exactly at any arc length."""

    segments: list[_Segment]

    @property
    def length(self) -> float:
        last = self.segments[-1]
        return last.s0 + last.length

    @classmethod
    def from_pieces(
        cls, start: tuple[float, float, float], pieces: Sequence[tuple[float, float]]
    ) -> Route:
        """Route from a start (x, y, yaw) and pieces (length m, curvature 1/m; > 0 turns left)."""
        segments = []
        x, y, yaw = start
        s = 0.0
        for length, curvature in pieces:
            segment = _Segment(s, length, curvature, x, y, yaw)
            segments.append(segment)
            (x, y), yaw, _ = _evaluate(segment, np.array([s + length]))
            x, y, yaw = float(x[0]), float(y[0]), float(yaw[0])
            s += length
        return cls(segments)

    def at(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions (N, 2), yaw (N,) (CCW from east, unwrapped) and curvature (N,) at arc
        lengths s (clipped to the route)."""
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        starts = np.array([seg.s0 for seg in self.segments])
        which = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(self.segments) - 1)
        xy = np.zeros((len(s), 2))
        yaw = np.zeros(len(s))
        curvature = np.zeros(len(s))
        for k, segment in enumerate(self.segments):
            sel = which == k
            if np.any(sel):
                (xs, ys), yaw[sel], curvature[sel] = _evaluate(segment, s[sel])
                xy[sel, 0], xy[sel, 1] = xs, ys
        return xy, yaw, curvature


def _evaluate(segment: _Segment, s: np.ndarray):
    ds = s - segment.s0
    k = segment.curvature
    yaw = segment.yaw0 + k * ds
    if k == 0.0:
        x = segment.x0 + ds * np.cos(segment.yaw0)
        y = segment.y0 + ds * np.sin(segment.yaw0)
    else:
        x = segment.x0 + (np.sin(yaw) - np.sin(segment.yaw0)) / k
        y = segment.y0 - (np.cos(yaw) - np.cos(segment.yaw0)) / k
    return (x, y), yaw, np.full(len(s), k)


def loop_route(
    layout: CityLayout,
    corner_streets: tuple[tuple[int, int], tuple[int, int]] = ((1, 1), (3, 2)),
    lane_offset_m: float | None = None,
    corner_radius_m: float = 10.0,
    laps: int = 1,
) -> Route:
    """Counter-clockwise loop around the blocks between street lines ``corner_streets`` =
    ((i0, j0), (i1, j1)), driving in the right-hand lane (``lane_offset_m`` outward of the
    centre line, default a quarter of the street width). Starts halfway along the southern
    street heading east; every corner is a left quarter turn of ``corner_radius_m``."""
    (i0, j0), (i1, j1) = corner_streets
    if not (0 <= i0 < i1 <= layout.blocks_x and 0 <= j0 < j1 <= layout.blocks_y):
        raise ValueError(
            f"loop streets {corner_streets} outside the {layout.blocks_x}×{layout.blocks_y} city"
        )
    offset = layout.street_width / 4.0 if lane_offset_m is None else lane_offset_m
    px, py = layout.pitch
    width = (i1 - i0) * px + 2 * offset
    height = (j1 - j0) * py + 2 * offset
    r = corner_radius_m
    if min(width, height) <= 2 * r:
        raise ValueError("corner radius too large for the loop")
    turn = (np.pi / 2 * r, 1.0 / r)
    north, west = (height - 2 * r, 0.0), (width - 2 * r, 0.0)
    lap = [north, turn, west, turn, north, turn, west, turn]
    pieces = [(width / 2 - r, 0.0), turn, *(lap * laps)[:-2], (width / 2 - r, 0.0)]
    start = ((i0 + i1) / 2 * px, j0 * py - offset, 0.0)
    return Route.from_pieces(start, pieces)


@dataclass
class VehicleMotion:
    """Vehicle state at times t: position (N, 2) on the ground, yaw (CCW from east), speed and
    yaw rate (curvature × speed)."""

    t: np.ndarray
    xy: np.ndarray
    yaw: np.ndarray
    speed: np.ndarray
    yaw_rate: np.ndarray

    @property
    def T_world_vehicle(self) -> np.ndarray:
        """Vehicle → world poses (N, 4, 4), vehicle origin on the ground."""
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        T = np.tile(np.eye(4), (len(self.t), 1, 1))
        T[:, 0, 0], T[:, 0, 1], T[:, 1, 0], T[:, 1, 1] = c, -s, s, c
        T[:, :2, 3] = self.xy
        return T


def drive(
    route: Route,
    times: np.ndarray,
    max_speed: float = 12.0,
    max_lateral_accel: float = 2.0,
    max_accel: float = 1.5,
    max_decel: float = 2.5,
    initial_speed: float = 8.0,
    stops_m: Sequence[float] = (),
    stop_duration_s: float = 3.0,
    step_m: float = 0.05,
) -> VehicleMotion:
    """Sample the vehicle along ``route`` at ``times`` (seconds from the start of the drive).

    Speed limit v(s) = min(max_speed, √(a_lat/|κ(s)|)), zero at each stop; a forward pass
    limits acceleration (v² grows by ≤ 2·a·ds) and a backward pass braking; time follows from
    dt = 2 ds / (v_i + v_{i+1}), plus the dwell at each stop. Raises ValueError if the route
    ends before the last time.
    """
    s = np.arange(0.0, route.length + step_m, step_m)
    _, _, curvature = route.at(s)
    limit = np.minimum(max_speed, np.sqrt(max_lateral_accel / np.maximum(np.abs(curvature), 1e-9)))
    stop_index = sorted({round(stop / step_m) for stop in stops_m if 0 < stop < route.length})
    # A step's limit binds both of its ends, so interpolated speeds respect it too.
    limit[1:] = np.minimum(limit[1:], limit[:-1].copy())
    limit[:-1] = np.minimum(limit[:-1], limit[1:].copy())
    limit[stop_index] = 0.0
    # The two passes are recurrences, run on Python floats (the same IEEE operations as on
    # NumPy scalars, ten times faster).
    speeds = [min(initial_speed, float(limit[0]))]
    for bound in limit[1:].tolist():
        speeds.append(min(bound, math.sqrt(speeds[-1] ** 2 + 2 * max_accel * step_m)))
    for i in range(len(speeds) - 2, -1, -1):
        speeds[i] = min(speeds[i], math.sqrt(speeds[i + 1] ** 2 + 2 * max_decel * step_m))
    v = np.array(speeds)
    dt = 2 * step_m / np.maximum(v[:-1] + v[1:], 1e-9)
    knot_t = np.concatenate([[0.0], np.cumsum(dt)])
    knot_s, knot_v = s, v
    for index in reversed(stop_index):
        knot_t = np.insert(knot_t, index + 1, knot_t[index])
        knot_t[index + 1 :] += stop_duration_s
        knot_s = np.insert(knot_s, index + 1, knot_s[index])
        knot_v = np.insert(knot_v, index + 1, 0.0)
    times = np.asarray(times, dtype=float)
    if times[-1] > knot_t[-1]:
        raise ValueError(
            f"route ends at {knot_t[-1]:.1f} s, before the last time {times[-1]:.1f} s"
        )
    arc = np.interp(times, knot_t, knot_s)
    speed = np.interp(times, knot_t, knot_v)
    xy, yaw, curvature = route.at(arc)
    return VehicleMotion(times, xy, yaw, speed, curvature * speed)


@dataclass
class VoPlan:
    """Everything of a sequence except the pixels: scene, camera, frame times and poses."""

    scene: Scene
    camera: Camera
    times: np.ndarray
    motion: VehicleMotion
    T_world_camera: np.ndarray
    noise_std: float = 0.0
    seed: int = 0

    @property
    def T_first_camera(self) -> np.ndarray:
        """Camera poses (N, 4, 4) in the frame of the first camera (the VO output convention)."""
        return np.linalg.inv(self.T_world_camera[0]) @ self.T_world_camera


@dataclass
class VoSequence:
    """An in-memory sequence: the plan and its images (N, height, width) uint8."""

    plan: VoPlan
    images: np.ndarray = field(repr=False)


def plan_vo_sequence(
    duration_s: float = 20.0,
    fps: float = 10.0,
    seed: int = 0,
    camera: Camera | None = None,
    scene: Scene | None = None,
    t0: float = 0.0,
    noise_std: float = 0.0,
    corner_streets: tuple[tuple[int, int], tuple[int, int]] = ((1, 1), (3, 2)),
    **drive_options,
) -> VoPlan:
    """Scene (``city_scene(seed)`` unless given), camera, frame times ``t0 + k/fps`` and poses.

    ``drive_options`` go to :func:`drive` (max_speed, initial_speed, stops_m, …).
    """
    camera = synthetic_camera() if camera is None else camera
    scene = city_scene(seed) if scene is None else scene
    if scene.layout is None:
        raise ValueError("the scene has no street layout to drive on")
    n_frames = round(duration_s * fps)
    if n_frames < 2:
        raise ValueError("a sequence needs at least two frames")
    elapsed = np.arange(n_frames) / fps
    one_lap = loop_route(scene.layout, corner_streets)
    reach = drive_options.get("max_speed", 12.0) * elapsed[-1]
    laps = int(np.ceil(reach / one_lap.length)) + 1
    route = loop_route(scene.layout, corner_streets, laps=laps)
    motion = drive(route, elapsed, **drive_options)
    motion.t = t0 + elapsed
    T_world_camera = motion.T_world_vehicle @ camera.T_vehicle_camera
    return VoPlan(scene, camera, motion.t.copy(), motion, T_world_camera, noise_std, seed)


def render_frames(plan: VoPlan, renderer: Renderer | None = None) -> Iterator[np.ndarray]:
    """The frames of a plan, in order (noise, if any, seeded per frame from the plan seed)."""
    renderer = Renderer(plan.scene, plan.camera) if renderer is None else renderer
    for k, T in enumerate(plan.T_world_camera):
        yield renderer.render(T, plan.noise_std, seed=plan.seed * 1_000_003 + k)


def simulate_vo(duration_s: float = 5.0, fps: float = 10.0, seed: int = 0, **options) -> VoSequence:
    """In-memory sequence (images + ground truth) for tests and library use; see
    :func:`plan_vo_sequence` for the options."""
    plan = plan_vo_sequence(duration_s, fps, seed, **options)
    return VoSequence(plan, np.stack(list(render_frames(plan))))


def generate_vo_sequence(
    out_dir: str | Path,
    duration_s: float = 20.0,
    fps: float = 10.0,
    seed: int = 0,
    progress: bool = False,
    image_format: ImageFormat | str = ImageFormat.PNG,
    **options,
) -> VoPlan:
    """Render a sequence to ``out_dir`` (layout in the module docstring) and return its plan.

    ``image_format`` is ``png`` (lossless, ≈ 130 kB per 640×360 frame) or ``jpg`` (quality 95,
    about half that). Numbered frames left in ``image_0`` by an earlier, longer run are removed
    so that the folder holds exactly this sequence.
    """
    image_format = checked(ImageFormat, image_format, "image_format")
    out = Path(out_dir)
    image_dir = out / "image_0"
    image_dir.mkdir(parents=True, exist_ok=True)
    plan = plan_vo_sequence(duration_s, fps, seed, **options)
    frames = render_frames(plan)
    if progress:
        frames = track(frames, total=len(plan.times), description="rendering")
    params = [cv2.IMWRITE_JPEG_QUALITY, 95] if image_format is ImageFormat.JPG else []
    names = set()
    for k, image in enumerate(frames):
        path = image_dir / f"{k:06d}.{image_format}"
        if not cv2.imwrite(str(path), image, params):
            raise OSError(f"cannot write {path}")
        names.add(path.name)
    remove_stale_frames(image_dir, names)
    write_sequence_files(out, plan)
    log.info("wrote %d frames to %s", len(plan.times), out)
    return plan


def remove_stale_frames(image_dir: Path, kept: set[str]) -> None:
    """Remove the numbered frames (``000000.png``, ``.jpg``) in ``image_dir`` that are not
    ``kept``: an earlier, longer run's, or its other image format's, which would otherwise
    outnumber the new times."""
    for stale in sorted(image_dir.glob("[0-9][0-9][0-9][0-9][0-9][0-9].*")):
        if stale.suffix in (".png", ".jpg") and stale.name not in kept:
            log.info("removing %s left by an earlier run", stale)
            stale.unlink()


def write_sequence_files(out: Path, plan: VoPlan) -> None:
    """Times, calibration, ground-truth poses and speed of a plan (everything but the images)."""
    np.savetxt(out / "times.txt", plan.times, fmt="%.6f")
    write_camera_yaml(out / "calib.yaml", plan.camera)
    camera_gt = Trajectory.from_matrices(plan.times, plan.T_first_camera)
    write_kitti(out / "ground_truth_camera.kitti", camera_gt)
    write_tum(out / "ground_truth_camera.tum", camera_gt)
    write_tum(
        out / "ground_truth.tum", Trajectory.from_matrices(plan.times, plan.motion.T_world_vehicle)
    )
    np.savetxt(
        out / "speed.csv",
        np.column_stack([plan.times, plan.motion.speed]),
        fmt="%.6f",
        delimiter=",",
        header="t,speed_mps",
        comments="",
    )


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m vo_doppler.sim.vo_sequence OUT [--duration S] [--fps F] [--seed N] …``"""
    parser = argparse.ArgumentParser(description="Render a synthetic city VO sequence.")
    parser.add_argument("out", type=Path)
    parser.add_argument("--duration", type=float, default=20.0, help="seconds (default 20)")
    parser.add_argument("--fps", type=float, default=10.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--max-speed", type=float, default=12.0, help="m/s (default 12)")
    parser.add_argument("--noise", type=float, default=0.0, help="pixel noise std, grey levels")
    parser.add_argument(
        "--stop", type=float, action="append", default=[], help="stop at this distance (m)"
    )
    parser.add_argument(
        "--format", choices=values(ImageFormat), default=ImageFormat.PNG.value, help="image files"
    )
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    generate_vo_sequence(
        args.out,
        args.duration,
        args.fps,
        args.seed,
        progress=True,
        image_format=args.format,
        camera=synthetic_camera(args.width, args.height),
        noise_std=args.noise,
        max_speed=args.max_speed,
        stops_m=args.stop,
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
