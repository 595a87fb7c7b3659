"""Which precise orbits a comma2k19 segment takes from a folder of SP3 files, and the picklable
import step of a batch over raw segments."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from tests.conftest import require_shared
from tests.helpers.precise_text import sp3_text
from vo_doppler.errors import InputError
from vo_doppler.io.comma2k19_import import (
    Comma2k19Import,
    orbits_for_segment,
    segment_gps_span,
)

COMMA = "comma2k19_example1"
SP3 = "Sta20124_1400_1845.sp3"


def write_orbit_day(path, start_gps_s: float, hours: float) -> None:
    t = start_gps_s + 900.0 * np.arange(int(hours * 4) + 1)
    position = np.full((t.size, 1, 3), 2.6e7)
    path.write_text(sp3_text(t, ["G01"], position, np.zeros((t.size, 1))))


@pytest.mark.shared_data
def test_the_folder_file_around_the_segment_is_chosen(tmp_path):
    segment = require_shared(COMMA)
    start, end = segment_gps_span(segment)
    assert end - start == pytest.approx(59.95, abs=0.01)  # 1200 frames at 20 Hz
    (tmp_path / SP3).symlink_to(segment / SP3)
    write_orbit_day(tmp_path / "earlier.SP3", start - 30 * 3600.0, 24.0)
    write_orbit_day(tmp_path / "just_covering.sp3", start - 900.0, 0.5)
    (tmp_path / "notes.txt").write_text("not an orbit file")
    assert orbits_for_segment(segment, tmp_path) == tmp_path / SP3
    assert orbits_for_segment(segment, segment / SP3) == segment / SP3


@pytest.mark.shared_data
def test_a_folder_without_a_covering_file_is_an_error_naming_the_time(tmp_path):
    segment = require_shared(COMMA)
    start, _ = segment_gps_span(segment)
    write_orbit_day(tmp_path / "other_day.sp3", start - 30 * 3600.0, 24.0)
    with pytest.raises(InputError, match=r"no SP3 file covers the segment .*GPS week 2012"):
        orbits_for_segment(segment, tmp_path)
    (tmp_path / "other_day.sp3").unlink()
    with pytest.raises(InputError, match=r"no SP3 files \(\*\.sp3\)"):
        orbits_for_segment(segment, tmp_path)


def test_the_import_step_pickles_and_names_its_orbits(tmp_path):
    step = Comma2k19Import(tmp_path / "orbits")
    assert pickle.loads(pickle.dumps(step)) == step
    assert "orbits" in repr(step)
