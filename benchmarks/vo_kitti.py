"""KITTI 06 clip: the project's VO against a classic frame-to-frame baseline, in one run.

Both pipelines read every image from disk (the same prefetching reader), take their step
lengths from the same speed signal (ground-truth step lengths written as a ``t,speed_mps`` CSV,
a stand-in for wheel speed) and are timed end to end. Every run is its own process with OpenCV,
OpenMP and BLAS limited to one thread, so both sides have the same resources; ``--pin CPU``
also pins each run to one core with ``taskset -c CPU`` (or pin the whole benchmark:
``taskset -c 0 python benchmarks/vo_kitti.py``). Each run reports its own wall and CPU time from
the first image read to the metric trajectory; the process's wall and CPU time (interpreter
start and imports included) are measured around it. The runs alternate, the order swapping every
repeat (``--repeats``, default 5), so that machine load hits both alike; every figure is the
median over the repeats.

The ground truth's attitude is checked too: its frame-to-frame rotation changes by about 1e-4°
per frame over frames 0–11 (a constant-rate interpolation, not a measured attitude, which
jitters by 1e-2–1e-1° per frame as it does from frame 12 on). The figures are therefore also
given from ``--measured-from`` (default 12) to the end, start-aligned there.

    python benchmarks/vo_kitti.py [--data ../shared/data/kitti06_0000_0050] [--pin 0]
        [--repeats 5] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
from rich.console import Console
from rich.table import Table

from vo_doppler.eval.metrics import attitude_roughness_deg, evaluate
from vo_doppler.eval.reference_speed import speed_from_poses
from vo_doppler.io.calibration import read_camera
from vo_doppler.io.images import list_images, prefetch_images, read_times
from vo_doppler.io.sensor_csv import SPEED_COLUMN, read_sensor_csv, write_sensor_csv
from vo_doppler.io.trajectory import read_kitti
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.vo.baseline import FrameToFrameVO
from vo_doppler.vo.batch import run_visual_odometry
from vo_doppler.vo.scale import metric_positions

ROOT = Path(__file__).resolve().parents[1]
CAMERA_UP = np.array([0.0, -1.0, 0.0])
OURS, BASELINE = "vo-doppler (window BA)", "baseline (FAST+KLT+E)"
ONE_THREAD = {name: "1" for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}


def default_data() -> Path:
    shared = Path(os.environ.get("VO_DOPPLER_SHARED_DATA", ROOT.parent / "shared" / "data"))
    return shared / "kitti06_0000_0050"


def write_speed_csv(truth: Trajectory, path: Path) -> None:
    """Speed samples whose trapezoidal integral between frames is the true step length (what
    ``vo-doppler kitti-speed`` writes)."""
    write_sensor_csv(path, speed_from_poses(truth), SPEED_COLUMN)


def travel_direction_deg(trajectory: Trajectory) -> tuple[float, float]:
    """Mean elevation (up) and azimuth (right) of the frame-to-frame motion in the camera frame
    (deg). A rotation error in the ground truth's camera extrinsic shows here as an offset
    common to every pipeline."""
    M = trajectory.matrices
    step = np.einsum("nij,nj->ni", np.linalg.inv(M[:-1])[:, :3, :3], M[1:, :3, 3] - M[:-1, :3, 3])
    elevation = np.degrees(np.arctan2(-step[:, 1], step[:, 2]))
    azimuth = np.degrees(np.arctan2(step[:, 0], step[:, 2]))
    return float(np.mean(elevation)), float(np.mean(azimuth))


def run_project_vo(files, times, camera, speed) -> tuple[Trajectory, dict]:
    output = run_visual_odometry(prefetch_images(files), times, camera, None, speed)
    stats = output.stats
    return output.trajectory, {
        "flagged_frames": len(stats.flagged_frames),
        "reprojection_rms_px": stats.reprojection_rms_px,
        "ba_runs": stats.ba_runs,
    }


def run_baseline(files, times, camera, speed) -> tuple[Trajectory, dict]:
    baseline = FrameToFrameVO(camera.K)
    poses = np.array([baseline.process(image) for image in prefetch_images(files)])
    poses[:, :3, 3] = metric_positions(poses, times, speed[0], speed[1])
    return Trajectory.from_matrices(times, poses), {}


PIPELINES = {OURS: run_project_vo, BASELINE: run_baseline}


def worker(name: str, data: Path, speed_csv: Path, out: Path) -> None:
    """One timed run in this process: poses to ``out``.npy, timings and statistics to .json."""
    cv2.setNumThreads(1)
    files = list_images(data / "image_0")
    times = read_times(data / "times.txt", len(files))
    camera = read_camera(data / "calib.txt")
    series = read_sensor_csv(speed_csv, SPEED_COLUMN)
    start_wall, start_cpu = time.perf_counter(), time.process_time()
    trajectory, stats = PIPELINES[name](files, times, camera, (series.t, series.value))
    run = {"wall": time.perf_counter() - start_wall, "cpu": time.process_time() - start_cpu}
    np.save(out.with_suffix(".npy"), trajectory.matrices)
    out.with_suffix(".json").write_text(json.dumps({"run": run, "stats": stats}))


def timed_process(name: str, args: argparse.Namespace, speed_csv: Path, out: Path) -> dict:
    """Run ``worker`` as its own single-threaded (optionally pinned) process; its own run
    timings and the whole process's wall and CPU seconds."""
    command = [sys.executable, __file__, "--worker", name, "--data", str(args.data)]
    command += ["--speed", str(speed_csv), "--out", str(out)]
    if args.pin is not None:
        command = ["taskset", "-c", str(args.pin), *command]
    start = time.perf_counter()
    process = subprocess.Popen(command, env=os.environ | ONE_THREAD)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{name} run failed: {' '.join(command)}")
    result = json.loads(out.with_suffix(".json").read_text())
    result["process"] = {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime}
    return result


