"""How the main job's peak memory grows with the drive's duration: ``run_memory.py`` on
recordings of several durations, one fresh process each, and the slope between them.

    python benchmarks/run_memory_duration.py SEQ_DIR [SEQ_DIR ...] [--json F]

Recordings of the durations to compare, e.g. simulated ones (``vo-doppler simulate --duration
300 --no-images -o D``; with images the VO stage is measured too, but rendering takes minutes
per minute of drive). Each row is one recording: its duration (the manifest's ``duration_s``,
else the GNSS epochs' span), the whole process's peak RSS and the step where it was reached;
the slope is the least-squares line through the peaks (MiB per second of drive). Prints a table
and writes JSON (with every step of every recording).
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import yaml

HERE = Path(__file__).resolve().parent


def duration_s(sequence: Path) -> float:
    """The recording's duration: the manifest's ``duration_s`` (simulated drives), else the
    span of its GNSS epochs."""
    manifest = yaml.safe_load((sequence / "sequence.yaml").read_text())
    if isinstance(manifest.get("duration_s"), int | float):
        return float(manifest["duration_s"])
    from vo_doppler.io.sequence import read_sequence

    epochs = read_sequence(sequence).observations.epoch_time
    return float(epochs[-1] - epochs[0])


def measure(sequence: Path) -> dict:
    """``run_memory.py``'s record of one recording, from a process of its own."""
    with tempfile.TemporaryDirectory(prefix="run_memory_duration_") as folder:
        record_path = Path(folder) / "record.json"
        subprocess.run(
            [sys.executable, str(HERE / "run_memory.py"), str(sequence), "--json", record_path],
            check=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        return json.loads(record_path.read_text())


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequences", type=Path, nargs="+")
    parser.add_argument("--json", type=Path, default=Path("out/bench/run_memory_duration.json"))
    args = parser.parse_args(argv)
    rows = []
    for sequence in args.sequences:
        record = measure(sequence)
        top = max(record["steps"], key=lambda step: step["peak_rss_mib"])
        rows.append(
            {
                "sequence": str(sequence),
                "duration_s": duration_s(sequence),
                "peak_rss_mib": record["whole_process"]["peak_rss_mib"],
                "peak_step": top["step"],
                "cpu_s": record["whole_process"]["cpu_s"],
                "steps": record["steps"],
            }
        )
    rows.sort(key=lambda row: row["duration_s"])
    print(
        f"{'recording':<28}{'duration [s]':>14}{'peak RSS [MiB]':>16}  {'at step':<18}"
        f"{'CPU [s]':>9}"
    )
    for row in rows:
        print(
            f"{Path(row['sequence']).name:<28}{row['duration_s']:>14.0f}"
            f"{row['peak_rss_mib']:>16.1f}  {row['peak_step']:<18}{row['cpu_s']:>9.1f}"
        )
    durations = np.array([row["duration_s"] for row in rows])
    peaks = np.array([row["peak_rss_mib"] for row in rows])
    slope = float(np.polyfit(durations, peaks, 1)[0]) if np.unique(durations).size > 1 else None
    if slope is not None:
        print(f"slope: {slope:.4f} MiB per second of drive ({slope * 1800:.0f} MiB per 30 min)")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps({"recordings": rows, "slope_mib_per_s": slope}, indent=2))
    print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
