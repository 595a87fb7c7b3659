"""The README's library snippets run as written, from the repository root."""

from __future__ import annotations

from pathlib import Path

import pytest

import vo_doppler.io.sequence
import vo_doppler.run
from tests.conftest import REPO_ROOT, SAMPLE
from tests.helpers.doc_snippets import python_snippets, run_snippet

SNIPPETS = python_snippets(REPO_ROOT / "README.md")


def test_the_readme_has_library_snippets():
    assert len(SNIPPETS) >= 2


def answer_the_sample_run_from(sample_run, monkeypatch) -> None:
    """Let a snippet's ``run_sequence`` on the bundled sample with the default configuration
    return the test process's run of that very call (``sample_run``, ~30 s saved) instead of
    repeating it; every other call runs. The snippet's ``read_sequence`` still reads the
    sample: only a sequence object it returned for the sample folder, untouched (the same
    object) and run with ``RunConfig()``, is answered."""
    read, run = vo_doppler.io.sequence.read_sequence, vo_doppler.run.run_sequence
    samples = []

    def reading(folder, *args, **kwargs):
        sequence = read(folder, *args, **kwargs)
        if not args and not kwargs and Path(folder).resolve() == SAMPLE.resolve():
            samples.append(sequence)
        return sequence

    def running(sequence, config=None, *args, **kwargs):
        default = (config or vo_doppler.run.RunConfig()) == vo_doppler.run.RunConfig()
        if default and not args and not kwargs and any(sequence is s for s in samples):
            return sample_run.result
        return run(sequence, config, *args, **kwargs)

    monkeypatch.setattr(vo_doppler.io.sequence, "read_sequence", reading)
    monkeypatch.setattr(vo_doppler.run, "run_sequence", running)


@pytest.mark.slow
@pytest.mark.xdist_group("time_origin")
@pytest.mark.parametrize("code", SNIPPETS, ids=[f"snippet{i}" for i in range(len(SNIPPETS))])
def test_snippet_runs_as_written(code, monkeypatch, capsys, request):
    monkeypatch.chdir(REPO_ROOT)
    if "run_sequence(" in code:
        answer_the_sample_run_from(request.getfixturevalue("sample_run"), monkeypatch)
    run_snippet(code, "README.md")
    assert capsys.readouterr().out.strip()
