"""vel.csv and pos.csv as text: the columns, each value's format, degrees for people, empty cells
for what is unknown, and the ENU columns about the median valid fix."""

from __future__ import annotations

import csv
from dataclasses import replace

import numpy as np

from tests.helpers.velocity import velocity_solution
from vo_doppler.geo import EnuFrame, geodetic_to_ecef
from vo_doppler.io.gnss_csv import SPP_COLUMNS, VELOCITY_COLUMNS, write_spp_csv, write_velocity_csv
from vo_doppler.model.gnss_solutions import SppSolution


def _rows(path) -> list[dict[str, str]]:
    with open(path, newline="") as handle:
        return list(csv.DictReader(handle))


def test_a_velocity_row_in_its_units_and_formats(tmp_path):
    solution = velocity_solution(
        np.array([1.2e9 + 0.05, 1.2e9 + 0.1]),
        np.array([[-3.0, 4.0, 0.12345], [np.nan, np.nan, np.nan]]),
        np.array([True, False]),
        verified=np.array([True, False]),
        speed_sigma_mps=np.array([0.05, np.nan]),
        course_sigma_rad=np.radians([1.5, np.nan]),
        horizontal_protection_mps=np.array([0.75, np.nan]),
    )
    solution = replace(solution, dop=np.array([[3.0, 2.5, 1.25, 2.0, 1.0]] * 2))
    path = tmp_path / "out" / "vel.csv"
    write_velocity_csv(path, solution)
    lines = path.read_text().splitlines()
    assert lines[0] == ",".join(VELOCITY_COLUMNS)
    assert lines[1] == (
        "1200000000.050,-3.0000,4.0000,0.1235,5.0000,323.13,0.0000,8,0.0500,1,1,0.0500,"
        "1.500,2.50,1.25,0.750"
    )
    row = _rows(path)[1]  # unsolved: empty numbers, not valid
    assert [row[c] for c in ("ve", "speed_mps", "course_deg", "hpl_mps")] == ["", "", "", ""]
    assert (row["valid"], row["verified"], row["n_sat"]) == ("0", "0", "8")


def test_positions_in_degrees_ecef_and_enu_about_the_median_valid_fix(tmp_path):
    lat, lon = np.radians(35.0), np.radians(139.0)
    origin = geodetic_to_ecef(lat, lon, 50.0)
    frame = EnuFrame(lat, lon, 50.0)
    # three valid fixes 0, 10 and 20 m east, the middle one the median; one invalid 500 m north
    ecef = frame.enu_to_ecef(np.array([[0.0, 0, 0], [10.0, 0, 0], [20.0, 0, 0], [0, 500.0, 0]]))
    n = 4
    solution = SppSolution(
        t=1.2e9 + np.arange(n, dtype=float),
        position_ecef=ecef,
        clock_bias_m={"G": np.zeros(n)},
        n_sat=np.full(n, 7),
        residual_rms_m=np.full(n, 1.5),
        pdop=np.full(n, 1.8),
        valid=np.array([True, True, True, False]),
        n_no_ephemeris=0,
        verified=np.array([True, True, True, True]),
        hdop=np.full(n, 0.9),
        horizontal_sigma_m=np.full(n, 2.0),
    )
    path = tmp_path / "pos.csv"
    write_spp_csv(path, solution)
    assert path.read_text().splitlines()[0] == ",".join(SPP_COLUMNS)
    rows = _rows(path)
    assert (rows[0]["lat_deg"], rows[0]["lon_deg"], rows[0]["height_m"]) == (
        "35.000000000",
        "139.000000000",
        "50.000",
    )
    assert float(rows[0]["x_m"]) == round(origin[0], 3)
    east = [float(r["e_m"]) for r in rows]
    np.testing.assert_allclose(east, [-10.0, 0.0, 10.0, -10.0], atol=2e-3)
    assert abs(float(rows[3]["n_m"]) - 500.0) < 2e-3
    assert [r["valid"] for r in rows] == ["1", "1", "1", "0"]
    assert rows[0]["vertical_sigma_m"] == rows[0]["hpl_m"] == rows[0]["vpl_m"] == ""
    # no valid fix: no ENU origin, the ENU cells empty
    write_spp_csv(path, replace(solution, valid=np.zeros(n, dtype=bool)))
    assert all(r["e_m"] == r["n_m"] == r["u_m"] == "" for r in _rows(path))
