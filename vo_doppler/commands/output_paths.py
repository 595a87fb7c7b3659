"""Checks of a command's output paths before any work: every output can be written, none is
one of the command's inputs (or another output), so a wrong ``-o`` never overwrites an input
and a command never fails at its very end after minutes of work.

A refused output is an :class:`~vo_doppler.errors.OutputError` (exit code 1, like every
unusable output location), whose message names the output and the input it would replace.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Mapping
from pathlib import Path

from vo_doppler.errors import OutputError

PathLike = str | Path


def _given(paths: Iterable[PathLike | None]) -> list[Path]:
    """The paths actually given (an option left out is None; ``--nav`` is a list)."""
    out = []
    for path in paths:
        if path is None:
            continue
        if isinstance(path, list | tuple):
            out += _given(path)
        else:
            out.append(Path(path))
    return out


def _same(a: Path, b: Path) -> bool:
    """Whether two paths name one file or folder (links and relative spellings resolved)."""
    if a.resolve() == b.resolve():
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_output_files(
    outputs: Mapping[str, PathLike | None], inputs: Iterable[PathLike | None]
) -> None:
    """Raise an :class:`OutputError` unless each of the ``outputs`` (what it is → file; None
    skipped) can be written, is none of the ``inputs`` and no other output. Nothing is
    created: a missing parent folder is made when the file is written."""
    sources = _given(inputs)
    named = [(what, Path(path)) for what, path in outputs.items() if path is not None]
    for i, (what, output) in enumerate(named):
        for source in sources:
            if _same(output, source):
                raise OutputError(
                    f"the {what.replace('_', ' ')} {output} is the input {source}: writing it "
                    "would destroy the input (choose another output path)"
                )
        for other_what, other in named[:i]:
            if _same(output, other):
                raise OutputError(
                    f"the {other_what} and the {what} are the same file {output} (choose "
                    "different paths)"
                )
        _check_writable_file(output)


def _check_writable_file(path: Path) -> None:
    """Raise unless ``path`` can be written as a file: not a folder, its nearest existing
    ancestor a writable folder, the file itself writable when it exists, and a name the file
    system takes. Judged from permissions alone: nothing is created, opened or changed in the
    user's folders (a probe file would show up, however briefly, to whatever watches them,
    and change the folder's modification time)."""
    try:
        _check_permissions(path)
    except OSError as exc:  # e.g. a name too long for the file system
        raise OutputError(f"{path}: cannot write the output ({exc.strerror})") from exc


def _check_permissions(path: Path) -> None:
    if path.is_dir():
        raise OutputError(f"{path}: the output is a folder; give a file name")
    ancestor = path.absolute().parent
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise OutputError(f"{path}: {ancestor} is a file, not a folder")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        raise OutputError(f"{path}: no permission to write in {ancestor}")
    if path.exists() and not os.access(path, os.W_OK):
        raise OutputError(f"{path}: no permission to write the existing file")
