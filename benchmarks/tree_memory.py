"""The memory a command needs from the machine, counted over every process it starts.

    python benchmarks/tree_memory.py [--interval S] [--json F] -- COMMAND [ARG ...]

``/usr/bin/time -v`` reports the largest resident set of a single process. A job that hands
part of its work to a child process can look smaller that way while the machine needs more, so
this samples the command's whole process tree every ``--interval`` seconds and reports the peak
of the **summed proportional set size** (``Pss`` of ``/proc/PID/smaps_rollup``: a page shared by
n processes counts 1/n in each, so the sum is what the tree occupies), next to the peak of the
summed resident sets (shared pages counted in every process) and the largest single process's
peak (``ru_maxrss`` of the children, what ``time -v`` prints). Sampling can miss a peak shorter
than the interval; the single-process figure cannot. Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path


def _children(pid: int) -> list[int]:
    found: list[int] = []
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return found
    for task in tasks:
        try:
            with open(f"/proc/{pid}/task/{task}/children") as children:
                found += [int(child) for child in children.read().split()]
        except OSError:
            continue
    return found


def _tree(root: int) -> list[int]:
    pids, todo = [], [root]
    while todo:
        pid = todo.pop()
        pids.append(pid)
        todo += _children(pid)
    return pids


def _rollup_kib(pid: int) -> tuple[int, int]:
    """(Rss, Pss) of one process in KiB; (0, 0) once it has gone."""
    rss = pss = 0
    try:
        with open(f"/proc/{pid}/smaps_rollup") as rollup:
            for line in rollup:
                if line.startswith("Rss:"):
                    rss = int(line.split()[1])
                elif line.startswith("Pss:"):
                    pss = int(line.split()[1])
    except OSError:
        return 0, 0
    return rss, pss


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--interval", type=float, default=0.1)
    parser.add_argument("--json", type=Path, default=Path("out/bench/tree_memory.json"))
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args(argv)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no command given")
    start = time.monotonic()
    process = subprocess.Popen(command)
    peak_pss = peak_rss = 0
    most_processes = 1
    while process.poll() is None:
        pids = _tree(process.pid)
        sizes = [_rollup_kib(pid) for pid in pids]
        peak_rss = max(peak_rss, sum(rss for rss, _ in sizes))
        peak_pss = max(peak_pss, sum(pss for _, pss in sizes))
        most_processes = max(most_processes, sum(1 for rss, _ in sizes if rss))
        time.sleep(args.interval)
    wall = time.monotonic() - start
    largest = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    record = {
        "command": command,
        "exit_code": process.returncode,
        "wall_s": wall,
        "interval_s": args.interval,
        "peak_tree_pss_mib": peak_pss / 1024.0,
        "peak_tree_rss_mib": peak_rss / 1024.0,
        "largest_process_peak_rss_mib": largest / 1024.0,
        "most_processes": most_processes,
    }
    print(f"{'command':<22}{' '.join(command)}")
    print(f"{'exit code':<22}{process.returncode}")
    print(f"{'wall time [s]':<22}{wall:.1f}")
    print(f"{'processes (at most)':<22}{most_processes}")
    print(f"{'tree PSS peak':<22}{peak_pss / 1024.0:.1f} MiB ({peak_pss * 1.024e-3:.1f} MB)")
    print(f"{'tree RSS peak':<22}{peak_rss / 1024.0:.1f} MiB")
    print(f"{'largest process':<22}{largest / 1024.0:.1f} MiB (time -v's maximum resident set)")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(record, indent=2))
    print(f"wrote {args.json}")
    return process.returncode


if __name__ == "__main__":
    sys.exit(main())
