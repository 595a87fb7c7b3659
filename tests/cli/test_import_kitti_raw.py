"""``vo-doppler import kitti-raw`` on the kitti_raw_mini drive, then ``run`` on the imported
folder: no GNSS, so the VO and the dead reckoning run alone and the outputs say so."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from tests.conftest import require_shared
from vo_doppler.cli import main
from vo_doppler.errors import EXIT_FAILURE, EXIT_OK, EXIT_USAGE

MINI = "kitti_raw_mini/2011_09_26/2011_09_26_drive_0001_sync"


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    drive = require_shared(MINI)
    folder = tmp_path_factory.mktemp("kitti") / "seq"
    assert main(["import", "kitti-raw", str(drive), "-o", str(folder)]) == EXIT_OK
    return folder


@pytest.mark.shared_data
def test_import_writes_a_sequence_without_gnss(imported):
    manifest = yaml.safe_load((imported / "sequence.yaml").read_text())
    assert manifest["format"] == "vo-doppler-sequence/1"
    assert "gnss" not in manifest and "can" not in manifest
    assert manifest["camera"]["images"] == "image_00"
    assert len(list((imported / "image_00").glob("*.png"))) == 10
    assert manifest["origin"]["lat_deg"] == pytest.approx(49.015003823272, abs=1e-12)
    image_warning, oxts_warning = manifest["kitti"]["warnings"]
    assert image_warning.split(": ", 1)[1].startswith("10 data files for the 108 timestamps")
    assert oxts_warning.split(": ", 1)[1].startswith("5 data files for the 108 timestamps")
    tum = np.loadtxt(imported / "ground_truth.tum")
    assert tum.shape == (5, 8)
    np.testing.assert_allclose(tum[0, 1:4], 0.0, atol=1e-9)  # the origin is the first fix


@pytest.mark.slow
@pytest.mark.shared_data
def test_run_on_the_imported_drive_runs_vo_and_dead_reckoning(imported, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(imported), "-o", str(out)]) == EXIT_OK
    printed = capsys.readouterr().out
    assert "no GNSS epochs" in printed and "GNSS pipelines were not run" in printed
    assert sorted(p.name for p in out.glob("*.tum")) == ["trajectory_dr.tum", "trajectory_vo.tum"]
    assert not (out / "heading.csv").exists()
    summary = json.loads((out / "summary.json").read_text())
    assert summary["gnss_epochs"] == 0
    assert summary["gnss"].startswith("none: the GNSS pipelines were not run")
    assert summary["vo_frames"] == 10
    assert any("has no GNSS" in text for text in summary["warnings"])
    assert sorted(summary["evaluation"]) == ["dr", "vo"]
    # 0.42 s of ground truth at 13 m/s: the DR from OXTS vf and wz follows it to centimetres
    assert summary["evaluation"]["dr"]["final_position_error_m"] < 0.2
    vo = np.loadtxt(out / "trajectory_vo.tum")
    assert vo.shape[0] == 10
    np.testing.assert_allclose(vo[0, 1:4], 0.0, atol=1e-9)  # placed at the origin
    report = (out / "report.html").read_text()
    assert "GNSS pipelines were not run" in report
    assert "GNSS headings" not in report


def test_bad_drive_exits_1_naming_it_and_a_bad_camera_exits_2(tmp_path, capsys):
    drive = tmp_path / "2011_09_26_drive_0001_sync"
    drive.mkdir()
    (drive / "image_00").mkdir()
    code = main(["import", "kitti-raw", str(drive), "-o", str(tmp_path / "seq")])
    assert code == EXIT_FAILURE
    err = capsys.readouterr().err
    assert f"{drive}: no oxts folder in the drive" in err and "Traceback" not in err
    args = ["import", "kitti-raw", str(drive), "--camera", "image_7", "-o", str(tmp_path / "s")]
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == EXIT_USAGE
