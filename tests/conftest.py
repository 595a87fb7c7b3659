"""Shared test fixtures: the real recordings folder, skipped cleanly when absent, and the
recordings and runs that several test files use, each built once per test process.

With pytest-xdist every worker builds its own copy of a session fixture: the tests sharing one
carry the same ``xdist_group`` mark (``--dist loadgroup`` in pyproject.toml's ``addopts``), so
that one worker builds it once for all of them; the tests of one module go to one worker too,
so that a module-scoped fixture is built once. The grouping is this file's
:class:`MarkGroupScheduling`: pytest-xdist 3.8's own loadgroup passes the group to the
controller in ``item._nodeid``, which pytest 9.2 no longer reads (pytest-xdist issue 1386), so
its groups were ignored."""

from __future__ import annotations

import collections.abc
import json
import os
import shutil
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import pytest
from xdist.scheduler import LoadScopeScheduling

if TYPE_CHECKING:
    from xdist.remote import Producer
    from xdist.workermanage import WorkerController

    from vo_doppler.model.sequence import Sequence
    from vo_doppler.run import RunResult

pytest_plugins = ["pytester"]
"""Its ``pytester`` fixture runs small suites of their own (tests/test_xdist_groups.py)."""

REPO_ROOT = Path(__file__).resolve().parents[1]
SAMPLE = REPO_ROOT / "sample_sequences" / "urban_canyon_small"
"""The bundled sample: 38 s at 20 Hz with 570 images."""


def shared_data_dir() -> Path:
    return Path(os.environ.get("VO_DOPPLER_SHARED_DATA", REPO_ROOT.parent / "shared" / "data"))


@pytest.fixture(scope="session")
def shared_data() -> Path:
    path = shared_data_dir()
    if not path.is_dir():
        pytest.skip(f"real recordings not found at {path} (set VO_DOPPLER_SHARED_DATA)")
    return path


@pytest.fixture(scope="session")
def turning_drive_folder(tmp_path_factory) -> Path:
    """The 20-s simulated canyon drive without images, with one left turn of 90° (13–16 s), the
    files ``vo-doppler simulate --duration 20 --seed 1 --no-images`` writes (the QA report's
    ``s1``; its reflected signals on, as the command's default): gyro bias 0.3 °/s, wheel scale
    1/1.02, the yaw rate counter-clockwise positive. Built once per test process by the
    simulator's library function, so that stage tests do not depend on the command line; a
    test that changes the recording works on a copy."""
    from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

    defaults = UrbanCanyonConfig()
    config = UrbanCanyonConfig(
        duration_s=20.0, seed=1, render=False, gnss=replace(defaults.gnss, nlos=True)
    )
    folder = tmp_path_factory.mktemp("turning") / "s1"
    simulate_urban_canyon(folder, config)
    return folder


@dataclass(frozen=True)
class SampleRun:
    """The bundled sample as read and its run with the default configuration."""

    sequence: Sequence
    result: RunResult


@pytest.fixture(scope="session")
def sample_run() -> SampleRun:
    """``run_sequence(read_sequence(SAMPLE), RunConfig())``, every stage with the VO (about
    30 s on a quiet core), once per test process: the README's first snippet makes this very
    call and the time-origin test compares it with the shifted sample's run (group
    ``time_origin``). Read-only."""
    from vo_doppler.io.sequence import read_sequence
    from vo_doppler.run import RunConfig, run_sequence

    sequence = read_sequence(SAMPLE)
    return SampleRun(sequence, run_sequence(sequence, RunConfig()))


@pytest.fixture(scope="session")
def drive_1hz_folder(tmp_path_factory) -> Path:
    """The 90-s simulated canyon drive without images and with a 1-Hz receiver (seed 3), built
    once per test process for the time-origin tests of the library and of the commands (group
    ``time_origin``). Read-only: a test that changes the recording works on a copy."""
    from vo_doppler.sim.gnss_observations import GnssSimConfig
    from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

    folder = tmp_path_factory.mktemp("drive_1hz") / "drive"
    config = UrbanCanyonConfig(
        duration_s=90.0, seed=3, render=False, gnss=GnssSimConfig(rate_hz=1.0)
    )
    simulate_urban_canyon(folder, config)
    return folder


@pytest.fixture(scope="session")
def short_drive_folder(tmp_path_factory) -> Path:
    """A 10-s simulated canyon drive with 320×180 images (seed 4), built once per test process
    for the tests that damage a copy of a recording or need one to read (group
    ``short_drive``). Read-only: a test that changes the recording works on a copy."""
    from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

    folder = tmp_path_factory.mktemp("short_drive") / "clean"
    config = UrbanCanyonConfig(duration_s=10.0, seed=4, image_size_px=(320, 180))
    simulate_urban_canyon(folder, config)
    return folder


@pytest.fixture(scope="session")
def short_drive_run(short_drive_folder, tmp_path_factory) -> Path:
    """The folder ``vo-doppler run`` writes for :func:`short_drive_folder` (report.html,
    summary.json, …), once per test process (group ``short_drive``). Read-only."""
    from vo_doppler.cli import main

    out = tmp_path_factory.mktemp("short_drive_run")
    assert main(["run", str(short_drive_folder), "-o", str(out)]) == 0
    return out


