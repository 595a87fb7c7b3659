"""Peak resident memory and CPU time of the main job, stage by stage, on one recording.

    python benchmarks/run_memory.py SEQ_DIR [--json F]

One process: imports (what ``vo-doppler run`` imports), reading the sequence, then the stages
of :func:`vo_doppler.run.run_sequence` (GNSS, heading, VO, correction: each stage function of
``vo_doppler.run_stages`` wrapped where it is called, to measure it) and writing the outputs
(report and figures). Before each step the kernel's peak-RSS mark is reset
(``/proc/self/clear_refs``, value 5, Linux ≥ 4.0) and read back after it (``VmHWM``), so every
row is that step's own peak; the whole process's peak is the largest of them (the reset clears
``ru_maxrss`` too). Prints a table and writes JSON. By default the VO runs in this process, so
its row is the VO's own peak; ``--in-child`` runs the GNSS and heading stages and the VO in
forked children and lets the observation rows go after the GNSS stage, as ``vo-doppler run``
does (the rows are then this process's alone, and the stages run in a child have none;
``tree_memory.py`` counts the children too).
"""

from __future__ import annotations

import argparse
import json
import resource
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

STAGES = ("sequence_gnss", "sequence_heading", "sequence_vo", "sequence_trajectories")


def _status_kib(field: str) -> int:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field + ":"):
                return int(line.split()[1])
    raise RuntimeError(f"no {field} in /proc/self/status")


class StageMeter:
    """Peak RSS (MiB), RSS after (MiB) and CPU seconds of each measured step, in order."""

    def __init__(self) -> None:
        self.rows: list[dict] = []

    def measure(self, name: str, function: Callable, *args, **kwargs):
        with open("/proc/self/clear_refs", "w") as refs:
            refs.write("5")
        cpu = time.process_time()
        result = function(*args, **kwargs)
        self.rows.append(
            {
                "step": name,
                "peak_rss_mib": _status_kib("VmHWM") / 1024.0,
                "rss_after_mib": _status_kib("VmRSS") / 1024.0,
                "cpu_s": time.process_time() - cpu,
            }
        )
        return result

    def wrap(self, module, name: str) -> None:
        original = getattr(module, name)

        def measured(*args, **kwargs):
            return self.measure(name, original, *args, **kwargs)

        setattr(module, name, measured)


def _imports():
    import vo_doppler.commands.run_command
    import vo_doppler.run

    return vo_doppler.run


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("sequence", type=Path)
    parser.add_argument("--json", type=Path, default=Path("out/bench/run_memory.json"))
    parser.add_argument(
        "--in-child",
        action="store_true",
        help="run the GNSS and heading stages and the VO in forked child processes and let "
        "the observation rows go after the GNSS stage, as vo-doppler run does; the VO row is "
        "then this process's own memory while it waits, and the GNSS and heading stages have "
        "no row (the children's: benchmarks/tree_memory.py)",
    )
    args = parser.parse_args(argv)
    meter = StageMeter()
    start_mib = _status_kib("VmRSS") / 1024.0
    run_module = meter.measure("imports", _imports)
    import vo_doppler.run_stages
    from vo_doppler.io.sequence import read_manifest, read_sequence_with_report
    from vo_doppler.report.run_outputs import input_warnings, result_checks, write_run_outputs

    for name in STAGES:  # wrapped where it is called: in run.py, in run_stages.py, or both
        for module in (run_module, vo_doppler.run_stages):
            if callable(vars(module).get(name)):
                meter.wrap(module, name)
    sequence, report = meter.measure("read", read_sequence_with_report, args.sequence)
    config = run_module.RunConfig()
    result = run_module.run_sequence(
        sequence, config, in_child=args.in_child, keep_rows=not args.in_child
    )
    warnings = input_warnings(sequence, report)
    checks = result_checks(sequence, report, result, warnings)
    with tempfile.TemporaryDirectory(prefix="run_memory_") as out:
        meter.measure(
            "outputs",
            write_run_outputs,
            sequence,
            result,
            config,
            Path(out),
            checks,
            read_manifest(args.sequence),
        )
    usage = resource.getrusage(resource.RUSAGE_SELF)
    print(f"{args.sequence.name}: interpreter alone {start_mib:.0f} MiB")
    print(f"{'step':<22}{'peak RSS [MiB]':>16}{'RSS after [MiB]':>17}{'CPU [s]':>9}")
    for row in meter.rows:
        print(
            f"{row['step']:<22}{row['peak_rss_mib']:>16.1f}{row['rss_after_mib']:>17.1f}"
            f"{row['cpu_s']:>9.2f}"
        )
    peak = max(row["peak_rss_mib"] for row in meter.rows)
    cpu = usage.ru_utime + usage.ru_stime
    print(f"{'whole process':<22}{peak:>16.1f}{'':>17}{cpu:>9.2f}")
    args.json.parent.mkdir(parents=True, exist_ok=True)
    record = {
        "sequence": str(args.sequence),
        "interpreter_mib": start_mib,
        "steps": meter.rows,
        "whole_process": {"peak_rss_mib": peak, "cpu_s": cpu},
    }
    args.json.write_text(json.dumps(record, indent=2))
    print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
