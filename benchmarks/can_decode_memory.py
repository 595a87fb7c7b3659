"""Peak memory of decoding a long CAN log: frames held as Python objects for the whole log
(``read_can_log`` then ``decode_motion``) against the streamed decode (``read_can_motion``).

The log is the sample sequence's candump log (38 s) repeated with shifted times to DURATIONS;
peak traced allocations (tracemalloc) per path, alternating, median of 3. Prints a table and
writes ``benchmarks/results/can_decode_memory.json``.
"""

from __future__ import annotations

import json
import statistics
import tempfile
import tracemalloc
from pathlib import Path

from vo_doppler.io.can import (
    SignalRef,
    decode_motion,
    load_dbc,
    parse_signal_list,
    read_can_log,
    read_can_motion,
)

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = ROOT / "sample_sequences" / "urban_canyon_small" / "can"
YAW = "VEHICLE_DYNAMICS.YAW_RATE"
WHEELS = "WHEEL_SPEEDS.WHEEL_SPEED_RL,WHEEL_SPEEDS.WHEEL_SPEED_RR"
DURATIONS = (120.0, 480.0)


def long_log(path: Path, duration_s: float) -> int:
    """The sample log repeated until ``duration_s``; the number of lines written."""
    lines = (SAMPLE / "vehicle.log").read_text().splitlines()
    stamps = [float(line[1 : line.index(")")]) for line in lines]
    span = stamps[-1] - stamps[0] + 0.012
    n = 0
    with path.open("w") as handle:
        shift = 0.0
        while shift < duration_s:
            for stamp, line in zip(stamps, lines, strict=True):
                handle.write(f"({stamp + shift:.6f}){line[line.index(')') + 1 :]}\n")
                n += 1
            shift += span
    return n


def held(path: Path) -> None:
    frames = read_can_log(path)
    decode_motion(
        frames, load_dbc(SAMPLE / "vehicle.dbc"), SignalRef.parse(YAW), parse_signal_list(WHEELS)
    )


def streamed(path: Path) -> None:
    read_can_motion(path, SAMPLE / "vehicle.dbc", YAW, WHEELS)


def peak_mib(function, path: Path) -> float:
    tracemalloc.start()
    function(path)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak / 2**20


def main() -> None:
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for duration in DURATIONS:
            path = Path(folder) / "long.log"
            n = long_log(path, duration)
            runs = {"held": [], "streamed": []}
            for _ in range(3):
                runs["held"].append(peak_mib(held, path))
                runs["streamed"].append(peak_mib(streamed, path))
            row = {"duration_s": duration, "frames": n}
            row |= {f"{k}_peak_mib": statistics.median(v) for k, v in runs.items()}
            row["ratio"] = row["held_peak_mib"] / row["streamed_peak_mib"]
            rows.append(row)
    print(f"{'drive s':>8} {'frames':>8} {'held MiB':>9} {'streamed MiB':>13} {'ratio':>6}")
    for r in rows:
        print(
            f"{r['duration_s']:>8.0f} {r['frames']:>8} {r['held_peak_mib']:>9.1f} "
            f"{r['streamed_peak_mib']:>13.1f} {r['ratio']:>6.1f}"
        )
    out = ROOT / "benchmarks" / "results" / "can_decode_memory.json"
    out.parent.mkdir(exist_ok=True)
    out.write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
