"""Reading a candump log whose lines are unreadable: time against the number of lines.

Linear-time recovery means the time per line stays flat as the log grows; the reader before
(re-scanning the rest of the text after every bad line) grew quadratically (40k lines: 22 s).
Prints a table and writes ``benchmarks/results/can_bad_lines.json``. Medians of 3 runs.
"""

from __future__ import annotations

import json
import statistics
import tempfile
import time
from pathlib import Path

from vo_doppler.io.can import read_can_log

SIZES = (5_000, 10_000, 20_000, 40_000)
GOOD = "(1600000000.{:06d}) can0 1A0#0400010006000000\n"
BAD = "(1600000000.{:06d}) can0 1A0#ZZ\n"


def write_log(path: Path, n: int) -> None:
    """Every other line unreadable (a bad hex payload)."""
    path.write_text("".join((GOOD if i % 2 else BAD).format(i) for i in range(n)))


def main() -> None:
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for n in SIZES:
            path = Path(folder) / f"bad_{n}.log"
            write_log(path, n)
            times = []
            for _ in range(3):
                start = time.perf_counter()
                frames = read_can_log(path)
                times.append(time.perf_counter() - start)
            assert frames.n_unreadable == n // 2
            median = statistics.median(times)
            rows.append({"lines": n, "seconds": median, "us_per_line": 1e6 * median / n})
    print(f"{'lines':>8} {'s':>8} {'µs/line':>9}")
    for row in rows:
        print(f"{row['lines']:>8} {row['seconds']:>8.3f} {row['us_per_line']:>9.1f}")
    out = Path(__file__).parent / "results" / "can_bad_lines.json"
    out.parent.mkdir(exist_ok=True)
    out.write_text(json.dumps(rows, indent=2))


if __name__ == "__main__":
    main()
