"""The memory a command needs from the machine, counted over every process it starts.

    python benchmarks/tree_memory.py [--interval S] [--json F] [--timeline F] -- COMMAND [ARG ...]

``/usr/bin/time -v`` reports the largest resident set of a single process. A job that hands
part of its work to a child process can look smaller that way while the machine needs more, so
this samples the command's whole process tree every ``--interval`` seconds
(``/proc/PID/smaps_rollup``) and reports the peak of its **footprint**: the command's own
resident set plus the pages private to each of its descendants (``Private_Clean`` +
``Private_Dirty``). A forked child shares the command's pages until it writes one, and those
are counted once, in the command; what the child writes or loads is its own. For a command
without children the footprint is its resident set, what ``time -v`` reports, so the two
arrangements compare on one scale. The summed proportional set size (``Pss``), also reported,
splits a shared library's pages with every other process using it.

The footprint depends on other processes in one way: the pages of a library file are private
to the child that loaded it only while no other process maps the same file. A second run of
the same installation alongside, holding OpenCV and pycolmap, turns the VO child's 46–50 MiB of
their pages into shared ones and lowers the footprint by as much: measure alone. It depends on
the page cache too: where a library's whole file is cached (just installed, or read by other
processes), each page fault maps the cached pages around the one touched as well (the kernel's
fault-around), so the VO child's OpenCV and pycolmap take 96 MiB resident instead of 50 (issue
30, docs/benchmarks.md "Memory"). These are clean file pages, which the kernel takes back
whenever memory is short; the footprint's **clean** part (the command's clean pages and the
children's private clean ones) is reported beside it, and the rest, the **dirty** part, is
what no setting of the cache changes. Also reported: the largest single process's peak
(``ru_maxrss`` of the children, what ``time -v`` prints; never missed between samples).
Prints a table and writes JSON.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

MIB = 1024.0
"""KiB per MiB."""


@dataclass(frozen=True)
class Rollup:
    """One process's memory in KiB (all zero once it has gone)."""

    rss: int = 0
    pss: int = 0
    private: int = 0
    clean: int = 0
    """Clean pages, shared or private."""
    private_clean: int = 0


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
    """``root`` first, then every descendant."""
    pids, todo = [], [root]
    while todo:
        pid = todo.pop(0)
        pids.append(pid)
        todo += _children(pid)
    return pids


def _rollup(pid: int) -> Rollup:
    fields = {}
    try:
        with open(f"/proc/{pid}/smaps_rollup") as rollup:
            for line in rollup:
                name, _, rest = line.partition(":")
                if name in ("Rss", "Pss", "Private_Clean", "Private_Dirty", "Shared_Clean"):
                    fields[name] = int(rest.split()[0])
    except OSError:
        return Rollup()
    private_clean = fields.get("Private_Clean", 0)
    private = private_clean + fields.get("Private_Dirty", 0)
    clean = private_clean + fields.get("Shared_Clean", 0)
    return Rollup(fields.get("Rss", 0), fields.get("Pss", 0), private, clean, private_clean)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--interval", type=float, default=0.1)
    parser.add_argument("--json", type=Path, default=Path("out/bench/tree_memory.json"))
    parser.add_argument(
        "--timeline",
        type=Path,
        help="also write every sample (CSV): seconds, processes, the footprint, the command's "
        "own resident set, the summed PSS and the footprint's clean pages [MiB]",
    )
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args(argv)
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no command given")
    start = time.monotonic()
    process = subprocess.Popen(command)
    samples = []
    while process.poll() is None:
        rollups = [_rollup(pid) for pid in _tree(process.pid)]
        own = rollups[0]
        footprint = own.rss + sum(child.private for child in rollups[1:])
        pss = sum(rollup.pss for rollup in rollups)
        alive = sum(1 for rollup in rollups if rollup.rss)
        clean = own.clean + sum(child.private_clean for child in rollups[1:])
        samples.append((time.monotonic() - start, alive, footprint, own.rss, pss, clean))
        time.sleep(args.interval)
    wall = time.monotonic() - start
    largest = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    peak = max(samples, key=lambda sample: sample[2], default=(0.0, 0, 0, 0, 0, 0))
    dirty = max(samples, key=lambda sample: sample[2] - sample[5], default=peak)
    record = {
        "command": command,
        "exit_code": process.returncode,
        "wall_s": wall,
        "interval_s": args.interval,
        "peak_footprint_mib": peak[2] / MIB,
        "peak_footprint_at_s": peak[0],
        "processes_at_peak": peak[1],
        "clean_at_peak_mib": peak[5] / MIB,
        "peak_dirty_footprint_mib": (dirty[2] - dirty[5]) / MIB,
        "peak_dirty_footprint_at_s": dirty[0],
        "peak_tree_pss_mib": max((s[4] for s in samples), default=0) / MIB,
        "largest_process_peak_rss_mib": largest / MIB,
        "most_processes": max((s[1] for s in samples), default=0),
    }
    rows = [
        ("command", " ".join(command)),
        ("exit code", str(process.returncode)),
        ("wall time [s]", f"{wall:.1f}"),
        ("processes (at most)", str(record["most_processes"])),
        (
            "footprint peak",
            f"{peak[2] / MIB:.1f} MiB ({peak[2] * 1.024e-3:.1f} MB) at {peak[0]:.0f} s, "
            f"{peak[1]} process(es)",
        ),
        ("  of it clean", f"{peak[5] / MIB:.1f} MiB (file pages the kernel can take back)"),
        (
            "dirty footprint peak",
            f"{(dirty[2] - dirty[5]) / MIB:.1f} MiB at {dirty[0]:.0f} s (the footprint less its "
            "clean pages)",
        ),
        ("summed PSS peak", f"{record['peak_tree_pss_mib']:.1f} MiB"),
        ("largest process", f"{largest / MIB:.1f} MiB (time -v's maximum resident set)"),
    ]
    for name, value in rows:
        print(f"{name:<22}{value}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(record, indent=2))
    if args.timeline is not None:
        lines = ["seconds,processes,footprint_mib,command_rss_mib,tree_pss_mib,clean_mib"]
        lines += [
            f"{t:.2f},{count},{foot / MIB:.1f},{own / MIB:.1f},{pss / MIB:.1f},{clean / MIB:.1f}"
            for t, count, foot, own, pss, clean in samples
        ]
        args.timeline.write_text("\n".join(lines) + "\n")
    print(f"wrote {args.json}")
    return process.returncode


if __name__ == "__main__":
    sys.exit(main())
