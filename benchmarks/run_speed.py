"""``vo-doppler run`` as users run it: CPU seconds per second of driving, real-time factor and
peak memory of the whole process (interpreter start, imports, report and figures included).

    python benchmarks/run_speed.py SEQUENCE_DIR [--repeats 3] [--against OTHER_VO_DOPPLER]
        [--json FILE]

Each run is its own process (``vo-doppler -q run SEQUENCE_DIR -o OUT``, a fresh output folder),
measured by the parent with ``wait4``: CPU = user + system time of the process and its threads,
wall = from spawn to exit, peak RSS = ``ru_maxrss``. Driving time is the span of the sequence's
image times (``sequence.yaml``'s duration when it has no camera). Figures are medians over the
repeats. ``--against`` names another build's ``vo-doppler`` executable (e.g. a checkout of the
previous commit with its own virtual environment): the two then alternate within every repeat,
the order swapping each time, so machine load hits both alike, and the table gives the ratios.
The load average before and after each run is recorded (the machine may be shared).
"""

from __future__ import annotations

import argparse
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

from vo_doppler.io.sequence import read_sequence

THIS_BUILD = Path(sys.executable).with_name("vo-doppler")


def driving_seconds(folder: Path) -> float:
    """Seconds of driving the run covers: the span of the image times, else of the GNSS epochs."""
    sequence = read_sequence(folder)
    t = sequence.image_times if sequence.has_camera else sequence.observations.epoch_time
    return float(t[-1] - t[0])


def timed_run(executable: Path, folder: Path, out: Path) -> dict:
    """One whole ``vo-doppler run`` process: its wall and CPU seconds and peak RSS (MiB)."""
    shutil.rmtree(out, ignore_errors=True)
    command = [str(executable), "-q", "run", str(folder), "-o", str(out)]
    load_before = os.getloadavg()[0]
    start = time.perf_counter()
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(process.pid, 0)
    wall = time.perf_counter() - start
    errors = process.stderr.read().decode(errors="replace") if process.stderr else ""
    if os.waitstatus_to_exitcode(status) != 0:
        raise SystemExit(f"{' '.join(command)} failed:\n{errors}")
    return {
        "wall_s": wall,
        "cpu_s": usage.ru_utime + usage.ru_stime,
        "peak_rss_mib": usage.ru_maxrss / 1024.0,
        "load_before": load_before,
        "load_after": os.getloadavg()[0],
    }


def summarise(runs: list[dict], driving_s: float) -> dict:
    cpu = statistics.median(r["cpu_s"] for r in runs)
    wall = statistics.median(r["wall_s"] for r in runs)
    return {
        "median_cpu_s": cpu,
        "median_wall_s": wall,
        "cpu_s_per_driving_s": cpu / driving_s,
        "real_time_factor": driving_s / wall,
        "peak_rss_mib": max(r["peak_rss_mib"] for r in runs),
        "runs": runs,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence", type=Path)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--against", type=Path, help="another build's vo-doppler executable, run alternately"
    )
    parser.add_argument("--json", type=Path, default=Path("benchmarks/results/run_speed.json"))
    args = parser.parse_args(argv)
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    builds = {"this build": THIS_BUILD}
    if args.against is not None:
        builds["--against"] = args.against
    driving_s = driving_seconds(args.sequence)
    console = Console(width=140)
    runs: dict[str, list[dict]] = {name: [] for name in builds}
    with tempfile.TemporaryDirectory(prefix="run_speed_") as scratch:
        for repeat in range(args.repeats):
            order = list(builds.items())
            for index, (name, executable) in enumerate(order[:: 1 if repeat % 2 == 0 else -1]):
                run = timed_run(executable, args.sequence, Path(scratch) / f"out{index}")
                runs[name].append(run)
                console.print(
                    f"repeat {repeat + 1}, {name}: CPU {run['cpu_s']:.1f} s, wall "
                    f"{run['wall_s']:.1f} s, peak RSS {run['peak_rss_mib']:.0f} MiB (load "
                    f"{run['load_before']:.1f} -> {run['load_after']:.1f})"
                )
    results = {name: summarise(group, driving_s) for name, group in runs.items()}
    table = Table(title=f"vo-doppler run on {args.sequence} ({driving_s:.1f} s of driving)")
    columns = (
        "build",
        "CPU-s per s of driving",
        "real-time factor",
        "median CPU [s]",
        "median wall [s]",
        "peak RSS [MiB]",
    )
    for column in columns:
        table.add_column(column, justify="left" if column == "build" else "right")
    for name, figures in results.items():
        table.add_row(
            name,
            f"{figures['cpu_s_per_driving_s']:.3f}",
            f"{figures['real_time_factor']:.2f}x",
            f"{figures['median_cpu_s']:.1f}",
            f"{figures['median_wall_s']:.1f}",
            f"{figures['peak_rss_mib']:.0f}",
        )
    console.print(table)
    report = {
        "sequence": str(args.sequence),
        "driving_s": driving_s,
        "cpu_count": os.cpu_count(),
        "repeats": args.repeats,
        "builds": {name: str(path) for name, path in builds.items()},
        "results": results,
    }
    if args.against is not None:
        ours, other = results["this build"], results["--against"]
        report["cpu_ratio"] = ours["median_cpu_s"] / other["median_cpu_s"]
        report["wall_ratio"] = ours["median_wall_s"] / other["median_wall_s"]
        console.print(
            f"this build / --against: CPU {report['cpu_ratio']:.3f}, wall "
            f"{report['wall_ratio']:.3f}"
        )
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(report, indent=2))
    console.print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
