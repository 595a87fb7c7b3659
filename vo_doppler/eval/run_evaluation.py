"""A run's trajectories against the ground truth, in one call that never costs the run its
other outputs: their absolute position errors as written, every pipeline's errors moved to the
truth (:mod:`vo_doppler.eval.pipelines`), and what could not be evaluated, in sentences."""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np

from vo_doppler.eval.per_distance import ErrorPerDistance
from vo_doppler.eval.pipelines import (
    AbsolutePositionErrors,
    PipelineErrors,
    absolute_position_errors,
    evaluate_pipelines,
    evaluation_warnings,
)
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.trajectory import Trajectory

log = logging.getLogger(__name__)


@dataclass
class RunEvaluation:
    """What :func:`evaluate_run` found; each dictionary is keyed by pipeline and holds only the
    trajectories it could evaluate."""

    absolute: dict[str, AbsolutePositionErrors] = field(default_factory=dict)
    """The trajectories as written (:func:`~vo_doppler.eval.pipelines.absolute_position_errors`)."""
    errors: dict[str, PipelineErrors] = field(default_factory=dict)
    per_100m: dict[str, ErrorPerDistance] = field(default_factory=dict)
    shown: dict[str, Trajectory] = field(default_factory=dict)
    """The trajectories as evaluated (:func:`~vo_doppler.eval.pipelines.evaluate_pipelines`)."""
    warnings: list[str] = field(default_factory=list)
    """What could not be evaluated (:func:`~vo_doppler.eval.pipelines.evaluation_warnings`),
    or the evaluation's failure; each also logged."""


def evaluate_run(
    trajectories: dict[str, Trajectory],
    table: HeadingTable | None,
    tc_usable: np.ndarray,
    truth: Trajectory,
    vehicle_span: tuple[float, float] | None = None,
) -> RunEvaluation:
    """Evaluate a run's ``trajectories`` against ``truth`` (``table``, ``tc_usable`` and
    ``vehicle_span`` as :func:`~vo_doppler.eval.pipelines.evaluate_pipelines` takes them).
    An exception in the evaluation (a bug) becomes the one warning of an empty evaluation."""
    try:
        absolute = {
            name: found
            for name, trajectory in trajectories.items()
            if (found := absolute_position_errors(trajectory, truth)) is not None
        }
        errors, per_100m, shown = evaluate_pipelines(
            trajectories, table, tc_usable, truth, vehicle_span
        )
        evaluation = RunEvaluation(
            absolute, errors, per_100m, shown, evaluation_warnings(trajectories, errors, truth)
        )
    except Exception as exc:  # a bug in the evaluation must not lose the trajectories
        log.debug("the evaluation failed", exc_info=True)
        evaluation = RunEvaluation(
            warnings=[
                f"the evaluation against the ground truth failed ({type(exc).__name__}: {exc}; "
                "a bug, please report it): the trajectories and figures are written without it"
            ]
        )
    for text in evaluation.warnings:
        log.warning("%s", text)
    return evaluation
