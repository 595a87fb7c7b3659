"""``vo-doppler eval`` options: ``--up -y`` is the value -y, as ``--up=-y`` is."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.cli import main
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.trajectory import Trajectory


@pytest.fixture
def turned_end(tmp_path):
    """A straight 19 m drive along x and an estimate whose last pose is turned 10° about y
    (a yaw of -10° about -y, the up of a camera frame) and not at all about z."""
    t = np.arange(20.0)
    positions = np.column_stack([t, np.zeros(20), np.zeros(20)])
    turns = np.zeros((20, 3))
    turns[-1, 1] = np.radians(10.0)
    truth, estimate = tmp_path / "truth.tum", tmp_path / "estimate.tum"
    write_tum(truth, Trajectory(t, positions, Rotation.identity(20)))
    write_tum(estimate, Trajectory(t, positions, Rotation.from_rotvec(turns)))
    return estimate, truth


@pytest.mark.parametrize(
    ("up", "yaw_error_deg"),
    [(["--up", "-y"], -10.0), (["--up=-y"], -10.0), (["--up", "y"], 10.0), (["--up", "z"], 0.0)],
)
def test_up_axis_spellings(turned_end, up, yaw_error_deg, capsys):
    estimate, truth = turned_end
    assert main(["eval", str(estimate), str(truth), *up, "--json"]) == 0
    figures = json.loads(capsys.readouterr().out)
    assert figures["end_yaw_error_deg"] == pytest.approx(yaw_error_deg, abs=1e-6)
