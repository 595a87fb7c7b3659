"""``vo-doppler import smartloc`` on the Berlin file, then ``run`` on the imported folder (no
navigation file: the dead reckoning alone, evaluated against the smartLoc ground truth), and
the exit codes of bad input and bad usage."""

from __future__ import annotations

import json
import logging

import pytest
import yaml

from tests.conftest import require_shared
from tests.helpers.smartloc_text import Measurement, Truth, smartloc_text
from vo_doppler.cli import main
from vo_doppler.errors import EXIT_FAILURE, EXIT_OK, EXIT_USAGE

REAL = "smartloc_berlin/tu_chemnitz_berlin_1_raw.csv"


@pytest.mark.shared_data
def test_import_then_run_gives_the_dead_reckoning(tmp_path, caplog):
    source = require_shared(REAL)
    caplog.set_level(logging.INFO)
    folder = tmp_path / "seq"
    assert main(["import", "smartloc", str(source), "-o", str(folder)]) == EXIT_OK
    text = caplog.text
    assert "545 measurement rows in 31 epochs" in text
    assert "no navigation file" in text
    manifest = yaml.safe_load((folder / "sequence.yaml").read_text())
    assert manifest["smartloc"]["nlos_rows"] == {"nlos": 263, "line_of_sight": 279, "unknown": 3}
    out = tmp_path / "out"
    assert main(["run", str(folder), "-o", str(out)]) == EXIT_OK
    summary = json.loads((out / "summary.json").read_text())
    assert summary["gnss_epochs"] == 0
    assert sorted(summary["evaluation"]) == ["dr"]
    # the DR integrates the ground truth's own speed and yaw rate: it follows it closely
    assert summary["evaluation"]["dr"]["final_position_error_m"] < 1.0


def test_a_bad_csv_exits_1_naming_the_line(tmp_path, capsys):
    source = tmp_path / "bad_raw.csv"
    source.write_text(smartloc_text([(Truth(10.0), [Measurement(), Measurement(gnss="Mars")])]))
    code = main(["import", "smartloc", str(source), "-o", str(tmp_path / "seq")])
    assert code == EXIT_FAILURE
    assert f"{source}:3: column (gnssId): unknown system 'Mars'" in capsys.readouterr().err
    assert not (tmp_path / "seq").exists()


def test_without_an_output_folder_it_is_a_usage_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as caught:
        main(["import", "smartloc", str(tmp_path / "x.csv")])
    assert caught.value.code == EXIT_USAGE
    assert "-o/--output" in capsys.readouterr().err