def median_fps(frames: int, runs: list[dict], scope: str, clock: str) -> float:
    return frames / float(np.median([r[scope][clock] for r in runs]))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=default_data())
    parser.add_argument(
        "--measured-from",
        type=int,
        default=12,
        help="first frame of the supplementary evaluation (where the GT attitude jitters)",
    )
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--pin", type=int, help="run every pipeline pinned to this CPU (taskset)")
    parser.add_argument("--json", type=Path, default=ROOT / "benchmarks/results/vo_kitti.json")
    parser.add_argument("--worker", choices=list(PIPELINES), help=argparse.SUPPRESS)
    parser.add_argument("--speed", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker is not None:
        worker(args.worker, args.data, args.speed, args.out)
        return 0
    if not args.data.is_dir():
        print(f"KITTI clip not found at {args.data}", file=sys.stderr)
        return 2
    files = list_images(args.data / "image_0")
    times = read_times(args.data / "times.txt", len(files))
    truth = read_kitti(args.data / "poses.txt", times)
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    runs: dict[str, list[dict]] = {name: [] for name in PIPELINES}
    results = {}
    first_poses: dict[str, np.ndarray] = {}
    with tempfile.TemporaryDirectory() as tmp:
        speed_csv = Path(tmp) / "speed.csv"
        write_speed_csv(truth, speed_csv)
        for repeat in range(args.repeats):
            order = list(PIPELINES) if repeat % 2 == 0 else list(PIPELINES)[::-1]
            for name in order:
                out = Path(tmp) / f"{len(name)}_{repeat}"
                runs[name].append(timed_process(name, args, speed_csv, out))
                poses = np.load(out.with_suffix(".npy"))
                if not np.array_equal(poses, first_poses.setdefault(name, poses)):
                    print(f"warning: {name} gave different poses in repeat {repeat}")
                results[name] = (Trajectory.from_matrices(times, poses), runs[name][-1]["stats"])
    rows = {}
    tail = np.arange(args.measured_from, len(files))
    for name, (trajectory, stats) in results.items():
        errors = evaluate(trajectory, truth, "start", CAMERA_UP)
        aligned = evaluate(trajectory, truth, "se2", CAMERA_UP)
        measured = evaluate(trajectory.subset(tail), truth.subset(tail), "start", CAMERA_UP)
        rows[name] = {
            "fps": median_fps(len(files), runs[name], "run", "wall"),
            "cpu_fps": median_fps(len(files), runs[name], "run", "cpu"),
            "process_fps": median_fps(len(files), runs[name], "process", "wall"),
            "process_cpu_fps": median_fps(len(files), runs[name], "process", "cpu"),
            "runs": [{key: r[key] for key in ("run", "process")} for r in runs[name]],
            "final_position_error_m": errors.final_position_error_m,
            "final_drift_pct": errors.final_drift_pct,
            "end_yaw_error_deg": errors.end_yaw_error_deg,
            "ate_rmse_m": errors.ate_rmse_m,
            "rotation_deg_per_100m": errors.mean_rotation_deg_per_100m,
            "se2_end_yaw_error_deg": aligned.end_yaw_error_deg,
            "se2_final_position_error_m": aligned.final_position_error_m,
            "from_measured_final_position_error_m": measured.final_position_error_m,
            "from_measured_end_yaw_error_deg": measured.end_yaw_error_deg,
            "travel_direction_elevation_azimuth_deg": travel_direction_deg(trajectory),
        }
        rows[name] |= stats
    ours, base = rows[OURS], rows[BASELINE]
    ratios = {
        "final_error_ratio": ours["final_position_error_m"] / base["final_position_error_m"],
        "fps_ratio": ours["fps"] / base["fps"],
        "cpu_fps_ratio": ours["cpu_fps"] / base["cpu_fps"],
        "process_fps_ratio": ours["process_fps"] / base["process_fps"],
        "process_cpu_fps_ratio": ours["process_cpu_fps"] / base["process_cpu_fps"],
        "from_measured_final_error_ratio": ours["from_measured_final_position_error_m"]
        / base["from_measured_final_position_error_m"],
    }
    table = Table(
        title=f"KITTI 06 frames 0-{len(files) - 1} ({truth.path_length:.1f} m), start-aligned"
    )
    for column in (
        "pipeline",
        "fps",
        "fps (CPU)",
        "fps (process)",
        "final error [m]",
        "drift [%]",
        "end yaw [deg]",
        "ATE [m]",
        "rot [deg/100 m]",
        "SE(2) end yaw [deg]",
        f"from {args.measured_from}: final [m]",
        f"from {args.measured_from}: end yaw [deg]",
    ):
        table.add_column(column, justify="right")
    for name, row in rows.items():
        table.add_row(
            name,
            f"{row['fps']:.1f}",
            f"{row['cpu_fps']:.1f}",
            f"{row['process_fps']:.1f}",
            f"{row['final_position_error_m']:.3f}",
            f"{row['final_drift_pct']:.2f}",
            f"{row['end_yaw_error_deg']:+.3f}",
            f"{row['ate_rmse_m']:.3f}",
            f"{row['rotation_deg_per_100m']:.3f}",
            f"{row['se2_end_yaw_error_deg']:+.3f}",
            f"{row['from_measured_final_position_error_m']:.3f}",
            f"{row['from_measured_end_yaw_error_deg']:+.3f}",
        )
    console = Console(width=200)
    console.print(table)
    roughness = attitude_roughness_deg(truth)
    split = args.measured_from - 1
    truth_check = {
        "travel_direction_elevation_azimuth_deg": travel_direction_deg(truth),
        "attitude_roughness_rms_deg_before": float(np.sqrt(np.mean(roughness[:split] ** 2))),
        "attitude_roughness_rms_deg_after": float(np.sqrt(np.mean(roughness[split:] ** 2))),
    }
    console.print(
        "ground-truth attitude second difference, RMS per frame: "
        f"frames 1-{split} {truth_check['attitude_roughness_rms_deg_before']:.5f}°, "
        f"frames {args.measured_from}-{len(files) - 2} "
        f"{truth_check['attitude_roughness_rms_deg_after']:.5f}°"
    )
    directions = {"ground truth": truth_check["travel_direction_elevation_azimuth_deg"]} | {
        name: row["travel_direction_elevation_azimuth_deg"] for name, row in rows.items()
    }
    console.print(
        "mean direction of travel in the camera frame (elevation, azimuth): "
        + "; ".join(f"{name} {e:+.3f}°, {a:+.3f}°" for name, (e, a) in directions.items())
    )
    console.print(
        f"final error ratio (ours/baseline) {ratios['final_error_ratio']:.2f} (target <= 0.5); "
        f"fps ratio {ratios['fps_ratio']:.2f} (target >= 1.5; by CPU time "
        f"{ratios['cpu_fps_ratio']:.2f}, whole processes {ratios['process_fps_ratio']:.2f}); "
        f"end yaw {ours['end_yaw_error_deg']:+.3f} deg (target |.| <= 0.2); "
        f"from frame {args.measured_from}: final error ratio "
        f"{ratios['from_measured_final_error_ratio']:.2f}, "
        f"end yaw {ours['from_measured_end_yaw_error_deg']:+.3f} deg"
    )
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(
        json.dumps(
            {
                "frames": len(files),
                "repeats": args.repeats,
                "pinned_cpu": args.pin,
                "pipelines": rows,
                **ratios,
                "truth_check": truth_check,
            },
            indent=2,
        )
    )
    console.print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
