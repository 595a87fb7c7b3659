"""The ``vo-doppler`` command: parses arguments and hands them to one subcommand module.

Exit codes (:mod:`vo_doppler.errors`): 0 success, 1 bad input or failed processing, 2 usage
error, 3 internal error. Every failure is one line on stderr; ``--debug`` adds the traceback.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import os
import sys
import traceback

from vo_doppler import __version__
from vo_doppler.commands.help_format import OptionsParser
from vo_doppler.errors import (
    EXIT_FAILURE,
    EXIT_INTERNAL,
    EXIT_OK,
    EXIT_USAGE,
    UsageError,
    VoDopplerError,
    shown,
    storage_refused,
)

SUBCOMMANDS: dict[str, tuple[str, str]] = {
    "run": (
        "run_command",
        "VO -> calibration -> tightly coupled heading -> correction on a sequence folder",
    ),
    "vo": ("vo_command", "monocular visual odometry over an image folder"),
    "gnss": ("gnss_command", "GNSS Doppler velocity and positions from RINEX"),
    "heading": ("heading_command", "tightly coupled Doppler-gyro-wheel heading per GNSS epoch"),
    "correct": ("correct_command", "correct a VO trajectory's heading with Doppler headings"),
    "eval": ("eval_command", "trajectory errors against ground truth"),
    "deadreckon": (
        "deadreckon_command",
        "low-cost path mapping: two gyros + GPS dead reckoning and drift table",
    ),
    "simulate": ("simulate_command", "generate a synthetic multi-sensor sequence"),
    "import": ("import_command", "convert a recording (comma2k19 segment) into a sequence folder"),
    "batch": (
        "batch_command",
        "the main job on many sequence folders, in parallel, with one aggregate table",
    ),
    "kitti-speed": (
        "kitti_speed_command",
        "speed CSV from KITTI ground-truth poses (for vo --speed)",
    ),
}
"""Subcommand → (module in ``vo_doppler.commands``, one-line help). A module is imported only
when its subcommand runs, so ``vo-doppler --help`` loads none of the library."""

log = logging.getLogger("vo_doppler")

EXIT_CODES_EPILOG = f"""exit codes:
  {EXIT_OK}  success
  {EXIT_FAILURE}  bad input or failed processing (the message names the file and line, epoch or key)
  {EXIT_USAGE}  usage error (unknown command or option, bad option value, a --start/--end outside
     the recording)
  {EXIT_INTERNAL}  internal error (a bug: rerun with --debug and report the traceback)
"""


def chosen_command(argv: list[str]) -> str | None:
    """The subcommand named on the command line (the first known name), if any."""
    return next((word for word in argv if word in SUBCOMMANDS), None)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser with every subcommand listed; ``command``'s own options are loaded (all of
    them when ``command`` is "*", for documentation and tests)."""
    parser = OptionsParser(
        prog="vo-doppler",
        description="Monocular visual odometry with heading corrected by GNSS Doppler.",
        epilog=EXIT_CODES_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more log output")
    parser.add_argument("-q", "--quiet", action="store_true", help="only warnings and errors")
    parser.add_argument(
        "--debug", action="store_true", help="print the traceback of any error (for bug reports)"
    )
    subparsers = parser.add_subparsers(
        dest="command", metavar="COMMAND", required=True, parser_class=OptionsParser
    )
    for name, (module, summary) in SUBCOMMANDS.items():
        if command in (name, "*"):
            importlib.import_module(f"vo_doppler.commands.{module}").register(subparsers, summary)
        else:
            subparsers.add_parser(name, help=summary, add_help=False)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(chosen_command(argv))
    args = parser.parse_args(argv)
    level = logging.WARNING if args.quiet else (logging.DEBUG if args.verbose else logging.INFO)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    try:
        return int(args.func(args) or EXIT_OK)
    except UsageError as exc:
        _report(args, f"usage error: {exc}")
        return EXIT_USAGE
    except VoDopplerError as exc:
        _report(args, f"error: {exc}")
        return EXIT_FAILURE
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # the top-level handler: anything else is a bug
        if isinstance(exc, OSError) and exc.filename is not None:
            _report(args, f"error: {_refused_file_operation(exc)}")
            return EXIT_FAILURE
        if storage_refused(exc):
            _report(args, f"error: {_refused_storage(args, exc)}")
            return EXIT_FAILURE
        _report(
            args,
            f"internal error: {type(exc).__name__}: {exc} (a bug; rerun with --debug for the "
            "traceback)",
        )
        return EXIT_INTERNAL


def _refused_file_operation(exc: OSError) -> str:
    """The message of a file operation the system refused (a full disk, permissions, a place
    that holds no files such as /proc): the environment, not a bug, so exit 1 naming the file.
    The checks before the work catch most such places; these are the rest."""
    reason = exc.strerror or type(exc).__name__
    other = f" → {exc.filename2}" if exc.filename2 is not None else ""
    return f"{exc.filename}{other}: {reason} (the system refused this file operation)"


OUTPUT_OPTIONS = ("output", "figure", "json")
"""The options that name what a command writes (``eval``'s ``--json`` is a path or a flag)."""


def _refused_storage(args: argparse.Namespace, exc: OSError) -> str:
    """The message of a write the system refused without naming the file (a full disk found
    when a buffered file is flushed): the command's outputs named instead."""
    outputs = [
        str(value)
        for name in OUTPUT_OPTIONS
        if isinstance(value := getattr(args, name, None), str | os.PathLike)
    ]
    where = " / ".join(outputs) or "the output"
    return f"{where}: {exc.strerror} (the system refused to store the results)"


def _report(args: argparse.Namespace, message: str) -> None:
    """One line on stderr (a multi-line message joined by "; "; a name that is not UTF-8 with
    ``\\xff`` escapes), the traceback under ``--debug``."""
    if args.debug:
        traceback.print_exc(file=sys.stderr)
    one_line = "; ".join(part.strip() for part in shown(message).splitlines() if part.strip())
    print(f"vo-doppler {args.command}: {one_line}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
