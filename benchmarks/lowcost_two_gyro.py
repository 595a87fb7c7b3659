"""Low-cost path mapping on generated two-gyro records (issue 6 acceptance, generated data).

Each record: 10 min standstill, then one closed 914 m stadium loop at 10 m/s; gyro 1 at 100 Hz
(bias +0.285 deg/s = 17.1 deg/min, the seed's sensor 1), gyro 2 at 50 Hz (bias −0.15 deg/s),
both with bias random walk and white noise; 1 Hz GPS with slowly wandering error. Drift is
measured against the true yaw over the whole record.

k is chosen the seed's way — swept on a separate standstill record of the same gyros whose
turn-on biases differ (``calibration_spec``) — and, for comparison, on the record's own
standstill. Prints the Table 1 layout per seed, the ratio of the worse single sensor to
"combined + ε0 removed", and the closed-loop gap; writes a JSON.

    .venv/bin/python benchmarks/lowcost_two_gyro.py [--seeds 7 1 2 3] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

from rich.console import Console
from rich.table import Table

from vo_doppler.lowcost.drift import VARIANTS
from vo_doppler.lowcost.gyro_combination import choose_k
from vo_doppler.lowcost.pipeline import DeadReckonConfig, Reference, run_deadreckon
from vo_doppler.lowcost.rate_alignment import align_rates
from vo_doppler.sim.two_gyro import TwoGyroSpec, calibration_spec, generate_two_gyro

ROOT = Path(__file__).resolve().parents[1]
DEBIASED = VARIANTS.index("combined + ε0 removed")


def calibration_k(spec: TwoGyroSpec) -> float:
    calibration = generate_two_gyro(calibration_spec(spec))
    aligned = align_rates(*calibration.gyro1, *calibration.gyro2)
    return choose_k(aligned.t, aligned.omega1, aligned.omega2).sweep.k


def run_record(spec: TwoGyroSpec, k: float | None, downsample: int = 1) -> dict:
    record = generate_two_gyro(spec)
    config = DeadReckonConfig(standstill_s=record.standstill, k=k, downsample=downsample)
    reference = Reference(record.truth_t, record.truth_yaw, "truth")
    result = run_deadreckon(record.gyro1, record.gyro2, record.gps, config, reference=reference)
    rows = {
        row.variant: {
            "drift_deg_per_min": row.drift_deg_per_min,
            "final_heading_error_deg": row.final_heading_error_deg,
            "gap_m": row.gap.gap_m,
            "gap_percent": row.gap.percent,
        }
        for row in result.rows
    }
    drift = {name: abs(v["drift_deg_per_min"]) for name, v in rows.items()}
    return {
        "k": result.model.k,
        "tau_s": result.model.tau,
        "rows": rows,
        "ratio_worse_single_to_debiased": max(drift["sensor 1"], drift["sensor 2"])
        / drift["combined + ε0 removed"],
        "best_variant": min(drift, key=drift.get),
        "loop_gap_percent": rows["combined + ε0 removed"]["gap_percent"],
    }


def print_table(console: Console, title: str, outcome: dict) -> None:
    table = Table(title=title)
    for column in ("variant", "drift °/min", "final error °", "gap m", "gap %"):
        table.add_column(column, justify="left" if column == "variant" else "right")
    for name, row in outcome["rows"].items():
        table.add_row(
            name,
            f"{row['drift_deg_per_min']:+.4f}",
            f"{row['final_heading_error_deg']:+.3f}",
            f"{row['gap_m']:.2f}",
            f"{row['gap_percent']:.2f}",
        )
    console.print(table)
    console.print(
        f"k {outcome['k']:.2f}, τ {outcome['tau_s']:.0f} s; worse single / combined + ε0 "
        f"removed = {outcome['ratio_worse_single_to_debiased']:.0f}×; best row: "
        f"{outcome['best_variant']}; loop gap {outcome['loop_gap_percent']:.2f} %"
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[7, 1, 2, 3])
    parser.add_argument(
        "--json", type=Path, default=ROOT / "benchmarks/results/lowcost_two_gyro.json"
    )
    args = parser.parse_args(argv)
    console = Console()
    out: dict = {}
    for seed in args.seeds:
        spec = TwoGyroSpec(seed=seed)
        k_cal = calibration_k(spec)
        runs = {
            "k from calibration record": run_record(spec, k_cal),
            "k swept on own standstill": run_record(spec, None),
            "k from calibration, noisier GPS (τ 60 s, 0.2 m white)": run_record(
                replace(spec, gps_tau_s=60.0, gps_white_m=0.2), k_cal
            ),
        }
        out[seed] = runs
        for label, outcome in runs.items():
            print_table(console, f"seed {seed}: {label}", outcome)
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(out, indent=2))
    console.print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
