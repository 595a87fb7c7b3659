"""``vo-doppler batch SEQ_DIR... -o OUT``: the main job on many recordings, one aggregate."""

from __future__ import annotations

import argparse
import signal
import sys
from pathlib import Path

from rich.console import Console
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from vo_doppler.batch import Executor, RecordingOutcome, Status, read_list, run_batch
from vo_doppler.choices import values
from vo_doppler.commands.arg_types import positive_int
from vo_doppler.commands.run_command import add_run_options, run_config
from vo_doppler.commands.span_options import add_span_options, time_span
from vo_doppler.errors import InputError
from vo_doppler.io.comma2k19_import import Comma2k19Import
from vo_doppler.report.batch_summary import summary_warnings, warnings_status


def register(subparsers, summary: str) -> None:
    parser = subparsers.add_parser(
        "batch",
        help=summary,
        description="Run what 'vo-doppler run' runs on every recording, writing each one's "
        "outputs into OUT/<name>/, then OUT/batch_summary.csv, .parquet and .html (per "
        "recording and overall: error per 100 m per pipeline when there is ground truth, "
        "heading availability, calibration, the run's warnings). A failed recording is listed "
        "and the others go on (one that fails before its outputs keeps its earlier results in "
        "OUT/<name>/); the exit status is 1 when any failed. --resume skips the recordings an "
        "earlier batch finished with the same inputs and options, unless their last run "
        "failed (a failed_run.log beside earlier results): those run again. --start/--end "
        "run each recording on that part of it, as run does; a recording the span does not "
        "fit fails with run's usage error, the others go on, and the exit status is 2.",
    )
    parser.add_argument(
        "sequences",
        type=Path,
        nargs="*",
        help="sequence folders (or segments: --comma2k19); one named twice (s1 s1/) runs once, "
        "with a warning",
    )
    parser.add_argument(
        "--list",
        type=Path,
        help="file listing sequence folders, one a line ('#' comments; relative to the file's "
        "folder); a folder listed twice runs once, with a warning naming the lines",
    )
    parser.add_argument("-o", "--output", type=Path, required=True, help="output folder")
    parser.add_argument(
        "--executor",
        choices=values(Executor),
        default=Executor.LOCAL.value,
        help="local: a process pool on this machine; ray: Ray tasks "
        "(pip install 'vo-doppler[ray]')",
    )
    parser.add_argument(
        "--workers",
        type=positive_int,
        help="recordings run at once (default: min(CPU cores, recordings); ray on a cluster: "
        "its CPUs)",
    )
    parser.add_argument(
        "--resume",
        action="store_true",
        help="skip recordings already finished in OUT (not those whose last run failed)",
    )
    parser.add_argument(
        "--ray-address",
        help="Ray cluster to use (e.g. ray://head:10001; default: $RAY_ADDRESS, else a local "
        "Ray instance)",
    )
    parser.add_argument(
        "--comma2k19",
        type=Path,
        metavar="ORBITS",
        help="the recordings are raw comma2k19 segments: each is imported first (as 'vo-doppler "
        "import comma2k19' does, into OUT/<name>/prepared) with these SP3 precise orbits: a "
        "file, or a folder of SP3 files from which each segment takes the one around its time",
    )
    add_run_options(parser)
    add_span_options(
        parser,
        "first GNSS epoch of each recording (without GNSS: its first image, else its first "
        "yaw-rate sample)",
    )
    parser.set_defaults(func=run, usage_error=parser.error)


def _terminate(signum, frame) -> None:
    raise KeyboardInterrupt


def run(args: argparse.Namespace) -> int:
    if not args.sequences and args.list is None:
        args.usage_error("no recordings: give sequence folders or --list FILE")
    listed = read_list(args.list) if args.list is not None else {}
    sources = list(args.sequences) + list(listed)
    if not sources:
        raise InputError("the list names no recording (only blank lines and comments)", args.list)
    signal.signal(signal.SIGTERM, _terminate)
    console = Console(width=None if sys.stdout.isatty() else 150)
    columns = (
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TimeElapsedColumn(),
    )
    with Progress(*columns, console=console, transient=True) as progress:
        task = progress.add_task("recordings", total=len({s.resolve() for s in sources}))

        def advance(outcome: RecordingOutcome) -> None:
            progress.advance(task)
            if outcome.status is Status.FAILED:
                progress.console.print(f"[red]{outcome.name} failed[/red]: {outcome.error}")

        result = run_batch(
            sources,
            args.output,
            executor=args.executor,
            workers=args.workers,
            resume=args.resume,
            config=run_config(args),
            prepare=None if args.comma2k19 is None else Comma2k19Import(args.comma2k19.resolve()),
            ray_address=args.ray_address,
            on_outcome=advance,
            listings=listed,
            span=time_span(args),
        )
    console.print(outcome_table(result.outcomes))
    console.print(f"wrote {result.csv}, {result.parquet.name} and {result.html.name}")
    return result.exit_code


def outcome_table(outcomes: list[RecordingOutcome]) -> Table:
    table = Table(title="recordings")
    for column in ("recording", "status", "time [s]", "exit category", "error"):
        table.add_column(column, justify="right" if column == "time [s]" else "left")
    for o in outcomes:
        category = "" if o.category is None else o.category.value
        warnings = len(summary_warnings(o.summary))
        style = "red" if o.status is Status.FAILED else "yellow" if warnings else None
        status = warnings_status(o.status.value, warnings)
        table.add_row(o.name, status, f"{o.seconds:.1f}", category, o.error or "", style=style)
    return table
