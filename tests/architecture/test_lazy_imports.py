"""Heavy libraries load when they are used, not on import: the main job's modules load neither
OpenCV nor pycolmap (about 70 MiB resident, needed only by the VO stage on a recording with a
camera) nor matplotlib (about 28 MiB, needed only when a figure is drawn), nor scipy.stats and
filterpy (about 0.4 s of CPU per process; filterpy only serves the Kalman calibration, which is not
the default), nor scipy.optimize and scipy.interpolate (about 24 MiB, needed only by the GNSS and
heading stages, which ``run`` gives a child process of their own: without them the parent holds
24 MiB less through the VO and the outputs), nor python-can and cantools (8 MiB, needed only while
the CAN log is read, which ``run`` does in a child process: ``tests/test_job.py``). Checked in a
fresh interpreter, since this one has them all loaded by other tests."""

from __future__ import annotations

import subprocess
import sys

from tests.conftest import REPO_ROOT
from vo_doppler.report.figure import new_figure

SAMPLE = REPO_ROOT / "sample_sequences" / "urban_canyon_small"

HEAVY = (
    "cv2",
    "pycolmap",
    "matplotlib",
    "scipy.stats",
    "filterpy",
    "scipy.optimize",
    "scipy.interpolate",
    "cantools",
    "can",
)
MAIN_JOB = (
    "vo_doppler.commands.run_command",
    "vo_doppler.run",
    "vo_doppler.report.run_outputs",
    "vo_doppler.job",
    "vo_doppler.batch",
)


def loaded_after_import(modules: tuple[str, ...]) -> list[str]:
    """The ``HEAVY`` libraries in ``sys.modules`` after importing ``modules`` in a new process."""
    code = (
        f"import sys\nfor name in {modules!r}:\n    __import__(name)\n"
        f"print(' '.join(m for m in {HEAVY!r} if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return done.stdout.split()


def test_the_main_job_imports_no_opencv_pycolmap_matplotlib_or_scipy_stats_or_optimize():
    assert loaded_after_import(MAIN_JOB) == []


def test_reading_a_sequence_with_a_camera_loads_no_opencv():
    """The image size is checked against the calibration from the first image's header
    (``io.image_header``): OpenCV loads with the VO, not while the GNSS and heading stages run
    (24 MiB less resident through them)."""
    code = (
        "import sys\nfrom vo_doppler.io.sequence import read_sequence\n"
        f"sequence = read_sequence({str(SAMPLE)!r})\n"
        "print(len(sequence.image_paths), sequence.camera.width, 'cv2' in sys.modules)"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["570", "640", "False"]


def test_the_check_sees_a_heavy_import():
    assert loaded_after_import(("vo_doppler.vo.batch",)) == ["cv2", "pycolmap"]
    assert "scipy.stats" in loaded_after_import(("scipy.stats",))
    assert loaded_after_import(("scipy.interpolate",)) == ["scipy.optimize", "scipy.interpolate"]
    assert loaded_after_import(("vo_doppler.io.can",)) == ["cantools", "can"]


def test_new_figure_draws_with_matplotlib():
    from matplotlib.figure import Figure

    figure = new_figure(figsize=(2.0, 1.5))
    assert isinstance(figure, Figure)
    assert tuple(figure.get_size_inches()) == (2.0, 1.5)
