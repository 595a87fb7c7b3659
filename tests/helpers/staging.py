"""Temporary output folders as a killed run leaves them: created by a process that has ended."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def cut_off_staging(out: Path) -> Path:
    """The staging folder (with a file in it) that a ``run`` into ``out`` made before it was
    killed: made by ``begin_staging`` in a child process, which has ended (and been reaped) on
    return."""
    script = (
        "import sys; from vo_doppler.io.output_folder import RUN, begin_staging; "
        "staging = begin_staging(sys.argv[1], RUN); (staging / 'half.png').write_text('half'); "
        "print(staging)"
    )
    done = subprocess.run(
        [sys.executable, "-c", script, str(out)],
        cwd=REPO_ROOT,
        capture_output=True,
        text=True,
        check=True,
        timeout=120,
    )
    staging = Path(done.stdout.strip())
    assert staging.is_dir() and staging.parent == out.absolute().parent
    return staging
