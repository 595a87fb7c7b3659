"""Low-cost path mapping on the real comma2k19 minute: gyro z + CAN yaw rate + u-blox fixes
against global_pose. No standstill: k and ε0 come from the first 5 s of straight driving."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.io.comma2k19 import read_lowcost_inputs
from vo_doppler.lowcost.drift import VARIANTS
from vo_doppler.lowcost.evaluation import (
    block_rate_errors,
    fitted_time_offset,
    gps_scatter,
    heading_run,
)

pytestmark = pytest.mark.shared_data
DEBIASED = VARIANTS.index("combined + ε0 removed")
DEBIASED_THRESHOLD = VARIANTS.index("combined + ε0 removed + threshold")


@pytest.fixture(scope="module")
def comma():
    require_shared("comma2k19_example1/global_pose/frame_times")
    return read_lowcost_inputs(require_shared("comma2k19_example1"))


def _final_errors(run):
    return {row.variant: row.final_heading_error_deg for row in run.rows}


def test_inputs_and_time_bases(comma):
    truth, fixes, gyro, can = comma
    assert len(truth.t) == 1200 and len(fixes.t) == 579
    assert fixes.t[-1] - fixes.t[0] == pytest.approx(60.0, abs=1.0)
    assert 100 < 1 / (gyro[0][1] - gyro[0][0]) < 110  # the IMU runs near 104 Hz
    assert len(can[0]) > 4000  # KINEMATICS frames decoded from can_motion.log


def test_heading_after_the_minute_with_five_second_eps0(comma):
    run = heading_run(*comma, window_s=5.0, k=None)
    errors = _final_errors(run)
    assert run.selected_trajectory.t[-1] - run.selected_trajectory.t[0] > 59.0
    assert abs(errors["sensor 2"]) > 20.0  # CAN YAW_RATE's ≈ −0.4 deg/s bias, uncorrected
    assert abs(errors["combined + ε0 removed + threshold"]) <= 1.0
    for k in (0.0, 2.0):  # each sensor alone, de-biased by its own ε0
        assert (
            abs(heading_run(*comma, window_s=5.0, k=k).rows[DEBIASED].final_heading_error_deg) < 2.5
        )


@pytest.mark.xfail(
    strict=True,
    reason="measured −1.69° (−2.80° against global_pose's body yaw; the start fitted to the GPS "
    "track, 0.11° off global_pose's course): 5-s means of "
    "(sensor − truth) rate scatter by ≈0.025 deg/s (common to both sensors), ≈1.5° over the "
    "minute; see benchmarks/lowcost_comma2k19.py",
)
def test_debiased_combined_heading_within_one_degree_with_five_second_eps0(comma):
    run = heading_run(*comma, window_s=5.0, k=None)
    assert abs(run.rows[DEBIASED].final_heading_error_deg) <= 1.0


def test_longer_eps0_window_meets_one_degree(comma):
    run = heading_run(*comma, window_s=20.0, k=None)
    assert abs(run.rows[DEBIASED].final_heading_error_deg) <= 1.0


def test_reconstructed_track_scatters_less_than_raw_fixes(comma):
    truth, fixes, _, _ = comma
    scatter, _, _, _ = gps_scatter(truth, fixes, (5, 10), 3.0)
    raw = scatter["raw"]
    for m in (5, 10):
        track = scatter[f"reconstructed M={m}"]
        assert track["std_about_mean_m"] < raw["std_about_mean_m"]
        assert track["jitter_rms_m"] < raw["jitter_rms_m"]
        assert track["rms_m"] < raw["rms_m"] + 0.01


def test_ground_truth_body_yaw_is_the_forward_axis(comma):
    truth = comma[0]
    # A car on a highway: the device's forward axis stays within a degree or so of the course,
    # and both headings change by less than a degree over this nearly straight minute.
    offset = np.degrees(truth.body_yaw - truth.yaw)
    assert np.all(np.abs(offset) < 2.0)
    assert abs(np.degrees(truth.body_yaw[-1] - truth.body_yaw[0])) < 1.0
    # The two truths' heading changes differ by several tenths of a degree over the minute:
    # the resolution limit of a 1° check on the dead-reckoned heading.
    change_gap = np.degrees(
        (truth.yaw[-1] - truth.yaw[0]) - (truth.body_yaw[-1] - truth.body_yaw[0])
    )
    assert 0.3 < abs(change_gap) < 0.6


def test_fixes_on_the_truth_clock_and_their_scatter(comma):
    """The fixes go to the log clock through the receiver's own time tags
    (``comma2k19.gps_minus_log``): no time offset is left to fit (measured −0.006 s; through
    ``global_pose``'s frame_gps_times it was +0.120 s, 2 m along-track, raw RMS 2.09 m)."""
    truth, fixes, _, _ = comma
    offset = fitted_time_offset(truth, fixes)
    assert abs(offset) < 0.03
    scatter, _, _, _ = gps_scatter(truth, fixes, (10,), 3.0)
    assert scatter["raw"]["rms_m"] < 0.5  # measured 0.44 m
    shifted = dataclasses.replace(fixes, t=fixes.t + offset)
    scatter, _, _, _ = gps_scatter(truth, shifted, (10,), 3.0)
    raw, track = scatter["raw"], scatter["reconstructed M=10"]
    assert raw["rms_m"] < 0.5
    assert track["rms_m"] < raw["rms_m"]
    assert track["std_about_mean_m"] < 0.9 * raw["std_about_mean_m"]


def test_the_five_second_wander_is_common_to_both_sensors(comma):
    """Why a 5-s ε0 misses 1°: the block errors against global_pose are shared by the IMU gyro
    and the CAN yaw rate, two independent sensors, so they sit in the truth (or in its 3-D
    heading against the body yaw rate), not in either sensor."""
    truth, _, gyro, can = comma
    gyro_errors, can_errors = block_rate_errors(*gyro, truth), block_rate_errors(*can, truth)
    assert np.corrcoef(gyro_errors, can_errors)[0, 1] > 0.7
    between = np.std(gyro_errors - can_errors)
    assert between < 0.7 * min(np.std(gyro_errors), np.std(can_errors))
    assert np.degrees(np.std(gyro_errors)) * 60.0 > 1.0  # ≈ 1.6° over the minute, 1σ
