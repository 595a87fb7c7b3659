"""``vo-doppler run`` freezes what is alive before its stages (the cycle collector's full passes
then skip the imported modules) and unfreezes it when it ends, also when it fails: a process
that goes on after the command (these tests, a notebook) keeps collecting its garbage."""

from __future__ import annotations

import gc

import pytest

from vo_doppler import job
from vo_doppler.cli import main
from vo_doppler.errors import EXIT_INTERNAL

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("short_drive")]


def test_the_collector_is_frozen_during_the_stages_and_unfrozen_after(
    short_drive_folder, tmp_path, monkeypatch
):
    drive = short_drive_folder
    frozen_during = []

    def failing_stages(*args, **kwargs):
        frozen_during.append(gc.get_freeze_count())
        raise RuntimeError("stage failed")

    monkeypatch.setattr(job, "run_sequence", failing_stages)  # the one job run and batch run
    assert gc.get_freeze_count() == 0
    assert main(["run", str(drive), "-o", str(tmp_path / "out")]) == EXIT_INTERNAL
    assert frozen_during and frozen_during[0] > 0
    assert gc.get_freeze_count() == 0
