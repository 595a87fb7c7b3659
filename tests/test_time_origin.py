"""Results do not depend on the time origin (issue 30): a recording with every time shifted by
1,653 GPS weeks (:data:`~tests.helpers.time_shift.WEEKS_NEAR_1E9_S`, 999,734,400 s, the whole
number of weeks nearest 10⁹ s: broadcast orbits count from the week's start) gives the same
GNSS velocities, heading table, trajectories and errors per 100 m as the recording itself.

Each case runs :func:`vo_doppler.run.run_sequence` twice, as ``vo-doppler run`` does without
its files: the bundled sample with every stage (VO included), the comma2k19 minute of
``VO_DOPPLER_SHARED_DATA`` (precise orbits, no camera) and a simulated drive with a 1-Hz
receiver under both heading methods. Before the fixes these cases found (the pseudorange noise
fitted to the rounding of epochs without redundancy, the nearest fix chosen by rounding on a
tie, a faulty satellite chosen by rounding among equal test statistics, the dead reckoning's
20-Hz grid drifting with ``np.arange`` on GPS seconds), the sample's dead reckoning + tight
heading gave 0.057 and 0.062 m per 100 m at the two origins and its velocities differed by up
to 441 m/s at an epoch."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.helpers.comma2k19 import imported_comma2k19
from tests.helpers.time_shift import WEEKS_NEAR_1E9_S, shifted_sequence
from vo_doppler.eval.pipelines import evaluate_pipelines
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.sequence import Sequence
from vo_doppler.run import RunConfig, RunResult, run_sequence

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("time_origin")]

SHIFT = WEEKS_NEAR_1E9_S
TOLERANCE = 1e-5
"""Relative and absolute tolerance of every number compared (rad, m/s, m, s): the satellites
move 2 mm over the rounding of a time near 2.4·10⁹ s (4.8·10⁻⁷ s), which moves a velocity by
~10⁻⁶ m/s and a heading by ~10⁻⁷ rad; a flag must be the same."""
ERROR_TOLERANCE_M = 1e-4
"""Errors per 100 m agree within 0.1 mm (they differed by 4-90 mm before the fixes)."""


def assert_same_arrays(name: str, first, second, time_fields=("t",)) -> None:
    """Every array field of two dataclass instances equal: flags and counts exactly, numbers
    within :data:`TOLERANCE` (NaN where the other is NaN), times less :data:`SHIFT`."""
    for field in dataclasses.fields(first):
        a, b = getattr(first, field.name), getattr(second, field.name)
        if not isinstance(a, np.ndarray) or a.dtype.kind not in "biuf":
            continue
        what = f"{name}.{field.name}"
        assert a.shape == b.shape, what
        if a.dtype.kind != "f":
            mismatch = np.flatnonzero((a != b).reshape(len(a), -1).any(axis=1))
            assert mismatch.size == 0, f"{what} differs at {mismatch[:10]}"
            continue
        b = b - SHIFT if field.name in time_fields else b
        np.testing.assert_allclose(b, a, rtol=TOLERANCE, atol=TOLERANCE, err_msg=what)


def errors_per_100m(result: RunResult, sequence: Sequence) -> dict[str, float]:
    errors, _, _ = evaluate_pipelines(
        {str(name): track for name, track in result.trajectories.items()},
        result.heading,
        result.tc_usable,
        sequence.truth,
        sequence.vehicle_span,
    )
    return {name: e.error_per_100m_m for name, e in errors.items()}


def assert_origin_free(
    sequence: Sequence, config: RunConfig | None = None, first: RunResult | None = None
) -> dict[str, float]:
    """The run on ``sequence`` (``first``, when already made) and on it shifted by
    :data:`SHIFT` agree; the errors per 100 m of the first."""
    shifted = shifted_sequence(sequence, SHIFT)
    first = first or run_sequence(sequence, config)
    second = run_sequence(shifted, config)
    assert_same_arrays("velocity", first.gnss.velocity, second.gnss.velocity)
    assert_same_arrays("heading", first.heading, second.heading)
    np.testing.assert_array_equal(first.tc_usable, second.tc_usable)
    assert first.trajectories.keys() == second.trajectories.keys()
    for name, track in first.trajectories.items():
        other = second.trajectories[name]
        np.testing.assert_allclose(other.t - SHIFT, track.t, atol=TOLERANCE, err_msg=name)
        np.testing.assert_allclose(other.positions, track.positions, atol=1e-3, err_msg=name)
    errors = errors_per_100m(first, sequence)
    shifted_errors = errors_per_100m(second, shifted)
    assert shifted_errors.keys() == errors.keys()
    for name, error in errors.items():
        assert shifted_errors[name] == pytest.approx(error, abs=ERROR_TOLERANCE_M), name
    return errors


def test_the_sample_runs_the_same_at_another_time_origin(sample_run):
    errors = assert_origin_free(sample_run.sequence, first=sample_run.result)
    assert {"vo", "vo_gps_tc", "dr_gps_tc"} <= errors.keys()


def test_the_comma2k19_minute_runs_the_same_at_another_time_origin(tmp_path_factory):
    errors = assert_origin_free(imported_comma2k19(tmp_path_factory))
    assert {"dr", "dr_gps_tc"} <= errors.keys()


@pytest.mark.parametrize("method", ["snooping", "robust"])
def test_a_1hz_drive_runs_the_same_at_another_time_origin(method, drive_1hz_folder):
    sequence = read_sequence(drive_1hz_folder)
    heading = HeadingPipelineConfig.robust() if method == "robust" else HeadingPipelineConfig()
    errors = assert_origin_free(sequence, RunConfig(heading=heading))
    assert {"dr", "dr_gps_conv", "dr_gps_tc"} <= errors.keys()
