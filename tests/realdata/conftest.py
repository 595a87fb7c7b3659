"""Real recordings whose GNSS stage several test files use, each built once per test process:
the tests sharing one carry its ``xdist_group`` mark, so that one worker builds it once for
all of them (tests/conftest.py)."""

from __future__ import annotations

import logging

import pytest

from benchmarks.real_sequences import HK_TST_CANYON, write_sequence
from tests.conftest import require_shared
from tests.helpers.comma2k19 import imported_comma2k19
from vo_doppler.gnss.pipeline import GnssVelocityResult
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.sequence import Sequence
from vo_doppler.run_stages import RunConfig, sequence_gnss


@pytest.fixture(scope="session")
def hk_canyon(tmp_path_factory) -> tuple[Sequence, GnssVelocityResult]:
    """The Hong Kong canyon drive as a sequence (vehicle signals synthesised from its
    reference by benchmarks/real_sequences.py) and its GNSS stage as ``run`` does it (SPP
    fixes included), group ``hk_canyon``. Read-only."""
    require_shared(HK_TST_CANYON.folder)
    folder = write_sequence(HK_TST_CANYON, require_shared("."), tmp_path_factory.mktemp("hk"))
    sequence = read_sequence(folder)
    logging.disable(logging.WARNING)
    try:
        return sequence, sequence_gnss(sequence, RunConfig())
    finally:
        logging.disable(logging.NOTSET)


@pytest.fixture(scope="session")
def comma2k19_sequence(tmp_path_factory) -> Sequence:
    """``vo-doppler import comma2k19`` of the minute with its precise orbits, read back, group
    ``comma2k19``. Read-only."""
    return imported_comma2k19(tmp_path_factory)


@pytest.fixture(scope="session")
def comma2k19_gnss(comma2k19_sequence) -> GnssVelocityResult:
    """The GNSS stage of :func:`comma2k19_sequence` as ``run`` does it, group ``comma2k19``.
    Read-only."""
    return sequence_gnss(comma2k19_sequence, RunConfig())
