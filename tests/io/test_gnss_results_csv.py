"""vel.csv and pos.csv read back as written (what scoring needs), bad rows naming their line."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.velocity import velocity_solution
from vo_doppler.errors import InputError
from vo_doppler.io.gnss_csv import write_spp_csv, write_velocity_csv
from vo_doppler.io.gnss_results_csv import read_position_csv, read_velocity_csv
from vo_doppler.model.gnss_solutions import SppSolution


def test_velocity_csv_reads_back(tmp_path):
    t = 1.2e9 + np.arange(4.0)
    enu = np.array([[1.0, 2.0, 0.1], [3.0, -4.0, 0.0], [np.nan] * 3, [0.5, 0.5, -0.2]])
    valid = np.array([True, True, False, False])
    written = velocity_solution(
        t,
        enu,
        valid,
        verified=np.array([True, True, False, True]),
        speed_sigma_mps=np.full(4, 0.1),
        course_sigma_rad=np.full(4, np.radians(2.0)),
    )
    path = tmp_path / "vel.csv"
    write_velocity_csv(path, written)
    read = read_velocity_csv(path)
    assert read.t == pytest.approx(t)
    assert read.velocity_enu == pytest.approx(enu, nan_ok=True)
    assert read.valid.tolist() == valid.tolist()
    assert read.verified.tolist() == [True, True, False, True]
    assert np.degrees(read.course_sigma_rad) == pytest.approx(np.full(4, 2.0))


def test_position_csv_reads_back(tmp_path):
    t = 1.2e9 + np.arange(3.0)
    ecef = np.array([[-2419239.2, 5385488.3, 2405340.5]] * 3) + np.arange(3.0)[:, None]
    valid = np.array([True, False, True])
    written = SppSolution(
        t,
        ecef,
        {},
        np.full(3, 7),
        np.ones(3),
        np.full(3, 2.0),
        valid,
        0,
        valid,
        np.full(3, 1.5),
        np.full(3, 4.0),
    )
    path = tmp_path / "pos.csv"
    write_spp_csv(path, written)
    read = read_position_csv(path)
    assert read.position_ecef == pytest.approx(ecef, abs=1e-3)
    assert read.valid.tolist() == valid.tolist()
    assert read.hdop == pytest.approx(np.full(3, 1.5))


@pytest.mark.parametrize(
    ("text", "words", "line"),
    [
        ("gps_time_s,ve,vn,vu\n1,0,0,0\n", "no column valid", 1),
        ("gps_time_s,ve,vn,vu,valid\n1,0,0,0,2\n", "valid must be 0 or 1", 2),
        ("gps_time_s,ve,vn,vu,valid\n1,,0,0,1\n", "a valid epoch without a velocity", 2),
        ("gps_time_s,ve,vn,vu,valid\n2,0,0,0,1\n1,0,0,0,1\n", "not after", 3),
        ("gps_time_s,ve,vn,vu,valid\n1,a,0,0,1\n", "ve is not a number", 2),
    ],
)
def test_bad_velocity_rows_name_their_line(tmp_path, text, words, line):
    path = tmp_path / "vel.csv"
    path.write_text(text)
    with pytest.raises(InputError, match=words) as caught:
        read_velocity_csv(path)
    assert caught.value.line == line and caught.value.path == path
