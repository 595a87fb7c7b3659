"""``vo-doppler deadreckon`` end to end on a generated record written in the real file formats."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from vo_doppler.cli import main
from vo_doppler.io.trajectory import read_tum
from vo_doppler.lowcost.drift import VARIANTS
from vo_doppler.sim.two_gyro import TwoGyroSpec, generate_two_gyro, write_two_gyro


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("two_gyro")
    record = generate_two_gyro(TwoGyroSpec())
    return record, write_two_gyro(record, folder)


def summary_of(out):
    return json.loads((out / "deadreckon_summary.json").read_text())


def _args(paths, out, *extra):
    return [
        "deadreckon",
        "--gyro1",
        str(paths["gyro1"]),
        "--gyro2",
        str(paths["gyro2"]),
        "--gps",
        str(paths["gps"]),
        "-o",
        str(out),
        *extra,
    ]


@pytest.mark.slow
def test_cli_writes_every_output(inputs, tmp_path, capsys):
    record, paths = inputs
    t0, t1 = record.standstill
    out = tmp_path / "out"
    code = main(_args(paths, out, "--standstill", f"{t0},{t1}", "--k", "1.13", "--downsample", "2"))
    assert code == 0
    printed = capsys.readouterr().out
    assert "combined + ε0" in printed and "k used 1.130" in printed
    assert "does not close" not in printed

    trajectory = read_tum(out / "trajectory.tum")
    n_fixes = len(record.gps[0])
    assert len(trajectory) == n_fixes
    np.testing.assert_allclose(trajectory.positions[0], 0.0, atol=1e-6)
    assert np.all(trajectory.positions[:, 2] == 0.0)

    with (out / "drift_table.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [row["variant"] for row in rows] == list(VARIANTS)
    drift = {row["variant"]: abs(float(row["drift_deg_per_min"])) for row in rows}
    assert float(rows[4]["loop_gap_percent"]) < 1.0 and float(rows[4]["end_error_m"]) >= 0.0
    assert summary_of(out)["route_closes"] is True
    assert drift["combined + ε0 removed"] < drift["sensor 1"] / 50.0

    geo = json.loads((out / "trajectory.geojson").read_text())
    names = [f["properties"]["name"] for f in geo["features"]]
    assert names == ["dead reckoning", "reconstructed GPS track", "start", "end"]
    line = np.array(geo["features"][0]["geometry"]["coordinates"])
    assert line.shape == (n_fixes, 2)
    np.testing.assert_allclose(
        line[0], [record.spec.origin_lon_deg, record.spec.origin_lat_deg], atol=1e-4
    )

    summary = json.loads((out / "deadreckon_summary.json").read_text())
    assert summary["k_used"] == pytest.approx(1.13)
    assert summary["standstill"] == [t0, t1]
    assert summary["gyro2"]["rate_hz"] == pytest.approx(50.0)
    for figure in ("map.png", "allan_deviation.png"):
        assert (out / figure).read_bytes()[:4] == b"\x89PNG"


def test_cli_bad_input_exit_codes(inputs, tmp_path, capsys):
    _, paths = inputs
    bad = tmp_path / "bad.csv"
    bad.write_text("time,rate\n0,1\n")
    code = main(_args({**paths, "gyro1": bad}, tmp_path / "o1"))
    assert code == 1
    assert "lacks column" in capsys.readouterr().err
    for extra in (["--k", "2.5"], ["--standstill", "5,1"], ["--downsample", "0"]):
        with pytest.raises(SystemExit) as info:
            main(_args(paths, tmp_path / "o2", *extra))
        assert info.value.code == 2


@pytest.mark.slow
def test_standstill_interval_that_moves_is_exit_1_with_the_speed(inputs, tmp_path, capsys):
    record, paths = inputs
    _, t1 = record.standstill
    moving = (t1 + 20.0, t1 + 40.0)  # the drive after the standstill
    code = main(_args(paths, tmp_path / "o", "--standstill", f"{moving[0]},{moving[1]}"))
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err
    t0, t1 = (f"{t:.2f}" for t in moving)
    assert f"standstill {t0}–{t1} s: the GPS track speed shows the vehicle moving" in err


def test_an_output_folder_holding_an_input_or_someone_elses_files_is_refused(
    inputs, tmp_path, capsys
):
    _, paths = inputs
    assert main(_args(paths, paths["gyro1"].parent)) == 1
    assert "the output folder contains the input" in capsys.readouterr().err
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    assert main(_args(paths, other)) == 1
    err = capsys.readouterr().err
    assert f"{other}: the output folder is not empty and was not written by 'vo-doppler " in err
    assert [p.name for p in other.iterdir()] == ["notes.txt"]


@pytest.mark.slow
def test_an_open_route_gets_the_end_error_and_no_loop_gap(inputs, tmp_path, capsys):
    """The QA case: a start-to-end "gap" reported on a route that is no loop (here the first
    60 s of the loop's drive)."""
    record, paths = inputs
    lines = paths["gps"].read_text().splitlines()
    half = tmp_path / "half.csv"
    half.write_text("\n".join(lines[:661]) + "\n")  # header, 600 s still, 60 s driving
    t0, t1 = record.standstill
    out = tmp_path / "out"
    assert main(_args({**paths, "gps": half}, out, "--standstill", f"{t0},{t1}")) == 0
    printed = capsys.readouterr().out
    assert "the GPS route does not close" in printed
    with (out / "drift_table.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert all(row["loop_gap_m"] == "nan" for row in rows)
    best = rows[VARIANTS.index("combined + ε0 removed")]
    assert 0.0 < float(best["end_error_percent"]) < 5.0
    assert summary_of(out)["route_closes"] is False
