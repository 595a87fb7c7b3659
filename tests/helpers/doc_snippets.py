"""The Python snippets of a Markdown page (the README, docs/*.md), run as written: each as a
script of its own, the page's name in its tracebacks."""

from __future__ import annotations

import re
from pathlib import Path

SNIPPET = re.compile(r"```python\n(.*?)```", re.S)
FILE_NAME = re.compile(r"""["']([\w./-]+\.[A-Za-z]\w*)["']""")


def python_snippets(page: Path) -> list[str]:
    """The code of each ```` ```python ```` block of ``page``, in order."""
    return SNIPPET.findall(page.read_text())


def named_files(code: str) -> list[str]:
    """The file names a snippet gives as string literals (``read_ubx("drive.ubx")``): what must
    exist where it runs."""
    return sorted(set(FILE_NAME.findall(code)))


def run_snippet(code: str, page: str) -> dict[str, object]:
    """Run ``code`` in a fresh namespace as ``page``'s (the name its tracebacks give) from the
    current folder; the names it bound."""
    namespace: dict[str, object] = {}
    exec(compile(code, page, "exec"), namespace)
    return {name: value for name, value in namespace.items() if not name.startswith("__")}
