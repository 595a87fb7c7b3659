"""Heading correction side by side: the seed's window (Eq. 11–13) against the Kalman blend.

    python benchmarks/correction_methods.py SEQUENCE_DIR [SEQUENCE_DIR ...] [--json FILE]

The whole pipeline (VO, calibration, tight heading) runs once per sequence; then every
correction method corrects the same VO, so the methods differ in nothing else. Prints, per
sequence and method, the horizontal error per 100 m and heading RMSE of VO alone, VO + GPS
(conventional), VO + GPS (tightly coupled) and DR + GPS (tightly coupled), with the issue-5
acceptance (VO + TC ≤ 0.5 m per 100 m and ≤ 0.25 × VO + conventional), and writes JSON.
"""

from __future__ import annotations

import sys
from pathlib import Path

from rich.console import Console
from rich.table import Table

from benchmarks.sequence_runs import read_with_truth, run_sequences, run_with_progress
from vo_doppler.eval.pipelines import evaluate_pipelines
from vo_doppler.fusion.correction import CorrectionConfig
from vo_doppler.fusion.heading_blend import BlendConfig
from vo_doppler.run import RunConfig, correct_all
from vo_doppler.vo.frames import vehicle_trajectory

ROOT = Path(__file__).resolve().parents[1]
METHODS = {
    "window": RunConfig(correction=CorrectionConfig(method="window")),
    "kalman": RunConfig(correction=CorrectionConfig(method="kalman")),
    "kalman causal": RunConfig(
        correction=CorrectionConfig(method="kalman", blend=BlendConfig(smooth=False))
    ),
}
PIPELINES = ("vo", "vo_gps_conv", "vo_gps_tc", "dr_gps_tc")


def evaluate_sequence(folder: Path, console: Console) -> dict:
    inputs = read_with_truth(folder)
    result = run_with_progress(inputs, console)
    methods = {}
    for name, config in METHODS.items():
        trajectories = correct_all(
            inputs,
            result.heading,
            vehicle_trajectory(result.vo.trajectory, inputs.camera.T_vehicle_camera),
            result.calibrated_speed,
            result.start_enu,
            config,
        )
        errors, _, _ = evaluate_pipelines(
            trajectories, result.heading, result.tc_usable, inputs.truth
        )
        methods[name] = {key: errors[key].to_dict() for key in PIPELINES if key in errors}
    return {"path_length_m": inputs.truth.path_length, "methods": methods}


def acceptance(rows: dict) -> str:
    tc = rows["vo_gps_tc"]["error_per_100m_m"]
    conv = rows["vo_gps_conv"]["error_per_100m_m"]
    ok = tc <= 0.5 and tc <= 0.25 * conv
    return f"{'met' if ok else 'missed'} (TC/conv {tc / conv:.2f})"


def print_sequence(console: Console, name: str, figures: dict) -> None:
    table = Table(title=f"{name}: {figures['path_length_m']:.0f} m")
    table.add_column("method")
    for label in ("VO", "VO + conv", "VO + TC", "DR + TC"):
        table.add_column(f"{label}: m per 100 m (heading RMSE)", justify="right")
    table.add_column("issue-5 acceptance")
    for method, rows in figures["methods"].items():
        cells = [
            f"{rows[key]['error_per_100m_m']:.3f} ({rows[key]['heading_rmse_deg']:.2f}°)"
            if key in rows
            else "-"
            for key in PIPELINES
        ]
        table.add_row(method, *cells, acceptance(rows))
    console.print(table)


def main(argv: list[str] | None = None) -> int:
    return run_sequences(
        __doc__.splitlines()[0],
        ROOT / "benchmarks/results/correction_methods.json",
        lambda folder, _, console: evaluate_sequence(folder, console),
        print_sequence,
        argv,
        width=170,
    )


if __name__ == "__main__":
    sys.exit(main())
