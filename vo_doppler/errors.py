"""Exceptions raised for bad input; each one names where the problem is."""

from __future__ import annotations

from pathlib import Path


class VoDopplerError(Exception):
    """Base class of every error the toolkit raises on purpose."""


class InputError(VoDopplerError):
    """An input file or value is unusable: the message names the file, line or epoch."""

    def __init__(self, message: str, path: str | Path | None = None, line: int | None = None):
        self.path = None if path is None else Path(path)
        self.line = line
        where = ""
        if path is not None:
            where = f"{path}"
            if line is not None:
                where += f":{line}"
            where += ": "
        super().__init__(where + message)
