"""The files of ``deadreckon`` written from one chain run on the generated two-gyro record: each
equal to the result it comes from (the trajectory, the GeoJSON lines and points, the drift
table, the summary in degrees), and longitude/latitude of ENU points on a hand-worked case."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
from matplotlib.image import imread

from tests.helpers.images import distinct_colours
from vo_doppler.geo import WGS84_A, WGS84_F, EnuFrame
from vo_doppler.io.trajectory import read_tum
from vo_doppler.lowcost.drift import VARIANTS
from vo_doppler.lowcost.pipeline import run_deadreckon
from vo_doppler.report.deadreckon import (
    DRIFT_COLUMNS,
    enu_to_lonlat,
    output_files,
    write_outputs,
)
from vo_doppler.sim.two_gyro import TwoGyroSpec, generate_two_gyro


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    record = generate_two_gyro(TwoGyroSpec())
    result = run_deadreckon(record.gyro1, record.gyro2, record.gps)
    folder = tmp_path_factory.mktemp("deadreckon") / "out"
    return result, write_outputs(folder, result)


def test_enu_points_become_longitude_then_latitude():
    lat0, lon0 = np.radians(35.0), np.radians(139.0)
    frame = EnuFrame(lat0, lon0, 0.0)
    # 100 m north: the meridian's radius of curvature M; 100 m east: the prime vertical's N,
    # and the tangent plane's east leaves the parallel toward the equator by (d/N)²·tan φ / 2
    e2 = WGS84_F * (2.0 - WGS84_F)
    w = 1.0 - e2 * np.sin(lat0) ** 2
    meridian, prime = WGS84_A * (1.0 - e2) / w**1.5, WGS84_A / np.sqrt(w)
    got = enu_to_lonlat(frame, np.array([0.0, 0.0, 100.0]), np.array([0.0, 100.0, 0.0]))
    expected = [
        [139.0, 35.0],
        [139.0, 35.0 + np.degrees(100.0 / meridian)],
        [
            139.0 + np.degrees(100.0 / (prime * np.cos(lat0))),
            35.0 - np.degrees((100.0 / prime) ** 2 * np.tan(lat0) / 2.0),
        ],
    ]
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-10)  # 0.01 mm


def test_every_file_is_written_and_the_trajectory_is_the_selected_one(written):
    result, paths = written
    assert paths == output_files(paths["map"].parent)
    assert sorted(p.name for p in paths["map"].parent.iterdir() if not p.name.startswith(".")) == (
        sorted(p.name for p in paths.values())
    )
    dr = result.selected_trajectory
    trajectory = read_tum(paths["trajectory"])
    np.testing.assert_allclose(trajectory.t, dr.t, rtol=0, atol=1e-6)
    np.testing.assert_allclose(trajectory.positions[:, 0], dr.east, atol=1e-6)
    np.testing.assert_allclose(trajectory.positions[:, 1], dr.north, atol=1e-6)
    np.testing.assert_array_equal(trajectory.positions[:, 2], 0.0)
    np.testing.assert_allclose(np.unwrap(trajectory.yaw()), np.unwrap(dr.yaw), atol=1e-6)


def test_the_geojson_holds_the_dead_reckoning_the_gps_track_and_both_ends(written):
    result, paths = written
    frame, dr = result.prepared.frame, result.selected_trajectory
    features = json.loads(paths["geojson"].read_text())["features"]
    line, gps, start, end = features
    assert line["properties"] == {"name": "dead reckoning", "variant": result.selected}
    np.testing.assert_allclose(
        line["geometry"]["coordinates"], enu_to_lonlat(frame, dr.east, dr.north), atol=1e-9
    )
    track = result.prepared.track_enu
    assert gps["properties"] == {"name": "reconstructed GPS track"}
    np.testing.assert_allclose(
        gps["geometry"]["coordinates"], enu_to_lonlat(frame, track[:, 0], track[:, 1]), atol=1e-9
    )
    assert (start["geometry"]["type"], end["geometry"]["type"]) == ("Point", "Point")
    assert start["geometry"]["coordinates"] == line["geometry"]["coordinates"][0]
    assert end["geometry"]["coordinates"] == line["geometry"]["coordinates"][-1]
    assert (start["properties"]["t"], end["properties"]["t"]) == (dr.t[0], dr.t[-1])


def test_the_drift_table_has_one_row_per_variant_of_the_results_figures(written):
    result, paths = written
    with paths["drift_table"].open() as handle:
        rows = list(csv.reader(handle))
    assert tuple(rows[0]) == DRIFT_COLUMNS
    assert [r[0] for r in rows[1:]] == list(VARIANTS) == [r.variant for r in result.rows]
    for text, row in zip(rows[1:], result.rows, strict=True):
        values = [float(v) for v in text[1:]]
        expected = [
            row.drift_deg_per_min,
            row.final_heading_error_deg,
            row.gap.gap_m,
            row.gap.percent,
            row.gap.end_error_m,
            row.gap.end_error_percent,
            row.gap.length_m,
        ]
        np.testing.assert_allclose(values, expected, rtol=0, atol=1e-3)


def test_the_summary_gives_rates_in_degrees_per_second(written):
    result, paths = written
    summary = json.loads(paths["summary"].read_text())
    model = result.model
    assert summary["k_used"] == model.k and summary["tau_s"] == model.tau
    assert summary["threshold_deg_per_s"] == pytest.approx(np.degrees(model.h), rel=1e-12)
    assert summary["eps0_deg_per_s"] == pytest.approx(
        {name: np.degrees(v) for name, v in model.eps0.items()}, rel=1e-12
    )
    assert summary["selected_variant"] == result.selected
    assert summary["route_closes"] is True
    assert summary["origin_lat_lon_deg"] == pytest.approx(
        [np.degrees(result.prepared.frame.lat_rad), np.degrees(result.prepared.frame.lon_rad)]
    )
    assert summary["gps_kept_fixes"] == len(result.prepared.track.kept)


def test_the_figures_are_pictures(written):
    _, paths = written
    for name in ("map", "allan"):
        pixels = imread(paths[name])
        assert pixels.shape[0] > 200 and pixels.shape[1] > 200, name
        assert distinct_colours(pixels) > 10, name
