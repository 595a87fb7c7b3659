"""Synthetic camera renderer: time per frame against brute-force ray casting, in one run.

Both render the same poses of a generated city drive (640×360 by default). The baseline casts
every pixel's ray against every plane of the scene (no culling, no polygon fill) and then uses
the same texture shading; the project's renderer culls, clips and fills only the planes in view
and resolves edge pixels exactly. The runs alternate so that machine load hits both alike;
times are medians. The baseline's images are checked to agree with the renderer's away from
edges, so the ratio compares equal work.

A second table times the frames ``vo-doppler simulate`` writes, on the urban-canyon drive:
the realistic camera (lens, rolling shutter, motion blur, sensor, traffic: the default) against
the clean rendering (``--clean``), frame by frame alternately, after each has built its scene.

    python benchmarks/render_speed.py [--frames 20] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from vo_doppler.sim.render import NEAR_M, Renderer
from vo_doppler.sim.urban_canyon import (
    UrbanCanyonConfig,
    VehicleDrive,
    build_city,
    camera_frames,
)
from vo_doppler.sim.vo_sequence import plan_vo_sequence, synthetic_camera

ROOT = Path(__file__).resolve().parents[1]


def brute_force(renderer: Renderer, T_world_camera: np.ndarray) -> np.ndarray:
    """Every plane against every pixel: nearest hit inside its rectangle, then the same shading."""
    T = np.asarray(T_world_camera, dtype=float)
    R_cw = T[:3, :3].T
    centre = T[:3, 3]
    t_cw = -R_cw @ centre
    n_planes = len(renderer.scene.planes)
    homographies = np.zeros((n_planes + 1, 9), dtype=np.float32)
    homographies[0, 8] = 1.0
    nearest = np.zeros(renderer._uu.shape, dtype=np.float32)
    index = np.zeros(renderer._uu.shape, dtype=np.int32)
    u, v = renderer._uu, renderer._vv
    for k in range(n_planes):
        n_c = R_cw @ renderer._normal[k]
        d_c = float(n_c @ (R_cw @ renderer._origin[k] + t_cw))
        if abs(d_c) < 1e-9:
            continue
        H = renderer._texture_homography(k, R_cw, centre, n_c, d_c).astype(np.float32)
        a, b, c = (n_c @ renderer._K_inv) / d_c
        inverse = a * u + b * v + c
        w = H[2, 0] * u + H[2, 1] * v + H[2, 2]
        s = (H[0, 0] * u + H[0, 1] * v + H[0, 2]) / w
        t = (H[1, 0] * u + H[1, 1] * v + H[1, 2]) / w
        low, high = renderer._low[k + 1], renderer._high[k + 1]
        hit = (inverse > nearest) & (inverse < 1.0 / NEAR_M)
        hit &= (s >= low[0]) & (s <= high[0]) & (t >= low[1]) & (t <= high[1])
        nearest = np.where(hit, inverse, nearest)
        index = np.where(hit, k + 1, index)
        homographies[k + 1] = H.ravel()
    image = renderer._shade(index, homographies, u, v)
    return np.clip(image, 0, 255).round().astype(np.uint8)


def simulator_frames(camera, frames: int) -> dict[str, float]:
    """Median seconds per frame of the realistic and the clean camera of the simulator."""
    streams = {}
    realistic = UrbanCanyonConfig(duration_s=60.0)
    clean_city = replace(realistic.city, window_facades=0, ground_contrast=1.0)
    clean = replace(realistic, camera_effects=None, city=clean_city)
    for name, config in (("realistic", realistic), ("clean", clean)):
        scene = build_city(config)
        vehicle = VehicleDrive(config, scene.layout)
        times = config.start_gps_s + np.linspace(5.0, 55.0, frames + 1)
        streams[name] = camera_frames(config, scene, camera, vehicle, times)
        next(streams[name])
    seconds = {name: [] for name in streams}
    for _ in range(frames):
        for name, stream in streams.items():
            start = time.perf_counter()
            next(stream)
            seconds[name].append(time.perf_counter() - start)
    return {name: float(np.median(values)) for name, values in seconds.items()}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=20)
    parser.add_argument("--width", type=int, default=640)
    parser.add_argument("--height", type=int, default=360)
    parser.add_argument("--json", type=Path, default=ROOT / "benchmarks/results/render_speed.json")
    args = parser.parse_args()

    camera = synthetic_camera(args.width, args.height)
    plan = plan_vo_sequence(30.0, 10.0, seed=0, camera=camera)
    renderer = Renderer(plan.scene, camera)
    poses = plan.T_world_camera[:: max(len(plan.times) // args.frames, 1)][: args.frames]
    times = {"renderer": [], "brute_force": []}
    cpu = {"renderer": [], "brute_force": []}
    mismatch = []
    for T in poses:
        start, start_cpu = time.perf_counter(), time.process_time()
        result = renderer.render_full(T)
        times["renderer"].append(time.perf_counter() - start)
        cpu["renderer"].append(time.process_time() - start_cpu)
        start, start_cpu = time.perf_counter(), time.process_time()
        baseline = brute_force(renderer, T)
        times["brute_force"].append(time.perf_counter() - start)
        cpu["brute_force"].append(time.process_time() - start_cpu)
        index = result.plane_index
        interior = np.zeros(index.shape, dtype=bool)
        interior[1:-1, 1:-1] = (
            (index[1:-1, 1:-1] == index[:-2, 1:-1])
            & (index[1:-1, 1:-1] == index[2:, 1:-1])
            & (index[1:-1, 1:-1] == index[1:-1, :-2])
            & (index[1:-1, 1:-1] == index[1:-1, 2:])
        )
        difference = np.abs(result.image.astype(int) - baseline.astype(int))[interior]
        mismatch.append(float(np.mean(difference > 1)))
    median = {name: float(np.median(values)) * 1e3 for name, values in times.items()}
    median_cpu = {name: float(np.median(values)) * 1e3 for name, values in cpu.items()}
    ratio = median["brute_force"] / median["renderer"]

    table = Table(
        title=f"{args.width}×{args.height}, {len(plan.scene.planes)} planes, "
        f"{len(poses)} poses of a city drive"
    )
    table.add_column("renderer")
    table.add_column("median ms/frame (wall)", justify="right")
    table.add_column("median CPU ms/frame", justify="right")
    table.add_column("speed-up (wall)", justify="right")
    for name, label in (
        ("renderer", "vo_doppler.sim.render.Renderer"),
        ("brute_force", "brute-force ray casting (baseline)"),
    ):
        table.add_row(
            label,
            f"{median[name]:.1f}",
            f"{median_cpu[name]:.1f}",
            f"{median['brute_force'] / median[name]:.1f}×",
        )
    Console().print(table)
    print(f"interior pixels differing by > 1 grey level: {100 * max(mismatch):.2f} % (worst frame)")
    simulator = simulator_frames(camera, args.frames)
    table = Table(title=f"vo-doppler simulate frames, {args.width}×{args.height}")
    table.add_column("camera")
    table.add_column("median ms/frame (wall)", justify="right")
    table.add_column("relative", justify="right")
    for name, label in (("clean", "clean (--clean)"), ("realistic", "realistic (default)")):
        table.add_row(
            label, f"{simulator[name] * 1e3:.1f}", f"{simulator[name] / simulator['clean']:.2f}×"
        )
    Console().print(table)

    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(
        json.dumps(
            {
                "width": args.width,
                "height": args.height,
                "planes": len(plan.scene.planes),
                "frames": len(poses),
                "renderer_ms": median["renderer"],
                "brute_force_ms": median["brute_force"],
                "renderer_cpu_ms": median_cpu["renderer"],
                "brute_force_cpu_ms": median_cpu["brute_force"],
                "speedup": ratio,
                "interior_mismatch_fraction_max": max(mismatch),
                "simulator_clean_ms": simulator["clean"] * 1e3,
                "simulator_realistic_ms": simulator["realistic"] * 1e3,
            },
            indent=2,
        )
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
