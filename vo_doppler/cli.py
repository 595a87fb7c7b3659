"""The ``vo-doppler`` command: parses arguments and hands them to one subcommand module.

Exit codes: 0 success, 1 runtime failure (bad input, failed processing), 2 usage error.
"""

from __future__ import annotations

import argparse
import logging
import sys

from vo_doppler import __version__
from vo_doppler.commands import (
    correct_command,
    deadreckon_command,
    eval_command,
    gnss_command,
    heading_command,
    run_command,
    simulate_command,
    vo_command,
)
from vo_doppler.errors import VoDopplerError

SUBCOMMANDS = (
    eval_command,
    deadreckon_command,
    vo_command,
    gnss_command,
    correct_command,
    heading_command,
    simulate_command,
    run_command,
)

log = logging.getLogger("vo_doppler")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="vo-doppler",
        description="Monocular visual odometry with heading corrected by GNSS Doppler.",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="more log output")
    parser.add_argument("-q", "--quiet", action="store_true", help="only warnings and errors")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for module in SUBCOMMANDS:
        module.register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    level = logging.WARNING if args.quiet else (logging.DEBUG if args.verbose else logging.INFO)
    logging.basicConfig(level=level, format="%(levelname)s %(name)s: %(message)s")
    try:
        return int(args.func(args) or 0)
    except VoDopplerError as exc:
        print(f"vo-doppler {args.command}: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
