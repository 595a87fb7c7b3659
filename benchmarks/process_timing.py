"""Whole-process timing for the benchmarks: one child process, measured by the parent with
``wait4`` (CPU = user + system time of the child and its threads, wall = spawn to exit, peak
RSS = ``ru_maxrss``), with the load average before and after (the machine may be shared)."""

from __future__ import annotations

import os
import subprocess
import tempfile
import time


def timed_process(command: list[str]) -> dict:
    """Run ``command`` to its end: its stdout (text), wall and CPU seconds, peak RSS (MiB) and
    the load averages. SystemExit naming the command, with its stderr, when it fails."""
    with tempfile.TemporaryFile() as stdout, tempfile.TemporaryFile() as stderr:
        load_before = os.getloadavg()[0]
        start = time.perf_counter()
        process = subprocess.Popen(command, stdout=stdout, stderr=stderr)
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - start
        process.returncode = os.waitstatus_to_exitcode(status)
        stdout.seek(0)
        stderr.seek(0)
        if process.returncode != 0:
            message = stderr.read().decode(errors="replace")
            raise SystemExit(f"{' '.join(command)} failed:\n{message}")
        return {
            "stdout": stdout.read().decode(errors="replace"),
            "wall_s": wall,
            "cpu_s": usage.ru_utime + usage.ru_stime,
            "peak_rss_mib": usage.ru_maxrss / 1024.0,
            "load_before": load_before,
            "load_after": os.getloadavg()[0],
        }
