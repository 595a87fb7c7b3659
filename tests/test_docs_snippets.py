"""The Python snippets of docs/*.md run as written, each from a folder holding the files it
names (the README's: tests/test_readme.py)."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from tests.conftest import REPO_ROOT, require_shared
from tests.fuzz.gnss_families import ubx_seed
from tests.helpers.doc_snippets import named_files, python_snippets, run_snippet

PAGES = sorted((REPO_ROOT / "docs").glob("*.md"))
SNIPPETS = [(page, code) for page in PAGES for code in python_snippets(page)]


def _ubx_log(path: Path) -> None:
    """The first epochs of the Yamatogawa u-blox walk as the UBX log it came from (RXM-RAWX,
    RXM-SFRBX, NAV-PVT), as the fuzz families write it."""
    require_shared("yamatogawa_ublox_walk/yamatogawa_rover.obs")
    require_shared("yamatogawa_ublox_walk/brdc0060.10n")
    path.write_bytes(ubx_seed())


MAKERS: dict[str, Callable[[Path], None]] = {"drive.ubx": _ubx_log}
"""How to write each file a snippet names, by its name."""


def test_the_docs_have_python_snippets():
    assert SNIPPETS


@pytest.mark.shared_data
@pytest.mark.parametrize(
    ("page", "code"),
    SNIPPETS,
    ids=[f"{page.stem}{k}" for k, (page, _) in enumerate(SNIPPETS)],
)
def test_doc_snippet_runs_as_written(page, code, tmp_path, monkeypatch):
    """Every name the snippet binds holds something (a reader that returned None for a part
    the page promises would pass a bare run)."""
    for name in named_files(code):
        assert name in MAKERS, f"{page.name} names {name}: add its maker to MAKERS"
        MAKERS[name](tmp_path / name)
    monkeypatch.chdir(tmp_path)
    bound = run_snippet(code, str(page.relative_to(REPO_ROOT)))
    assert bound
    assert [name for name, value in bound.items() if value is None] == []
