"""The ``xdist_group`` marks keep a group's tests on one pytest-xdist worker under
``--dist loadgroup`` (tests/conftest.py's :class:`MarkGroupScheduling`): the groups as the
marks name them, one work unit per group and one per module's unmarked tests, the units with
slow tests queued first, and a real run of a small suite on two workers. pytest-xdist 3.8's
own loadgroup stopped grouping under pytest 9.2 without any test failing."""

from __future__ import annotations

import os
import re
from collections import defaultdict
from dataclasses import dataclass, field
from types import SimpleNamespace

import pytest

from tests.conftest import (
    GROUPS_DIR_KEY,
    REPO_ROOT,
    MarkGroupScheduling,
    pytest_collection_modifyitems,
    xdist_group_of,
)

MARKED = """
import pytest

pytestmark = pytest.mark.xdist_group("drive")


def test_a():
    pass


@pytest.mark.parametrize("i", range(2))
def test_b(i):
    pass


@pytest.mark.xdist_group(name="sample")
def test_both():
    pass
"""

MIXED = """
import pytest


@pytest.mark.xdist_group("drive")
def test_c():
    pass


@pytest.mark.parametrize("i", range(3))
def test_free(i):
    pass
"""

GROUPS = {
    "test_marked.py::test_a": "drive",
    "test_marked.py::test_b[0]": "drive",
    "test_marked.py::test_b[1]": "drive",
    "test_marked.py::test_both": "drive_sample",
    "test_mixed.py::test_c": "drive",
    "test_mixed.py::test_free[0]": None,
    "test_mixed.py::test_free[1]": None,
    "test_mixed.py::test_free[2]": None,
}
"""The small suite's tests and their groups (None: unmarked)."""


@dataclass(eq=False)
class Worker:
    """As much of pytest-xdist's ``WorkerController`` as the scheduler uses: its id, the
    indices of the tests it was sent, and whether it was told to shut down."""

    gateway: SimpleNamespace
    sent: list[int] = field(default_factory=list)
    shutting_down: bool = False

    def send_runtest_some(self, indices: list[int]) -> None:
        self.sent.extend(indices)

    def shutdown(self) -> None:
        self.shutting_down = True


SLOW = """
import pytest


@pytest.mark.slow
def test_slow():
    pass
"""


def collect(pytester: pytest.Pytester, **files: str) -> list[pytest.Item]:
    """The small suite's items (and those of ``files``), collected in this process. Without
    Hypothesis's plugin, which would import Hypothesis anew for each collection when this
    process has not (3 s)."""
    pytester.makepyfile(test_marked=MARKED, test_mixed=MIXED, **files)
    pytester.makeini("[pytest]\nmarkers =\n    slow: a slow test\n")
    items, _ = pytester.inline_genitems("-p", "no:hypothesispytest")
    return items


def schedule(pytester, tmp_path, items, workers: int) -> tuple[MarkGroupScheduling, list[Worker]]:
    """A scheduler fed as the controller feeds it by ``workers`` workers that collected
    ``items`` and wrote their groups, after its first distribution."""
    nodeids = [item.nodeid for item in items]
    nodes = [Worker(SimpleNamespace(id=f"gw{n}")) for n in range(workers)]
    scheduler = MarkGroupScheduling(
        pytester.parseconfig("--tx", f"{workers}*popen"), None, tmp_path
    )
    for node in nodes:
        config = SimpleNamespace(
            workerinput={GROUPS_DIR_KEY: str(tmp_path), "workerid": node.gateway.id}
        )
        pytest_collection_modifyitems(config, items)
        scheduler.add_node(node)
        scheduler.add_node_collection(node, nodeids)
    scheduler.schedule()
    return scheduler, nodes


def test_the_marks_name_the_groups(pytester):
    items = collect(pytester)
    assert {item.nodeid: xdist_group_of(item) for item in items} == GROUPS


def test_a_group_is_one_work_unit_on_one_worker(pytester, tmp_path):
    """Each worker writes its collection's groups, the scheduler reads them: the tests of group
    ``drive`` from both files share one scope and go to one worker, the unmarked tests of a
    module share their module's scope."""
    items = collect(pytester)
    nodeids = [item.nodeid for item in items]
    scheduler, workers = schedule(pytester, tmp_path, items, 2)

    scopes = {nodeid: scheduler._split_scope(nodeid) for nodeid in nodeids}
    drive = [nodeid for nodeid, group in GROUPS.items() if group == "drive"]
    free = [nodeid for nodeid, group in GROUPS.items() if group is None]
    assert {scopes[nodeid] for nodeid in drive} == {"drive"}
    assert [scopes[nodeid] for nodeid in free] == ["test_mixed.py"] * 3
    sent = [{nodeids[index] for index in worker.sent} for worker in workers]
    assert [set(drive) <= tests for tests in sent].count(True) == 1
    assert [set(free) <= tests for tests in sent].count(True) == 1


def test_units_with_slow_tests_are_queued_first(pytester, tmp_path):
    """The worker takes the largest unit (``drive``: 4 tests); of the units left, test_slow.py
    with its slow test is queued before test_mixed.py (3 tests) and ``drive_sample`` (1 test,
    first in the collection), as pytest-xdist would not."""
    items = collect(pytester, test_slow=SLOW)
    scheduler, (worker,) = schedule(pytester, tmp_path, items, 1)
    assert list(scheduler.assigned_work[worker]) == ["drive"]
    assert list(scheduler.workqueue) == ["test_slow.py", "test_mixed.py", "drive_sample"]


@pytest.mark.slow
def test_two_workers_run_each_group_on_one(pytester, monkeypatch):
    """``pytest -n 2 --dist loadgroup`` with this project's conftest as a plugin, on eight
    tests of one group over two files and eight unmarked ones: the group's tests all ran on
    one worker (ungrouped, the first two tests go to two workers)."""
    for name in ("first", "second"):
        pytester.makepyfile(
            **{
                f"test_{name}": f"""
import pytest

pytestmark = pytest.mark.xdist_group("drive")


@pytest.mark.parametrize("i", range(4))
def test_{name}_drive(i):
    pass
"""
            }
        )
    pytester.makepyfile(
        test_free="""
import pytest


@pytest.mark.parametrize("i", range(8))
def test_free(i):
    pass
"""
    )
    paths = [str(REPO_ROOT), *os.environ.get("PYTHONPATH", "").split(os.pathsep)]
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join(filter(None, paths)))
    result = pytester.runpytest_subprocess(
        "-n", "2", "--dist", "loadgroup", "-p", "tests.conftest", "-v"
    )
    result.assert_outcomes(passed=16)
    workers: dict[str, set[str]] = defaultdict(set)
    for line in result.outlines:
        ran = re.match(r"\[(gw\d+)\] .*PASSED (\S+)", line)
        if ran:
            workers["drive" if "_drive[" in ran[2] else ran[2]].add(ran[1])
    assert len(workers) == 9
    assert len(workers["drive"]) == 1
