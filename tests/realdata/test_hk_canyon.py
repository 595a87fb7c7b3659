"""The Hong Kong urban-canyon drive (u-blox M8T, GPS + BeiDou, 1 Hz; ../shared/data), vehicle
signals synthesised from its reference (benchmarks/real_sequences.py): the robust heading
method's figures (issue 29's acceptance) and a negated yaw rate caught at 1 Hz."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.eval.gnss_scores import score_heading, score_velocity
from vo_doppler.geo import wrap_angle
from vo_doppler.heading.integrity import car_checked_velocity
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.model.ground_truth import GroundTruth
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import sample
from vo_doppler.run_stages import sequence_heading

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("hk_canyon")]


def test_robust_heading_holds_in_the_real_canyon_at_1_hz(hk_canyon):
    sequence, gnss = hk_canyon
    table = sequence_heading(sequence, gnss.rows, gnss.velocity, HeadingPipelineConfig.robust())
    truth = sequence.truth
    velocity = np.gradient(truth.positions, truth.t, axis=0)
    speed = np.hypot(*(sample(truth.t, velocity[:, i], table.t) for i in range(2)))
    moving = speed > 3.0
    reliable = moving & np.isfinite(table.yaw_tc) & table.tc_reliable
    error = np.degrees(np.abs(wrap_angle(table.yaw_tc - truth.yaw_at(table.t))))[reliable]
    # measured with the heading smoother: 100 % of 152 moving epochs, median 0.60°, p95 2.55°
    # (issue 29 asks ≥ 90 %, ≤ 1°, ≤ 3°; the robust windows alone gave 94.1 %, 1.03° / 2.97°)
    assert reliable.sum() / moving.sum() >= 0.90
    assert np.median(error) <= 1.0 and np.percentile(error, 95) <= 3.0
    inside = np.isfinite(sample(sequence.wheel_speed.t, sequence.wheel_speed.value, table.t))
    # synthesised: gyro bias 0.5 °/s, wheel scale 1.02 (calibrated scale 1/1.02); measured
    # 0.503 °/s and 0.46 % low (issue 29 asks 0.05 °/s and 0.5 %)
    calibration = table.calibration
    assert abs(np.degrees(calibration.gyro_bias) - 0.5) <= 0.05
    assert abs(calibration.wheel_scale * 1.02 - 1.0) <= 0.005
    assert calibration.epochs == inside.sum()
    noise = gnss.moving_noise  # fitted from the drive's own residuals
    assert noise.n_bins >= 3 and noise.k_slope < 0 and 0.15 < noise.rest_factor < 0.5


def test_conventional_headings_and_velocities_the_car_checked_hold_in_the_canyon(hk_canyon):
    """Issue 29: the conventional course valid after the car's tests within 5° at p95 and none
    beyond 15°, and the conventional velocity (``vel.csv`` of ``run``) at standstill within
    0.1 m/s at p95; the GNSS stage's own verdict (``gnss velocity``) does not meet either."""
    sequence, gnss = hk_canyon
    table = sequence_heading(sequence, gnss.rows, gnss.velocity, HeadingPipelineConfig.robust())
    truth = GroundTruth(sequence.truth.t, sequence.truth.positions, sequence.enu, None, "TUM")
    headings = score_heading(table, truth).conventional
    # measured: 55 of 152 moving epochs (36 %), median 1.28°, p95 3.84°, max 5.13°
    assert headings.availability >= 0.3
    assert headings.error_deg.p95 <= 5.0 and headings.error_deg.beyond[15.0] == 0
    checked = score_velocity(car_checked_velocity(gnss.velocity, table), truth)
    # measured: the same moving epochs; 35 of 57 standstill epochs, p95 0.07 m/s, max 0.12
    assert checked.course_error_deg.p95 <= 5.0 and checked.course_error_deg.beyond[15.0] == 0
    assert checked.standstill_speed_mps.count >= 20
    assert checked.standstill_speed_mps.p95 <= 0.1
    # the GNSS stage alone: 88 % moving with p95 9.2° and two beyond 15°; standstill p95 0.74
    alone = score_velocity(gnss.velocity, truth)
    assert alone.course_error_deg.p95 > 5.0 and alone.standstill_speed_mps.p95 > 0.1


def test_a_negated_yaw_rate_at_1_hz_is_an_error_naming_it(hk_canyon):
    sequence, gnss = hk_canyon
    negated = SensorSeries(sequence.yaw_rate.t, -sequence.yaw_rate.value)
    with pytest.raises(InputError, match="wrong sign"):
        sequence_heading(
            replace(sequence, yaw_rate=negated),
            gnss.rows,
            gnss.velocity,
            HeadingPipelineConfig.robust(),
        )