def require_shared(relative: str) -> Path:
    """Path of one recording inside the shared data folder, or skip the test."""
    path = shared_data_dir() / relative
    if not path.exists():
        pytest.skip(f"real recording {relative} not found under {shared_data_dir()}")
    return path


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    """Captured output as text the xdist workers can send: a test on file names that are not
    UTF-8 logs them as surrogate escapes, which execnet refuses to serialise (the whole run then
    stops with an internal error); they are shown as backslash escapes instead."""
    outcome = yield
    report = outcome.get_result()
    report.sections = [
        (title, text.encode("utf-8", "backslashreplace").decode("utf-8"))
        for title, text in report.sections
    ]


GROUPS_DIR_KEY = "vo_doppler_xdist_groups_dir"
"""The ``workerinput`` entry naming the folder where each worker writes its tests' groups."""

_groups_dir = pytest.StashKey[Path]()


def xdist_group_of(item: pytest.Item) -> str | None:
    """The item's ``xdist_group`` as pytest-xdist's loadgroup names it (the names of all its
    marks, sorted and joined by ``_``; ``default`` for a mark without one), None when unmarked."""
    names = {
        str(mark.args[0] if mark.args else mark.kwargs.get("name", "default"))
        for mark in item.iter_markers("xdist_group")
    }
    return "_".join(sorted(names)) if names else None


class MarkGroupScheduling(LoadScopeScheduling):
    """``--dist loadgroup``: the tests of one ``xdist_group`` form one work unit, so one worker
    runs them all; every other test is in its module's unit (as ``--dist loadfile``), so that a
    module-scoped fixture is built once (tests/vo/test_odometry.py's rendered drive was built on
    both workers: 9 s each). After the first units, the units with the most tests marked
    ``slow`` go first and the fast ones last, so that the workers end together.

    The controller collects no tests, so it cannot read the marks: each worker writes its
    collection's groups (node id → group) and slow tests to ``<groups_dir>/<worker id>.json``
    before it reports the collection (:func:`pytest_collection_modifyitems`), and the scheduler
    reads that file with the collection."""

    def __init__(self, config: pytest.Config, log: Producer | None, groups_dir: Path) -> None:
        super().__init__(config, log)
        self.groups_dir = groups_dir
        self.groups: dict[str, str] = {}
        self.slow: set[str] = set()

    def add_node_collection(
        self, node: WorkerController, collection: collections.abc.Sequence[str]
    ) -> None:
        """Register the worker's collection and the groups and slow tests it wrote for it."""
        groups_file = self.groups_dir / f"{node.gateway.id}.json"
        written = json.loads(groups_file.read_text(encoding="utf-8"))
        self.groups.update(written["groups"])
        self.slow.update(written["slow"])
        super().add_node_collection(node, collection)

    def _split_scope(self, nodeid: str) -> str:
        """The test's work unit: its group's name, or its module's path when it has none."""
        return self.groups.get(nodeid, nodeid.split("::", 1)[0])

    def schedule(self) -> None:
        """Distribute the first units (the largest, as pytest-xdist does), then queue the rest
        by their number of slow tests, then of tests, both decreasing."""
        super().schedule()
        queued = sorted(
            self.workqueue.items(),
            key=lambda unit: (-sum(nodeid in self.slow for nodeid in unit[1]), -len(unit[1])),
        )
        self.workqueue.clear()
        self.workqueue.update(queued)


@pytest.hookimpl(optionalhook=True)
def pytest_configure_node(node: WorkerController) -> None:
    """Under ``--dist loadgroup``, tell each worker the folder for its groups (one temporary
    folder per run, made with the first worker, removed by :func:`pytest_unconfigure`)."""
    config = node.config
    if config.getvalue("dist") != "loadgroup":
        return
    if _groups_dir not in config.stash:
        config.stash[_groups_dir] = Path(tempfile.mkdtemp(prefix="xdist-groups-"))
    node.workerinput[GROUPS_DIR_KEY] = str(config.stash[_groups_dir])


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """On a worker under ``--dist loadgroup``: write the grouped tests' node ids and groups and
    the node ids of the tests marked ``slow`` for :class:`MarkGroupScheduling`, once the items
    and their ids are final (``trylast``)."""
    workerinput: dict[str, object] | None = getattr(config, "workerinput", None)
    if workerinput is None or GROUPS_DIR_KEY not in workerinput:
        return
    groups = {item.nodeid: group for item in items if (group := xdist_group_of(item))}
    slow = [item.nodeid for item in items if item.get_closest_marker("slow")]
    groups_file = Path(str(workerinput[GROUPS_DIR_KEY])) / f"{workerinput['workerid']}.json"
    groups_file.write_text(json.dumps({"groups": groups, "slow": slow}), encoding="utf-8")


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: Producer) -> MarkGroupScheduling | None:
    """The scheduler for ``--dist loadgroup`` (pytest-xdist's own for every other mode)."""
    if config.getvalue("dist") != "loadgroup":
        return None
    return MarkGroupScheduling(config, log, config.stash[_groups_dir])


def pytest_unconfigure(config: pytest.Config) -> None:
    """Remove the run's folder of worker groups, if it made one."""
    groups_dir = config.stash.get(_groups_dir, None)
    if groups_dir is not None:
        shutil.rmtree(groups_dir, ignore_errors=True)
