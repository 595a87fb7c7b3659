"""The command line shared by the benchmarks that evaluate sequence folders one by one:
``SCRIPT SEQUENCE_DIR [SEQUENCE_DIR ...] [--json FILE]``, a table per sequence, one JSON."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path

from rich.console import Console

Evaluate = Callable[[Path, Path, Console], dict]
"""(sequence folder, output folder of the JSON, console) → the sequence's figures."""
Show = Callable[[Console, str, dict], None]


def run_sequences(
    description: str,
    default_json: Path,
    evaluate: Evaluate,
    show: Show,
    argv: list[str] | None = None,
    width: int = 160,
) -> int:
    """Parse the arguments, evaluate and show every sequence, write ``{"sequences": …}``."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("sequences", nargs="+", type=Path)
    parser.add_argument("--json", type=Path, default=default_json)
    args = parser.parse_args(argv)
    console = Console(width=width)
    results = {}
    for folder in args.sequences:
        name = folder.resolve().name
        results[name] = evaluate(folder, args.json.parent, console)
        show(console, name, results[name])
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps({"sequences": results}, indent=2))
    console.print(f"wrote {args.json} (figures, if any, beside it)")
    return 0
