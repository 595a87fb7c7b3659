"""The low-cost chain on a generated two-gyro record (known biases, random walks and truth):
the seed's Table 1 ordering, the closed-loop gap, and bad input handled and reported."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.geo import wrap_angle
from vo_doppler.lowcost.drift import VARIANTS
from vo_doppler.lowcost.gyro_combination import choose_k
from vo_doppler.lowcost.pipeline import (
    DeadReckonConfig,
    Reference,
    fit_initial_heading,
    run_deadreckon,
)
from vo_doppler.lowcost.rate_alignment import align_rates
from vo_doppler.sim.two_gyro import (
    DEG,
    TwoGyroSpec,
    calibration_spec,
    generate_two_gyro,
)


@pytest.fixture(scope="module")
def record():
    return generate_two_gyro(TwoGyroSpec())


@pytest.fixture(scope="module")
def calibrated_k():
    """The seed's workflow: k swept on a separate standstill record of the same gyros."""
    calibration = generate_two_gyro(calibration_spec(TwoGyroSpec()))
    aligned = align_rates(*calibration.gyro1, *calibration.gyro2)
    return choose_k(aligned.t, aligned.omega1, aligned.omega2).sweep.k


def _run(record, **config):
    reference = Reference(record.truth_t, record.truth_yaw, "truth")
    config = DeadReckonConfig(standstill_s=record.standstill, **config)
    return run_deadreckon(record.gyro1, record.gyro2, record.gps, config, reference=reference)


def test_generator_truth_and_sensor_errors(record):
    spec = record.spec
    assert np.hypot(record.truth_east[-1], record.truth_north[-1]) < 1e-6
    assert record.truth_yaw[-1] - record.truth_yaw[0] == pytest.approx(2 * np.pi, abs=1e-6)
    t1, w1 = record.gyro1
    still = t1 < record.standstill[1]
    assert np.mean(w1[still]) == pytest.approx(spec.bias1, abs=0.01 * DEG)
    assert len(record.gyro2[0]) == pytest.approx(len(t1) / 2, abs=2)
    again = generate_two_gyro(TwoGyroSpec())
    np.testing.assert_array_equal(again.gyro2[1], record.gyro2[1])


def test_drift_table_follows_the_seed_ordering(record, calibrated_k):
    result = _run(record, k=calibrated_k)
    drift = {row.variant: abs(row.drift_deg_per_min) for row in result.rows}
    assert [row.variant for row in result.rows] == list(VARIANTS)
    assert drift["sensor 1"] == pytest.approx(17.1, rel=0.02)  # the seed's 17.1 deg/min
    worse_single = max(drift["sensor 1"], drift["sensor 2"])
    best_debiased = min(drift["combined + ε0 removed"], drift["combined + ε0 removed + threshold"])
    assert best_debiased == min(drift.values())
    assert worse_single / drift["combined + ε0 removed"] >= 100.0
    assert drift["combined + ε0 removed"] < drift["combined"] / 10.0


def test_closed_loop_gap_below_one_percent(record, calibrated_k):
    result = _run(record, k=calibrated_k)
    gap = result.rows[VARIANTS.index("combined + ε0 removed")].gap
    assert gap.length_m == pytest.approx(record.spec.loop_length_m, rel=0.02)
    assert gap.percent <= 1.0
    assert gap.closed and gap.end_error_m <= 0.01 * gap.length_m


def test_auto_choices_on_the_same_record(record):
    result = _run(record)
    model = result.model
    true_k = 2 * record.spec.bias1 / (record.spec.bias1 - record.spec.bias2)
    assert model.k_choices.sweep.k == pytest.approx(true_k, abs=0.03)
    assert model.k_choices.closed_form.k == pytest.approx(true_k, abs=0.03)
    # Inverse variance of white noise: k = 2σ1²/(σ1² + σ2²) with σ2 = 2σ1 and gyro 2 at half
    # the rate (resampled, so its per-sample variance is σ2² at 50 Hz): 2·1/(1 + 2) ≈ 0.67–0.8.
    assert 0.5 < model.k_choices.inverse_variance.k < 1.0
    assert 20.0 < model.tau <= (record.standstill[1] - record.standstill[0]) / 3 + 1e-6
    assert model.eps0["sensor 1"] == pytest.approx(record.spec.bias1, abs=0.005 * DEG)
    assert model.eps0["sensor 2"] == pytest.approx(record.spec.bias2, abs=0.01 * DEG)


def test_standstill_found_from_the_track(record):
    result = run_deadreckon(record.gyro1, record.gyro2, record.gps)
    t0, t1 = result.prepared.standstill
    assert t0 == pytest.approx(record.standstill[0], abs=1.0)
    assert t1 == pytest.approx(record.standstill[1], abs=5.0)
    assert result.reference_source == "reconstructed GPS course"
    assert all(np.isfinite(row.drift_deg_per_min) for row in result.rows)


