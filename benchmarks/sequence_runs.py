"""The command line shared by the benchmarks that evaluate sequence folders one by one:
``SCRIPT SEQUENCE_DIR [SEQUENCE_DIR ...] [--json FILE]``, a table per sequence, one JSON."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path

from rich.console import Console
from rich.progress import Progress

from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.sequence import Sequence
from vo_doppler.run import RunResult, run_sequence

Evaluate = Callable[[Path, Path, Console], dict]
"""(sequence folder, output folder of the JSON, console) → the sequence's figures."""
Show = Callable[[Console, str, dict], None]


def read_with_truth(folder: Path) -> Sequence:
    """The sequence's inputs; a benchmark without ground truth stops with the folder named."""
    inputs = read_sequence(folder)
    if inputs.truth is None:
        raise SystemExit(f"{folder}: no ground truth; the benchmark needs one")
    return inputs


def run_with_progress(inputs: Sequence, console: Console) -> RunResult:
    """``run_sequence`` with the default configuration and a progress bar over the images."""
    with Progress(console=console, transient=True) as progress:
        task = progress.add_task(f"{inputs.name}: VO", total=len(inputs.image_paths))
        return run_sequence(inputs, on_frame=lambda _: progress.advance(task))


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
