"""Read time of a RINEX observation file: vo_doppler's vectorised reader against georinex.

    python benchmarks/rinex_read.py [OBS] [--repeats 3] [--json FILE]

Every read is its own process (``benchmarks/rinex_read.py --child READER OBS``), the two
readers alternating within every repeat with the order swapped each time, so machine load hits
both alike. Two statistics, each the same on both sides and each a median over the repeats:
the read alone (``time.perf_counter`` around the reader's call, inside the child) and the whole
process (interpreter start and imports included, wall and CPU measured by the parent with
``wait4``: :mod:`benchmarks.process_timing`). The claim is the ratio of each.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
import warnings
from pathlib import Path

from benchmarks.process_timing import timed_process

ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("VO_DOPPLER_SHARED_DATA", ROOT.parent / "shared" / "data"))
READERS = ("vo_doppler", "georinex")


def read_once(reader: str, path: Path) -> tuple[float, int]:
    """Seconds of one read by ``reader`` and the number of values it gave."""
    if reader == "vo_doppler":
        from vo_doppler.io.rinex_obs import read_obs

        start = time.perf_counter()
        n_values = len(read_obs(path))
        return time.perf_counter() - start, n_values
    import georinex

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.perf_counter()
        data = georinex.load(path, useindicators=True)
        seconds = time.perf_counter() - start
    observables = [name for name in data.data_vars if not name.endswith(("lli", "ssi"))]
    return seconds, int(sum(data[name].count() for name in observables))


def measure(path: Path, repeats: int) -> dict[str, list[dict]]:
    runs: dict[str, list[dict]] = {reader: [] for reader in READERS}
    script = str(Path(__file__).resolve())
    for repeat in range(repeats):
        for reader in READERS if repeat % 2 == 0 else READERS[::-1]:
            run = timed_process([sys.executable, script, "--child", reader, str(path)])
            read_s, n_values = json.loads(run.pop("stdout"))
            runs[reader].append({**run, "read_s": read_s, "n_values": n_values})
            print(f"repeat {repeat + 1}/{repeats} {reader}: read {read_s:.3f} s", flush=True)
    return runs


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("obs", nargs="?", default=SHARED / "septentrio_static" / "rover.obs")
    parser.add_argument("--repeats", type=int, default=3, help="runs of each reader (median)")
    parser.add_argument("--json", default=ROOT / "benchmarks" / "results" / "rinex_read.json")
    parser.add_argument("--child", choices=READERS, help=argparse.SUPPRESS)
    args = parser.parse_args()
    path = Path(args.obs)
    if args.child:
        print(json.dumps(read_once(args.child, path)))
        return 0
    runs = measure(path, args.repeats)
    median = {
        reader: {key: statistics.median(r[key] for r in runs[reader]) for key in runs[reader][0]}
        for reader in READERS
    }
    ours, theirs = median["vo_doppler"], median["georinex"]
    print(f"\n{path.name} ({path.stat().st_size / 1e6:.1f} MB), medians of {args.repeats}")
    print(f"{'reader':<12}{'values':>10}{'read s':>10}{'process s':>11}{'process CPU s':>15}")
    for reader in READERS:
        m = median[reader]
        print(
            f"{reader:<12}{m['n_values']:>10.0f}{m['read_s']:>10.3f}{m['wall_s']:>11.2f}"
            f"{m['cpu_s']:>15.2f}"
        )
    ratios = {
        "read": theirs["read_s"] / ours["read_s"],
        "process_wall": theirs["wall_s"] / ours["wall_s"],
        "process_cpu": theirs["cpu_s"] / ours["cpu_s"],
    }
    print(
        f"georinex / vo_doppler: read {ratios['read']:.0f}x, whole process "
        f"{ratios['process_wall']:.0f}x wall, {ratios['process_cpu']:.0f}x CPU"
    )
    out = Path(args.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(
        json.dumps({"file": str(path), "runs": runs, "median": median, "ratios": ratios}, indent=2)
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
