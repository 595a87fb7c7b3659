"""An output folder written all at once: checked before any work, filled in a temporary folder
beside it, and moved into place only when complete, so a failed run leaves the previous results
untouched and a rerun leaves no stale files."""

from __future__ import annotations

import os
import shutil
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from vo_doppler.errors import OutputError


def check_output_folder(path: str | Path) -> Path:
    """``path`` when it can become the output folder: not an existing file, and its nearest
    existing ancestor (or itself) a writable folder; an :class:`OutputError` otherwise."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise OutputError(f"{path}: the output exists and is not a folder")
    ancestor = path.absolute()
    while not ancestor.exists():
        ancestor = ancestor.parent
    if not ancestor.is_dir():
        raise OutputError(f"{path}: {ancestor} is not a folder")
    if not os.access(ancestor, os.W_OK | os.X_OK) or (
        path.exists() and not os.access(path.absolute().parent, os.W_OK | os.X_OK)
    ):
        raise OutputError(f"{path}: no permission to write there")
    return path


@contextmanager
def staged_output(path: str | Path) -> Iterator[Path]:
    """A temporary folder beside ``path`` to write into; on normal exit it replaces ``path``
    (the previous folder is removed), on an exception it is removed and ``path`` is unchanged."""
    path = check_output_folder(path).absolute()
    path.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{path.name}.partial-", dir=path.parent))
    try:
        yield staging
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    previous = None
    if path.exists():
        previous = Path(tempfile.mkdtemp(prefix=f".{path.name}.old-", dir=path.parent))
        previous.rmdir()
        path.rename(previous)
    staging.rename(path)
    if previous is not None:
        shutil.rmtree(previous, ignore_errors=True)


def untouched(path: str | Path) -> str:
    """What a failed run left at ``path``: the sentence for its message."""
    state = "left as it was" if Path(path).exists() else "not created"
    return f"nothing written: {path} {state}"
