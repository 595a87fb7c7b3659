"""How well corners track on the synthetic camera images, against exact ground truth.

On a generated city drive, every ``--every``-th frame pair: Shi–Tomasi corners in the first
frame (``cv2.goodFeaturesToTrack``, up to 1000, quality 0.01, 7 px apart), pyramidal KLT to the
next frame and back (``cv2.calcOpticalFlowPyrLK``, 4 levels). Reported: corners per frame, the
fraction whose forward–backward error is < 0.5 px (of all corners, and of those whose true
position is still in the next image), and of those passing, the fraction within 0.5 px of the
true position (each corner back-projected onto the plane it lies on and projected into the next
camera). Several frame rates and KLT windows side by side.

    python benchmarks/synthetic_tracking.py [--duration 30] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import cv2
import numpy as np
from rich.console import Console
from rich.table import Table

from vo_doppler.sim.render import Renderer, project_points
from vo_doppler.sim.vo_sequence import plan_vo_sequence, render_frames

ROOT = Path(__file__).resolve().parents[1]


def track_statistics(fps: float, window: int, duration: float, every: int) -> dict[str, float]:
    plan = plan_vo_sequence(duration, fps, seed=0)
    renderer = Renderer(plan.scene, plan.camera)
    frames = list(render_frames(plan, renderer))
    width, height = plan.camera.width, plan.camera.height
    counts, passed, passed_in_view, accurate = [], [], [], []
    for k in range(0, len(frames) - 1, every):
        first, second = frames[k], frames[k + 1]
        corners = cv2.goodFeaturesToTrack(first, 1000, 0.01, 7)
        options = {"winSize": (window, window), "maxLevel": 3}
        ahead, status, _ = cv2.calcOpticalFlowPyrLK(first, second, corners, None, **options)
        back, status_back, _ = cv2.calcOpticalFlowPyrLK(second, first, ahead, None, **options)
        error = np.linalg.norm((back - corners)[:, 0], axis=1)
        good = (status[:, 0] == 1) & (status_back[:, 0] == 1) & (error < 0.5)
        result = renderer.render_full(plan.T_world_camera[k])
        points = renderer.backproject(plan.T_world_camera[k], corners[:, 0], result.plane_index)
        truth = project_points(plan.camera, plan.T_world_camera[k + 1], points)
        with np.errstate(invalid="ignore"):
            in_view = np.all((truth >= 0) & (truth <= (width - 1, height - 1)), axis=1)
        true_error = np.linalg.norm(truth - ahead[:, 0], axis=1)
        counts.append(len(corners))
        passed.append(good.mean())
        passed_in_view.append(good[in_view].mean())
        accurate.append(np.mean(true_error[good & in_view] < 0.5))
    return {
        "corners_per_frame": float(np.mean(counts)),
        "fb_pass": float(np.mean(passed)),
        "fb_pass_in_view": float(np.mean(passed_in_view)),
        "passing_within_half_px_of_truth": float(np.mean(accurate)),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=30.0)
    parser.add_argument("--every", type=int, default=3, help="use every n-th frame pair")
    parser.add_argument(
        "--json", type=Path, default=ROOT / "benchmarks/results/synthetic_tracking.json"
    )
    args = parser.parse_args()
    cases = [(10.0, 21), (10.0, 15), (15.0, 21)]
    results = {}
    table = Table(title=f"KLT on a {args.duration:g}-s synthetic city drive (≤ 12 m/s)")
    for column in ("fps", "KLT window", "corners", "FB < 0.5 px", "FB ok, in view", "≤ 0.5 px"):
        table.add_column(column, justify="right")
    for fps, window in cases:
        stats = track_statistics(fps, window, args.duration, args.every)
        results[f"fps{fps:g}_win{window}"] = stats
        table.add_row(
            f"{fps:g}",
            str(window),
            f"{stats['corners_per_frame']:.0f}",
            f"{stats['fb_pass']:.2f}",
            f"{stats['fb_pass_in_view']:.2f}",
            f"{stats['passing_within_half_px_of_truth']:.2f}",
        )
    Console().print(table)
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(results, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