def test_gps_gaps_duplicates_and_nans_are_handled_and_reported(record, calibrated_k, caplog):
    t, lat, lon = (np.array(a, dtype=float) for a in record.gps)
    # 15 s without fixes on the first straight (interpolation across a turn would cut it).
    gap = (t > record.standstill[1] + 5) & (t < record.standstill[1] + 20)
    keep = ~gap
    t, lat, lon = t[keep], lat[keep], lon[keep]
    t = np.insert(t, 100, t[100])
    lat = np.insert(lat, 100, lat[100] + 1e-6)
    lon = np.insert(lon, 100, lon[100])
    lat[200] = np.nan
    g1t, g1 = (np.array(a, dtype=float) for a in record.gyro1)
    g1[5000:5010] = np.nan
    with caplog.at_level(logging.WARNING):
        result = run_deadreckon(
            (g1t, g1),
            record.gyro2,
            (t, lat, lon),
            DeadReckonConfig(standstill_s=record.standstill, k=calibrated_k),
            reference=Reference(record.truth_t, record.truth_yaw, "truth"),
        )
    report = result.prepared.report
    assert (report.n_gaps, report.n_duplicate_times, report.n_non_finite) == (1, 1, 1)
    assert result.rates.report1.n_non_finite == 10
    assert "gaps longer" in caplog.text and "duplicate-time" in caplog.text
    dr = result.selected_trajectory
    assert len(dr.t) == len(t) - 2 and np.all(np.isfinite(dr.east))
    row = result.rows[VARIANTS.index("combined + ε0 removed")]
    assert abs(row.drift_deg_per_min) < 0.17 and row.gap.percent < 1.0


def test_missing_standstill_and_disjoint_inputs_raise(record):
    t, lat, lon = record.gps
    drive = (t > record.standstill[1] + 5) & (t < t[-1] - record.spec.end_standstill_s - 5)
    with pytest.raises(InputError, match="no standstill"):
        run_deadreckon(record.gyro1, record.gyro2, (t[drive], lat[drive], lon[drive]))
    g2t, g2 = record.gyro2
    with pytest.raises(InputError, match="do not overlap"):
        run_deadreckon(record.gyro1, (g2t + 1e5, g2), record.gps)
    with pytest.raises(InputError, match="gyro samples inside the standstill"):
        run_deadreckon(
            record.gyro1, record.gyro2, record.gps, DeadReckonConfig(standstill_s=(0.0, 1.0))
        )


def test_the_initial_heading_is_the_gps_track_fitted_not_the_reference(record, calibrated_k):
    """A user's start: the rotation that lays the path's first seconds onto the fixes, with its
    σ; a ground truth given as the reference scores the result and must not start it (before,
    the dead reckoning started from the reference's first yaw: a benchmark given the truth
    reported the drift alone, not the figure a user gets)."""
    config = DeadReckonConfig(standstill_s=record.standstill, k=calibrated_k)
    own = run_deadreckon(record.gyro1, record.gyro2, record.gps, config)
    turned = Reference(record.truth_t, record.truth_yaw + 0.3, "truth turned by 0.3 rad")
    scored = run_deadreckon(record.gyro1, record.gyro2, record.gps, config, reference=turned)
    start = own.initial_heading
    assert start is not None and start == scored.initial_heading
    np.testing.assert_allclose(
        own.selected_trajectory.yaw[0], scored.selected_trajectory.yaw[0], atol=1e-12
    )
    truth = np.interp(start.t0, record.truth_t, np.unwrap(record.truth_yaw))
    error = np.degrees(wrap_angle(start.yaw - truth))
    assert start.sigma > 0.0 and abs(error) < max(4.0 * np.degrees(start.sigma), 0.5)


def test_the_initial_heading_fit_recovers_a_turning_path_exactly():
    """The path turns (the gyro's shape), the fixes are that path turned by 40° and moved: the
    fit returns 40° to rounding and σ 0; noise of 0.5 m per axis over 60 m of path gives a σ
    near 0.5 / √Σ|d|² (counted once per second) and an error within it."""
    t = np.arange(0.0, 6.0, 0.1)
    yaw = 0.05 * t**2
    step = np.column_stack([np.cos(yaw), np.sin(yaw)]) * 1.0
    shape = np.concatenate([[[0.0, 0.0]], np.cumsum(step[:-1], axis=0)])
    turn = np.radians(40.0)
    rotation = np.array([[np.cos(turn), -np.sin(turn)], [np.sin(turn), np.cos(turn)]])
    track = shape @ rotation.T + [120.0, -35.0]
    exact = fit_initial_heading(t, track, shape, (0.0, 6.0))
    assert np.degrees(exact.yaw) == pytest.approx(40.0, abs=1e-9)
    assert exact.sigma == pytest.approx(0.0, abs=1e-9) and exact.fixes == t.size
    errors, sigmas = [], []
    for seed in range(200):
        noisy = track + np.random.default_rng(seed).normal(scale=0.5, size=track.shape)
        fit = fit_initial_heading(t, noisy, shape, (0.0, 6.0))
        errors.append(fit.yaw - turn)
        sigmas.append(fit.sigma)
    # fixes independent at 10 Hz here: the σ counted once per second is conservative by √10
    assert np.std(errors) < np.median(sigmas) < 4.0 * np.std(errors)
    assert fit_initial_heading(t, track, shape, (0.0, 0.15)) is None  # two epochs
    assert fit_initial_heading(t, track * 0.01, shape * 0.01, (0.0, 6.0)) is None  # 0.6 m
