"""``vo-doppler import comma2k19``, then ``gnss velocity|spp --orbits`` and ``run`` on the
imported folder (no camera: the non-visual pipelines, and the output says so)."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest
import yaml

from tests.conftest import require_shared
from vo_doppler.cli import main
from vo_doppler.errors import InputError
from vo_doppler.io.gnss_csv import SPP_COLUMNS, VELOCITY_COLUMNS
from vo_doppler.io.satellite_states import read_satellite_states

COMMA = "comma2k19_example1"


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    segment = require_shared(COMMA)
    folder = tmp_path_factory.mktemp("import") / "seq"
    sp3 = segment / "Sta20124_1400_1845.sp3"
    assert main(["import", "comma2k19", str(segment), "--orbits", str(sp3), "-o", str(folder)]) == 0
    return folder


def _table(path):
    with path.open() as handle:
        rows = list(csv.reader(handle))
    return rows[0], rows[1:]


@pytest.mark.shared_data
def test_import_writes_a_sequence_folder(imported):
    manifest = yaml.safe_load((imported / "sequence.yaml").read_text())
    assert manifest["format"] == "vo-doppler-sequence/1"
    assert "camera" not in manifest
    assert manifest["gnss"]["orbits"].endswith(".sp3") and "nav" not in manifest["gnss"]
    offset = manifest["clock_offsets"]["log_to_gps_s"]
    # the receiver's time tags against the log times; global_pose's frame_gps_times: +0.126 s
    assert offset == pytest.approx(2012 * 604800 + 357697.7233, abs=1e-3)
    assert manifest["can"]["time_offset_s"] == offset
    for key in ("obs", "orbits", "doppler_sigma"):
        assert (imported / manifest["gnss"][key]).is_file()
    header = (imported / "gnss/raw_gnss_ublox.obs").read_text().split("END OF HEADER")[0]
    assert "GLONASS SLOT / FRQ #" in header
    tum = np.loadtxt(imported / "ground_truth.tum")
    assert tum.shape == (1200, 8)


@pytest.mark.slow
@pytest.mark.shared_data
def test_gnss_commands_with_orbits(imported, tmp_path):
    obs = imported / "gnss/raw_gnss_ublox.obs"
    orbits = next((imported / "gnss").glob("*.sp3"))
    out = tmp_path / "vel.csv"
    args = ["gnss", "velocity", str(obs), "--orbits", str(orbits), "--systems", "GR"]
    assert main([*args, "-o", str(out)]) == 0
    header, rows = _table(out)
    assert tuple(header) == VELOCITY_COLUMNS
    table = np.array(rows, dtype=float)
    valid = table[:, header.index("valid")] == 1
    assert valid.mean() > 0.95
    speed = table[valid, header.index("speed_mps")]
    assert 7.0 < np.median(speed) < 21.0  # 7.9 → 20 m/s
    assert np.all(table[valid, header.index("course_sigma_deg")] > 0)
    spp = tmp_path / "pos.csv"
    args = ["gnss", "spp", str(obs), "--orbits", str(orbits), "--systems", "GR", "-o", str(spp)]
    assert main(args) == 0
    header, rows = _table(spp)
    assert tuple(header) == SPP_COLUMNS
    assert np.array(rows, dtype=float)[:, header.index("valid")].mean() > 0.9


def test_clocks_need_orbits(tmp_path):
    with pytest.raises(InputError, match="precise orbits"):
        read_satellite_states([tmp_path / "x.nav"], clocks=tmp_path / "x.clk")
    with pytest.raises(InputError, match="no satellite states"):
        read_satellite_states()


def test_nav_and_orbits_are_exclusive():
    with pytest.raises(SystemExit) as stop:
        main(["gnss", "velocity", "x.obs", "--nav", "n", "--orbits", "o.sp3", "-o", "v.csv"])
    assert stop.value.code == 2


@pytest.mark.slow
@pytest.mark.shared_data
def test_run_without_camera(imported, tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", str(imported), "-o", str(out)]) == 0
    assert "no camera: only the non-visual pipelines ran" in capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert summary["camera"] == "none: non-visual pipelines only"
    for pipeline in ("dr", "dr_gps_conv", "dr_gps_tc"):
        assert (out / f"trajectory_{pipeline}.tum").is_file()
    assert not (out / "trajectory_vo.tum").exists()
    evaluation = summary["evaluation"]
    # one minute of highway: the DR's own heading drifts, each GNSS heading corrects it
    assert evaluation["dr_gps_tc"]["error_per_100m_m"] < evaluation["dr"]["error_per_100m_m"]
    assert evaluation["dr"]["heading_availability"] == 0.0
