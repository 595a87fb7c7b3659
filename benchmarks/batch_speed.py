"""``vo-doppler batch`` wall time with N workers against the same command with one worker.

    python benchmarks/batch_speed.py SEQ_DIR... [--workers 2] [--repeats 1] [--ray] [--json F]

Each configuration runs as a whole process (``vo-doppler batch ... -o OUT``, a fresh output
folder every time, so nothing is resumed), the configurations alternating within each repeat;
the ratio is of the medians. The load average before and after each run is recorded (the
machine may be shared). The aggregates of every run must agree (all columns but the times).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rich.console import Console
from rich.table import Table

VO_DOPPLER = Path(sys.executable).with_name("vo-doppler")
TIMES = {"seconds"}


def run_batch_process(sequences: list[Path], out: Path, options: list[str]) -> dict:
    """Wall time of one ``vo-doppler batch`` process and its aggregate rows (times dropped)."""
    shutil.rmtree(out, ignore_errors=True)
    command = [str(VO_DOPPLER), "-q", "batch", *map(str, sequences), "-o", str(out), *options]
    load_before = os.getloadavg()[0]
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(
            f"{' '.join(command)} exited {done.returncode}:\n{done.stdout}{done.stderr}"
        )
    with (out / "batch_summary.csv").open() as stream:
        rows = [{k: v for k, v in row.items() if k not in TIMES} for row in csv.DictReader(stream)]
    return {
        "wall_s": wall,
        "load_before": load_before,
        "load_after": os.getloadavg()[0],
        "rows": rows,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequences", nargs="+", type=Path)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--ray", action="store_true", help="also time --executor ray")
    parser.add_argument("--json", type=Path, default=Path("out/bench/batch_speed.json"))
    args = parser.parse_args(argv)
    configurations = {
        "serial (--workers 1)": ["--workers", "1"],
        f"local, --workers {args.workers}": ["--workers", str(args.workers)],
    }
    if args.ray:
        configurations[f"ray, --workers {args.workers}"] = [
            "--executor",
            "ray",
            "--workers",
            str(args.workers),
        ]
    console = Console(width=140)
    runs: dict[str, list[dict]] = {name: [] for name in configurations}
    with tempfile.TemporaryDirectory(prefix="batch_speed_") as scratch:
        for repeat in range(args.repeats):
            for index, (name, options) in enumerate(configurations.items()):
                run = run_batch_process(args.sequences, Path(scratch) / f"out{index}", options)
                runs[name].append(run)
                console.print(
                    f"repeat {repeat + 1}, {name}: {run['wall_s']:.1f} s "
                    f"(load {run['load_before']:.1f} -> {run['load_after']:.1f})"
                )
    reference = next(iter(runs.values()))[0]["rows"]
    agree = all(run["rows"] == reference for group in runs.values() for run in group)
    serial = statistics.median(r["wall_s"] for r in next(iter(runs.values())))
    table = Table(title=f"vo-doppler batch on {len(args.sequences)} recordings")
    for column in ("configuration", "median wall [s]", "runs [s]", "ratio to serial"):
        table.add_column(column, justify="left" if column == "configuration" else "right")
    results = {}
    for name, group in runs.items():
        median = statistics.median(r["wall_s"] for r in group)
        walls = [r["wall_s"] for r in group]
        results[name] = {
            "median_wall_s": median,
            "wall_s": walls,
            "ratio_to_serial": median / serial,
            "load_average": [(r["load_before"], r["load_after"]) for r in group],
        }
        runs_text = ", ".join(f"{w:.1f}" for w in walls)
        table.add_row(name, f"{median:.1f}", runs_text, f"{median / serial:.2f}")
    console.print(table)
    console.print(f"aggregates identical across runs (times aside): {agree}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    report = {
        "sequences": [str(s) for s in args.sequences],
        "cpu_count": os.cpu_count(),
        "repeats": args.repeats,
        "aggregates_agree": agree,
        "configurations": results,
    }
    args.json.write_text(json.dumps(report, indent=2))
    console.print(f"wrote {args.json}")
    return 0 if agree else 1


if __name__ == "__main__":
    sys.exit(main())
