"""A run's evaluation in one call: the same figures as the pipelines' evaluation and the
absolute errors, the trajectories outside the truth named in a warning, and a failure turned
into the one warning of an empty evaluation (logged), never an exception."""

from __future__ import annotations

import numpy as np
import pytest

from tests.eval.test_pipelines import TABLE, USABLE, T, drive
from vo_doppler.eval import run_evaluation
from vo_doppler.eval.pipelines import absolute_position_errors, evaluate_pipelines
from vo_doppler.eval.run_evaluation import evaluate_run
from vo_doppler.model.trajectory import Trajectory


def _trajectories() -> dict[str, Trajectory]:
    truth = drive(T)
    shifted = Trajectory(truth.t, truth.positions + np.array([3.0, -4.0, 0.0]), truth.orientations)
    late = Trajectory(truth.t + 1000.0, truth.positions, truth.orientations)
    return {"dr": shifted, "dr_gps_tc": late}


def test_the_figures_are_the_pipelines_and_the_absolute_errors():
    trajectories, truth = _trajectories(), drive(T)
    found = evaluate_run(trajectories, TABLE, USABLE, truth)
    errors, per_100m, shown = evaluate_pipelines(trajectories, TABLE, USABLE, truth)
    assert set(found.errors) == set(found.per_100m) == set(found.shown) == {"dr"}
    assert found.per_100m["dr"].errors_m.tolist() == per_100m["dr"].errors_m.tolist()
    assert found.errors["dr"].to_dict() == errors["dr"].to_dict()
    np.testing.assert_array_equal(found.shown["dr"].positions, shown["dr"].positions)
    assert found.absolute == {"dr": absolute_position_errors(trajectories["dr"], truth)}
    assert found.absolute["dr"].start_horizontal_m == pytest.approx(5.0, abs=1e-9)
    (warning,) = found.warnings
    assert warning.startswith("not evaluated: wheel + gyro DR + GPS (tightly coupled)")


def test_a_failing_evaluation_is_one_logged_warning_and_nothing_else(monkeypatch, caplog):
    def broken(*_):
        raise RuntimeError("boom")

    monkeypatch.setattr(run_evaluation, "evaluate_pipelines", broken)
    with caplog.at_level("WARNING"):
        found = evaluate_run(_trajectories(), TABLE, USABLE, drive(T))
    assert found.absolute == found.errors == found.per_100m == found.shown == {}
    (warning,) = found.warnings
    assert warning.startswith("the evaluation against the ground truth failed (RuntimeError: boom")
    assert warning in caplog.text
