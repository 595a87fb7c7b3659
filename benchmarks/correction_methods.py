"""Heading correction side by side: the seed's window (Eq. 11–13) against the Kalman blend.

    python benchmarks/correction_methods.py SEQUENCE_DIR [SEQUENCE_DIR ...] [--json FILE]

The whole pipeline (VO, calibration, tight heading) runs once per sequence; then every
correction method corrects the same VO, so the methods differ in nothing else. Prints, per
sequence and method, the horizontal error per 100 m and heading RMSE of VO alone, VO + GPS
(conventional), VO + GPS (tightly coupled) and DR + GPS (tightly coupled), with the issue-13
acceptance (VO + TC ≤ 0.5 × VO alone and ≤ 0.5 × VO + conventional), and writes JSON.
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
from vo_doppler.model.sequence import Sequence
from vo_doppler.run import Pipeline, RunConfig, RunResult
from vo_doppler.run_stages import sequence_trajectories
from vo_doppler.vo.frames import vehicle_trajectory

ROOT = Path(__file__).resolve().parents[1]
METHODS = {
    "window": RunConfig(correction=CorrectionConfig(method="window")),
    "kalman": RunConfig(correction=CorrectionConfig(method="kalman")),
    "kalman causal": RunConfig(
        correction=CorrectionConfig(method="kalman", blend=BlendConfig(smooth=False))
    ),
}
PIPELINES = tuple(Pipeline)
MAX_RATIO = 0.5
"""Issue 13: VO + GPS (tightly coupled) at most half the VO alone's and the conventional's error."""


def evaluate_methods(
    inputs: Sequence, result: RunResult, methods: dict[str, RunConfig]
) -> dict[str, tuple]:
    """Per method, ``evaluate_pipelines`` of the same pipeline run corrected by that method."""
    evaluated = {}
    for name, config in methods.items():
        trajectories, _ = sequence_trajectories(
            inputs,
            result.heading,
            vehicle_trajectory(result.vo.trajectory, inputs.camera.T_vehicle_camera),
            result.calibrated_speed,
            result.antenna,
            config,
        )
        evaluated[name] = evaluate_pipelines(
            trajectories, result.heading, result.tc_usable, inputs.truth
        )
    return evaluated


def ratios(rows: dict) -> dict[str, float]:
    """VO + TC error per 100 m over the VO alone's and over VO + conventional's."""
    tc = rows["vo_gps_tc"]["error_per_100m_m"]
    return {
        "tc_over_vo": tc / rows["vo"]["error_per_100m_m"],
        "tc_over_conv": tc / rows["vo_gps_conv"]["error_per_100m_m"],
    }


def acceptance(rows: dict) -> str:
    r = ratios(rows)
    ok = r["tc_over_vo"] <= MAX_RATIO and r["tc_over_conv"] <= MAX_RATIO
    verdict = "met" if ok else "missed"
    return f"{verdict} (TC/VO {r['tc_over_vo']:.2f}, TC/conv {r['tc_over_conv']:.2f})"


def evaluate_sequence(folder: Path, console: Console) -> dict:
    inputs = read_with_truth(folder)
    result = run_with_progress(inputs, console)
    methods = {
        name: {key: errors[key].to_dict() for key in PIPELINES if key in errors}
        for name, (errors, _, _) in evaluate_methods(inputs, result, METHODS).items()
    }
    return {"path_length_m": inputs.truth.path_length, "methods": methods}


def print_sequence(console: Console, name: str, figures: dict) -> None:
    table = Table(title=f"{name}: {figures['path_length_m']:.0f} m")
    table.add_column("method")
    for label in ("VO", "VO + conv", "VO + TC", "DR + TC"):
        table.add_column(f"{label}: m per 100 m (heading RMSE)", justify="right")
    table.add_column("issue-13 acceptance")
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
        width=190,
    )


if __name__ == "__main__":
    sys.exit(main())
