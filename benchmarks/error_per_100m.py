"""Trajectory error per 100 m, side by side, for the six pipelines on each sequence: VO and
wheel + gyro dead reckoning, each alone (initial heading from ground truth), + GPS
(conventional Doppler heading) and + GPS (tightly coupled heading).

    python benchmarks/error_per_100m.py SEQUENCE_DIR [SEQUENCE_DIR ...] [--json FILE]

Each sequence folder needs a sequence.yaml with ground truth (``vo-doppler simulate`` writes
one). The pipeline runs once per sequence; its VO is corrected by the adaptive blend
(``kalman``) and by the paper's window method (Eq. 11–13), reported side by side with the
issue-13 ratios (VO + TC over VO alone and over VO + conventional, each to be ≤ 0.5). Prints a
table per sequence and method and writes JSON and the figures (trajectories, heading, error per
100 m; blend) next to it.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from benchmarks.correction_methods import METHODS, acceptance, evaluate_methods
from benchmarks.sequence_runs import read_with_truth, run_sequences, run_with_progress
from vo_doppler.eval.pipelines import PIPELINE_LABELS
from vo_doppler.report.heading_figure import heading_figure
from vo_doppler.report.run_report import error_per_100m_figure, trajectories_figure

ROOT = Path(__file__).resolve().parents[1]
SIDE_BY_SIDE = {name: METHODS[name] for name in ("kalman", "window")}


def evaluate_sequence(folder: Path, figures: Path, console: Console) -> dict:
    inputs = read_with_truth(folder)
    result = run_with_progress(inputs, console)
    evaluated = evaluate_methods(inputs, result, SIDE_BY_SIDE)
    _, per_100m, shown = evaluated["kalman"]
    table = result.heading
    truth = inputs.truth
    truth_yaw = truth.yaw_at(table.t)
    figures.mkdir(parents=True, exist_ok=True)
    trajectories_figure(figures / f"{inputs.name}_trajectories.png", shown, truth, inputs.name)
    heading_figure(figures / f"{inputs.name}_heading.png", table, truth_yaw, inputs.name)
    error_per_100m_figure(figures / f"{inputs.name}_error_per_100m.png", per_100m, inputs.name)
    return {
        "gnss_epochs": len(table),
        "conventional_availability": float(np.mean(table.published_conventional[0])),
        "tight_availability": float(np.mean(table.tc_available)),
        "tight_used": float(np.mean(result.tc_usable)),
        "path_length_m": truth.path_length,
        "methods": {
            method: {name: e.to_dict() for name, e in errors.items()}
            for method, (errors, _, _) in evaluated.items()
        },
    }


def print_sequence(console: Console, name: str, figures: dict) -> None:
    table = Table(
        title=f"{name}: {figures['path_length_m']:.0f} m, conventional heading (GNSS tests) on "
        f"{figures['conventional_availability']:.0%} of epochs, tightly coupled on "
        f"{figures['tight_availability']:.0%} (used {figures['tight_used']:.0%})"
    )
    for column in (
        "correction",
        "pipeline",
        "horizontal error/100 m mean [m]",
        "max [m]",
        "3-D error/100 m [m]",
        "KITTI [%]",
        "heading RMSE [deg]",
        "heading availability",
        "final horizontal error [m]",
    ):
        table.add_column(column, justify="right")
    for method, pipelines in figures["methods"].items():
        for key, row in pipelines.items():
            table.add_row(
                method,
                PIPELINE_LABELS[key],
                f"{row['error_per_100m_m']:.2f}",
                f"{row['error_per_100m_max_m']:.2f}",
                f"{row['error_per_100m_3d_m']:.2f}",
                f"{row['kitti_translation_pct']:.2f}",
                f"{row['heading_rmse_deg']:.2f}",
                f"{row['heading_availability']:.0%}",
                f"{row['final_position_error_m']:.2f}",
            )
        table.add_section()
    console.print(table)
    for method, pipelines in figures["methods"].items():
        console.print(f"{method}: issue-13 acceptance {acceptance(pipelines)}")


def main(argv: list[str] | None = None) -> int:
    return run_sequences(
        __doc__.splitlines()[0],
        ROOT / "benchmarks/results/error_per_100m.json",
        evaluate_sequence,
        print_sequence,
        argv,
    )


if __name__ == "__main__":
    sys.exit(main())
