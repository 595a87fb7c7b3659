"""Kalman heading blend (B1)–(B4): exact synthetic cases, statistics with fixed seeds, and the
window/kalman choice in the pipeline and the CLI."""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tests.fusion.test_heading_correction import _ground_truth, _table, _vo_output
from tests.helpers.correction import blend_camera
from vo_doppler.cli import main
from vo_doppler.fusion.correction import AbsoluteHeading, CorrectionConfig, correct
from vo_doppler.fusion.heading_blend import (
    BlendConfig,
    DriftClock,
    OffsetMeasurements,
    blend_heading,
    decimate,
    fit_process_noise,
    forward_filter,
    robust_start,
    rts_smooth,
)
from vo_doppler.fusion.heading_correction import correct_heading
from vo_doppler.geo import wrap_angle, yaw_of
from vo_doppler.heading.conventional import velocity_heading_sigma
from vo_doppler.io.heading_csv import read_heading_csv, write_heading_csv
from vo_doppler.io.trajectory import read_tum, write_tum
from vo_doppler.model.camera import CAMERA_TO_VEHICLE_FORWARD as FORWARD_CAMERA_TO_VEHICLE
from vo_doppler.model.trajectory import Trajectory

FIXED = BlendConfig(sigma_distance_rad_per_sqrt_m=1e-3, sigma_turn=1e-3, measurement_scale=1.0)
"""Noise given, nothing fitted."""


def _expected(gt: Trajectory) -> np.ndarray:
    expected = gt.matrices.copy()
    expected[:, :3, 3] -= gt.positions[0]
    return expected


def _turned_vo(gt: Trajectory, offset) -> Trajectory:
    """Level vehicle poses whose every increment and orientation is turned by −offset(t) about
    z (the VO's heading error), starting at the truth's start."""
    offset = np.broadcast_to(np.asarray(offset, dtype=float), (len(gt),))
    turn = Rotation.from_euler("z", -offset[:, None]).as_matrix()
    middle = Rotation.from_euler("z", -0.5 * (offset[1:] + offset[:-1])[:, None]).as_matrix()
    steps = np.einsum("nij,nj->ni", middle, np.diff(gt.positions, axis=0))
    positions = np.concatenate([gt.positions[:1], gt.positions[0] + np.cumsum(steps, axis=0)])
    rotations = turn @ gt.orientations.as_matrix()
    return Trajectory(gt.t, positions, Rotation.from_matrix(rotations))


def _straight(n: int, step_m: float = 1.0, rate_hz: float = 10.0) -> Trajectory:
    t = np.arange(n) / rate_hz
    positions = np.column_stack([step_m * np.arange(n), np.zeros(n), np.zeros(n)])
    return Trajectory(t, positions, Rotation.identity(n))


@pytest.mark.parametrize("fit", [True, False])
def test_constant_offset_is_recovered_exactly_and_the_trajectory_equals_the_truth(fit):
    t, yaw, gt = _ground_truth()
    config = BlendConfig() if fit else FIXED
    result = blend_camera(_vo_output(gt), t, yaw, 0.01, config=config)
    # The VO starts at yaw 0, the truth at 2.5 rad: δ = 2.5 everywhere.
    np.testing.assert_allclose(result.correction, 2.5, atol=1e-9)
    np.testing.assert_allclose(result.vehicle.matrices, _expected(gt), atol=1e-9)
    assert result.noise.fitted == fit
    assert result.has_absolute.all() and result.measurements == len(t) - 1


def test_extrinsic_and_camera_output_are_honoured():
    t, yaw, gt = _ground_truth(n=60)
    mount = np.eye(4)
    mount[:3, :3] = Rotation.from_euler("Z", 0.2).as_matrix() @ FORWARD_CAMERA_TO_VEHICLE[:3, :3]
    mount[:3, 3] = [1.5, 0.3, 1.2]
    result = blend_camera(_vo_output(gt, mount), t, yaw, 0.01, camera_to_vehicle=mount)
    np.testing.assert_allclose(result.vehicle.matrices, _expected(gt), atol=1e-9)
    np.testing.assert_allclose(result.camera.matrices, _expected(gt) @ mount, atol=1e-9)


def test_forward_filter_is_causal_and_exact_from_the_first_measurement():
    t, yaw, gt = _ground_truth()
    result = blend_camera(_vo_output(gt), t, yaw, 0.01, config=BlendConfig(smooth=False))
    # The first measurement is the first step's course, at its middle time: before it (the
    # first pose) nothing is known and the VO is left as it is; from it on, exact.
    assert result.correction[0] == 0.0
    np.testing.assert_allclose(result.correction[1:], 2.5, atol=1e-9)
    np.testing.assert_allclose(result.vehicle.positions, _expected(gt)[:, :3, 3], atol=1e-9)
    np.testing.assert_allclose(result.vehicle.matrices[1:], _expected(gt)[1:], atol=1e-9)


def test_pitch_and_roll_are_untouched():
    t, yaw, gt = _ground_truth()
    drift = 0.02 * t
    vo = _turned_vo(gt, drift)
    result = blend_heading(vo, t, yaw, 0.01)
    euler_out = Rotation.from_matrix(result.vehicle.matrices[:, :3, :3]).as_euler("ZYX")
    euler_in = vo.orientations.as_euler("ZYX")
    np.testing.assert_allclose(euler_out[:, 1:], euler_in[:, 1:], atol=1e-12)
    # The offset follows the drift (0.4 rad over the drive, 0.002 rad per step): noise-free
    # headings, so closely inside; beyond the first and last measurements it is held.
    error = np.abs(wrap_angle(result.correction - drift))
    assert error[5:-5].max() < 1e-4 and error.max() < 0.0025


def test_noisy_headings_on_a_perfect_vo_kalman_beats_the_window():
    t, yaw, gt = _ground_truth(n=600, yaw0=0.3)
    vo = _turned_vo(gt, 0.0)
    # Headings at the steps' middle times, where the truth's course is the mean of the two
    # poses' yaws: each measurement has its own independent error.
    t_mid = 0.5 * (t[1:] + t[:-1])
    sigma = np.radians(1.0)
    level = {}

    def rmse(result):
        return np.sqrt(np.mean(wrap_angle(yaw_of(result.vehicle.matrices[:, :3, :3]) - yaw) ** 2))

    errors = {"kalman": [], "window": []}
    for seed in range(4):
        noise = sigma * np.random.default_rng(seed).standard_normal(len(t_mid))
        noisy = wrap_angle(0.5 * (yaw[1:] + yaw[:-1]) + noise)
        kalman = blend_heading(vo, t_mid, noisy, sigma, **level)
        errors["kalman"].append(rmse(kalman))
        errors["window"].append(
            rmse(correct_heading(vo, t_mid, noisy, reference="course", **level))
        )
        assert kalman.noise.sigma_distance < 1e-3
        assert 1 / 1.6 < kalman.noise.scale < 1.6
    # The window averages 20 epochs (≈ 0.22°); the smoother, seeing a VO that does not drift,
    # averages the whole drive (the mean of 599 errors: 0.04°).
    assert np.mean(errors["kalman"]) < 0.3 * np.mean(errors["window"])
    assert np.mean(errors["kalman"]) < np.radians(0.1)


def test_offset_across_the_wrap():
    gt = _straight(200)
    t = gt.t
    true_offset = np.linspace(3.0, 3.3, len(t))  # crosses +π
    vo = _turned_vo(gt, true_offset)
    config = BlendConfig(sigma_distance_rad_per_sqrt_m=0.02, sigma_turn=1e-3, measurement_scale=1.0)
    result = blend_heading(vo, t, np.zeros(len(t)), 1e-4, config=config)
    assert np.max(np.abs(wrap_angle(result.correction - true_offset))) < 1e-3
    assert np.max(np.abs(np.diff(result.correction))) < 0.01  # held unwrapped, no 2π jumps
    error = np.linalg.norm(result.vehicle.positions - (gt.positions - gt.positions[0]), axis=1)
    assert error.max() < 0.2


def test_circular_mean_of_measurements_either_side_of_pi():
    gt = _straight(100)
    absolute = np.where(np.arange(100) % 2 == 0, np.radians(179.0), np.radians(-179.0))
    result = blend_heading(gt, gt.t, absolute, np.radians(1.0))
    final_yaw = yaw_of(result.vehicle.matrices[-1:, :3, :3])[0]
    assert abs(wrap_angle(final_yaw - np.pi)) < np.radians(0.2)


def test_gap_forward_holds_and_smoother_interpolates_by_distance():
    gt = _straight(300)
    t = gt.t
    valid = (t < 10.0) | (t >= 20.0)
    offset = np.where(t < 15.0, 0.01, 0.03)  # the VO's error jumps inside the gap
    vo = _turned_vo(gt, offset)
    absolute = np.zeros(len(t))
    common = {}
    smooth = blend_heading(vo, t, absolute, 1e-5, valid, config=FIXED, **common)
    forward = blend_heading(
        vo,
        t,
        absolute,
        1e-5,
        valid,
        config=replace(FIXED, smooth=False),
        **common,
    )
    gap = (t > 10.05) & (t < 19.95)
    last_before = forward.correction[np.flatnonzero(t < 10.0)[-1]]
    assert last_before == pytest.approx(0.01, abs=1e-6)
    np.testing.assert_allclose(forward.correction[gap], last_before, atol=1e-12)
    # Straight at constant speed: the process variance grows linearly in time, so the smoother
    # goes linearly from the last estimate before the gap to the first after it.
    # Middles of the last and first steps with a measurement (9.95 lies between the epochs
    # 9.9 and 20.0, too far apart to interpolate).
    t_a, t_b = 9.85, 20.05
    line = 0.01 + (0.03 - 0.01) * (t[gap] - t_a) / (t_b - t_a)
    np.testing.assert_allclose(smooth.correction[gap], line, atol=1e-5)
    assert smooth.correction_sigma[gap].max() > 5 * np.median(smooth.correction_sigma[~gap])


def test_process_noise_fit_recovers_a_known_random_walk():
    rng = np.random.default_rng(3)
    sigma_d, sigma_r = 0.003, 0.01
    n = 3000
    distance = np.arange(n, dtype=float)  # 1 m between measurements, no turning
    t = distance / 10.0
    walk = np.cumsum(sigma_d * rng.standard_normal(n))
    measurements = OffsetMeasurements(
        t, walk + sigma_r * rng.standard_normal(n), np.full(n, sigma_r), np.zeros(n)
    )
    clock = DriftClock(t, distance, np.zeros(n))
    noise = fit_process_noise(measurements, clock, BlendConfig(sigma_turn=1e-4))
    # Grid steps are a factor 1.58: within one step either side.
    assert sigma_d / 1.6 < noise.sigma_distance < sigma_d * 1.6
    assert 1 / 1.6 < noise.scale < 1.6
    assert noise.fitted


def test_too_few_measurements_keep_the_defaults_and_the_floor_holds():
    clock = DriftClock(np.arange(5.0), np.arange(5.0), np.zeros(5))
    few = OffsetMeasurements(np.arange(5.0), np.zeros(5), np.full(5, 0.01), np.zeros(5))
    config = BlendConfig()
    noise = fit_process_noise(few, clock, config)
    assert not noise.fitted
    assert (noise.sigma_distance, noise.sigma_turn, noise.scale) == (
        config.default_sigma_distance_rad_per_sqrt_m,
        config.default_sigma_turn,
        1.0,
    )
    n = 400
    still = OffsetMeasurements(np.arange(n) / 10, np.zeros(n), np.full(n, 0.01), np.zeros(n))
    long_clock = DriftClock(np.arange(n) / 10, np.arange(n, dtype=float), np.zeros(n))
    assert (
        fit_process_noise(still, long_clock, config).sigma_distance
        == config.min_sigma_distance_rad_per_sqrt_m
    )


def test_correlated_headings_are_inflated_in_the_filter():
    gt = _straight(400)
    static = BlendConfig(sigma_distance_rad_per_sqrt_m=1e-9, sigma_turn=1e-9, measurement_scale=1.0)
    common = dict(config=static)
    white = blend_heading(gt, gt.t, np.zeros(len(gt)), 0.01, **common)
    correlated = blend_heading(gt, gt.t, np.zeros(len(gt)), 0.01, correlation_s=2.0, **common)
    # 20 measurements per 2 s carry one measurement's information: √20 less certain.
    ratio = correlated.correction_sigma[200] / white.correction_sigma[200]
    assert ratio == pytest.approx(np.sqrt(20.0), rel=1e-3)
    assert white.correction_sigma[200] == pytest.approx(0.01 / np.sqrt(399), rel=1e-3)


def test_filter_and_smoother_by_hand():
    z = np.array([0.0, 1.0])
    forward = forward_filter(z, np.array([1.0, 1.0]), np.array([0.0, 1.0]))
    # P⁻ = 1 + 1 = 2, S = 3, K = 2/3.
    np.testing.assert_allclose(forward.x, [0.0, 2.0 / 3.0])
    np.testing.assert_allclose(forward.P, [1.0, 2.0 / 3.0])
    assert forward.log_likelihood == pytest.approx(-0.5 * (np.log(2 * np.pi * 3.0) + 1.0 / 3.0))
    x, P = rts_smooth(forward)
    # C = 1/2: x₀ = 0 + ½·(2/3) = 1/3, P₀ = 1 + ¼·(2/3 − 2) = 2/3.
    np.testing.assert_allclose(x, [1.0 / 3.0, 2.0 / 3.0])
    np.testing.assert_allclose(P, [2.0 / 3.0, 2.0 / 3.0])
    wrapped = forward_filter(np.array([np.pi - 0.1, -np.pi + 0.1]), np.ones(2), np.zeros(2))
    assert wrapped.x[1] == pytest.approx(np.pi)


def test_robust_update_bounds_an_outliers_pull():
    r, q = np.array([1e-4, 1e-4]), np.array([0.0, 1e-4])
    for outlier in (1.0, 2.5):
        robust = forward_filter(np.array([0.0, outlier]), r, q, huber_k=3.0)
        # S = 3e-4, u = ν/√S > 3: δ moves by k·√S·P⁻/S = 3·2e-4/√3e-4 whatever the outlier.
        u = outlier / np.sqrt(3e-4)
        assert robust.x[1] == pytest.approx(6e-4 / np.sqrt(3e-4))
        assert robust.P[1] == pytest.approx((1.0 - 2.0 / u) * 2e-4)
    inside = forward_filter(np.array([0.0, 0.02]), r, q, huber_k=3.0)
    plain = forward_filter(np.array([0.0, 0.02]), r, q)
    np.testing.assert_allclose(inside.x, plain.x)
    assert inside.log_likelihood == pytest.approx(plain.log_likelihood)


def test_the_likelihood_is_a_contaminated_normal_whose_outliers_cost_at_most_ln_2pi_over_eps():
    r, q = np.array([1e-4, 1e-4]), np.array([0.0, 1e-4])
    S = 3e-4
    for innovation in (0.01, 0.5, 2.5):
        normal = -0.5 * innovation**2 / S - 0.5 * np.log(2 * np.pi * S)
        z = np.array([0.0, innovation])
        gaussian = forward_filter(z, r, q, huber_k=3.0).log_likelihood
        assert gaussian == pytest.approx(normal)
        for epsilon in (1e-3, 0.1):
            mixed = forward_filter(z, r, q, huber_k=3.0, outlier_fraction=epsilon).log_likelihood
            expected = np.log((1 - epsilon) * np.exp(normal) + epsilon / (2 * np.pi))
            assert mixed == pytest.approx(expected, rel=1e-12)
            assert mixed >= np.log(epsilon / (2 * np.pi))
    # one set of parameters per ε, side by side
    both = forward_filter(
        np.array([0.0, 2.5]), r, q, 3.0, outlier_fraction=np.array([1e-3, 0.1])
    ).log_likelihood
    assert both[1] > both[0]


def test_robust_update_follows_a_lasting_change_and_ignores_a_burst():
    lasting = forward_filter(np.r_[0.0, np.full(300, 0.35)], np.ones(301), np.full(301, 1e-3), 3.0)
    assert lasting.x[-1] == pytest.approx(0.35, abs=0.01)
    n = 400
    gt = _straight(n)
    yaw = np.zeros(n)
    yaw[150:180] = np.radians(20.0)  # three seconds of a reflected conventional heading
    fixed = BlendConfig(sigma_distance_rad_per_sqrt_m=1e-4, sigma_turn=1e-4, measurement_scale=1.0)
    common = {"config": fixed, "reference": "orientation"}
    robust = blend_heading(gt, gt.t, yaw, np.radians(0.5), **common)
    plain = blend_heading(
        gt, gt.t, yaw, np.radians(0.5), **{**common, "config": replace(fixed, huber_k=np.inf)}
    )
    assert np.degrees(np.abs(robust.correction).max()) < 0.5
    assert np.degrees(np.abs(plain.correction).max()) > 2.5


def test_robust_weight_judges_one_measurements_error_not_the_inflated_variance():
    # κ = 40 correlated measurements: r = 40·r₁ enters the gain, r₁ the robust weight.
    r, r_single, q = np.array([1e-4, 4e-3]), np.array([1e-4, 1e-4]), np.array([0.0, 1e-4])
    P_pred, S, S_single = 2e-4, 2e-4 + 4e-3, 2e-4 + 1e-4
    outlier = 0.18  # 10.4 σ of one measurement, but only 2.8 σ of the inflated S
    robust = forward_filter(np.array([0.0, outlier]), r, q, 3.0, r_single)
    # δ moves by k·√S₁·P⁻/S, whatever the outlier; judged against S it would move P⁻/S·0.18.
    assert robust.x[1] == pytest.approx(3.0 * np.sqrt(S_single) * P_pred / S)
    u = outlier / np.sqrt(S_single)
    assert robust.P[1] == pytest.approx((1.0 - P_pred / (S * u / 3.0)) * P_pred)
    assert robust.log_likelihood == pytest.approx(-0.5 * np.log(2 * np.pi * S_single) - 0.5 * u**2)
    blind = forward_filter(np.array([0.0, outlier]), r, q, 3.0)
    assert blind.x[1] == pytest.approx(P_pred / S * outlier)
    assert blind.x[1] > 3.0 * robust.x[1]


def test_robust_start_takes_the_median_only_when_the_first_is_an_outlier():
    first = np.arange(3)
    r, still = np.full(3, 1e-4), np.zeros(3)
    start = robust_start(np.array([0.5, 0.0, 0.001]), r, still, first, 3.0)
    assert start == pytest.approx(0.001)  # the median of 0.5, 0, 0.001
    # Within k·√(r₀ + r_m + Q_m − Q₀) of the median, the first measurement starts.
    # Still: 3·√2e-4 = 0.042; with 1e-4 of process variance up to the median: 3·√3e-4 = 0.052.
    drifting = np.array([0.0, 0.0, 1e-4])
    assert robust_start(np.array([0.05, 0.0, 0.001]), r, still, first, 3.0) == pytest.approx(0.001)
    assert robust_start(np.array([0.05, 0.0, 0.001]), r, drifting, first, 3.0) == pytest.approx(
        0.05
    )
    assert robust_start(np.array([0.055, 0.0, 0.001]), r, drifting, first, 3.0) == pytest.approx(
        0.001
    )
    across = robust_start(np.array([-np.pi + 0.3, np.pi - 0.01, np.pi - 0.02]), r, still, first, 3)
    assert across == pytest.approx(np.pi - 0.01)


def test_a_wrong_first_heading_does_not_start_the_blend():
    n = 400
    gt = _straight(n)
    yaw = np.zeros(n)
    yaw[0] = np.radians(30.0)  # the first heading is wrong
    config = BlendConfig(
        sigma_distance_rad_per_sqrt_m=1e-4, sigma_turn=1e-4, measurement_scale=1.0, smooth=False
    )
    common = {"config": config, "reference": "orientation"}
    robust = blend_heading(gt, gt.t, yaw, np.radians(0.5), **common)
    first = blend_heading(
        gt,
        gt.t,
        yaw,
        np.radians(0.5),
        **{**common, "config": replace(config, start_measurements=1)},
    )
    assert np.degrees(np.abs(robust.correction).max()) < 0.1
    assert np.degrees(np.abs(first.correction).max()) > 10.0


def test_pipeline_dispatches_on_the_method():
    t, yaw, gt = _ground_truth(n=80)
    heading = AbsoluteHeading(t, yaw, np.ones(len(t), bool), np.full(len(t), 0.01), 2.0)
    vo = _turned_vo(gt, 0.0)
    for method in ("window", "kalman"):
        out = correct(vo, heading, CorrectionConfig(method=method)).vehicle
        np.testing.assert_allclose(out.matrices, gt.matrices, atol=1e-9)
    with pytest.raises(
        ValueError,
        match=r"CorrectionConfig.method: unknown correction method 'median'; choose from "
        r"kalman, window$",
    ):
        CorrectionConfig(method="median")
    refused = r"unknown heading reference 'sideways'; choose from course, orientation$"
    with pytest.raises(ValueError, match="CorrectionConfig.reference: " + refused):
        CorrectionConfig(reference="sideways")
    with pytest.raises(ValueError, match="^reference: " + refused):
        blend_heading(vo, t, yaw, reference="sideways")


@pytest.mark.parametrize("extra", [[], ["--causal"]])
def test_correct_cli_kalman_recovers_the_enu_trajectory(tmp_path, capsys, extra):
    t, yaw, gt = _ground_truth(n=80)
    write_tum(tmp_path / "vo.tum", _vo_output(gt))
    table = _table(t, yaw, np.ones(len(t), bool), np.ones(len(t), bool))
    write_heading_csv(tmp_path / "heading.csv", table)
    out = tmp_path / "corrected.tum"
    args = ["correct", str(tmp_path / "vo.tum"), "--heading", str(tmp_path / "heading.csv")]
    args += ["--correction", "kalman", "--source", "tc", "-o", str(out), *extra]
    assert main(args) == 0
    corrected = read_tum(out)
    # Headings are rounded to 1e-4° in the CSV: 2e-6 rad over 80 m.
    np.testing.assert_allclose(corrected.positions, gt.positions - gt.positions[0], atol=1e-3)
    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["correction"] == "kalman" and summary["final_correction_deg"] == pytest.approx(
        np.degrees(2.5), abs=1e-3
    )


def test_velocity_heading_sigma_is_the_cross_track_sigma_over_the_speed():
    rotation = Rotation.from_euler("xyz", [0.3, -0.7, 1.1]).as_matrix()  # some ECEF→ENU
    velocity = np.array([[3.0, 4.0, 0.5], [-10.0, 0.0, 0.0], [0.0, 0.0, 2.0]])
    # East-north covariances: isotropic 0.04; then 1.0 along east only (along-track), which
    # leaves a westward velocity's yaw exact; a vertical velocity has no yaw.
    enu = np.zeros((3, 3, 3))
    enu[0] = 0.04 * np.eye(3)
    enu[1, 0, 0], enu[1, 1, 1], enu[1, 2, 2] = 1.0, 1e-4, 9.0
    enu[2] = np.eye(3)
    ecef = rotation.T @ enu @ rotation
    sigma = velocity_heading_sigma(velocity, ecef, rotation)
    np.testing.assert_allclose(sigma[:2], [0.2 / 5.0, 0.01 / 10.0], rtol=1e-9)
    assert np.isnan(sigma[2])


def test_without_any_absolute_heading_the_vo_is_left_as_it_is():
    t, yaw, gt = _ground_truth(n=50)
    vo = _turned_vo(gt, 0.3)
    level = {}
    for smooth in (True, False):
        result = blend_heading(
            vo, t, yaw, 0.01, np.zeros(len(t), bool), config=BlendConfig(smooth=smooth), **level
        )
        assert result.measurements == 0 and not result.noise.fitted
        np.testing.assert_allclose(result.correction, 0.0)
        np.testing.assert_allclose(result.vehicle.matrices, vo.matrices, atol=1e-12)


@pytest.mark.parametrize("command", ["run", "correct"])
def test_unknown_correction_method_is_a_usage_error(tmp_path, command):
    args = [command, str(tmp_path), "-o", str(tmp_path / "out"), "--correction", "median"]
    if command == "correct":
        args += ["--heading", str(tmp_path / "h.csv")]
    with pytest.raises(SystemExit) as exit_info:
        main(args)
    assert exit_info.value.code == 2


def test_correct_cli_kalman_weighs_conventional_headings_by_their_sigma(tmp_path):
    """Conventional headings alternate, 10 epochs each, between the truth (σ 0.1°) and 3° off
    (σ 10°): with the σ column the blend follows the precise ones; without it (old files) it
    averages them."""
    t, yaw, gt = _ground_truth(n=80)
    write_tum(tmp_path / "vo.tum", _vo_output(gt))
    precise = (np.arange(len(t)) // 10) % 2 == 0
    table = _table(t, yaw, np.zeros(len(t), bool), np.ones(len(t), bool))
    table = replace(
        table,
        yaw_conv=np.where(precise, yaw, yaw + np.radians(3.0)),
        sigma_conv=np.radians(np.where(precise, 0.1, 10.0)),
    )
    errors = {}
    for name, keep_sigma in (("with", True), ("without", False)):
        path = tmp_path / f"heading_{name}.csv"
        write_heading_csv(path, table)
        if not keep_sigma:
            lines = [line.rsplit(",", 3)[0] for line in path.read_text().splitlines()]
            path.write_text("\n".join(lines) + "\n")
            assert np.isnan(read_heading_csv(path).sigma_conv).all()
        else:
            np.testing.assert_allclose(read_heading_csv(path).sigma_conv, table.sigma_conv)
        out = tmp_path / f"corrected_{name}.tum"
        args = ["correct", str(tmp_path / "vo.tum"), "--heading", str(path)]
        assert main([*args, "--correction", "kalman", "--source", "conv", "-o", str(out)]) == 0
        corrected = read_tum(out)
        errors[name] = np.abs(wrap_angle(yaw_of(corrected.orientations.as_matrix()) - yaw))
    assert np.degrees(np.median(errors["with"])) < 0.1
    assert np.degrees(np.median(errors["without"])) > 1.0


def _burst_headings(seed: int, burst_deg: float):
    """A drift-free VO of a 120-s drive and 10-Hz headings with 1° of white noise, one second
    ``burst_deg`` off at the start and at 50 s and 1.5 s 0.4·``burst_deg`` the other way at
    80 s (reflected conventional headings)."""
    t, yaw, gt = _ground_truth(n=1200, yaw0=0.3)
    t_mid = 0.5 * (t[1:] + t[:-1])
    error = np.radians(1.0) * np.random.default_rng(seed).standard_normal(len(t_mid))
    for start, length, size in ((0.0, 1.0, 1.0), (50.0, 1.0, 1.0), (80.0, 1.5, -0.4)):
        error[(t_mid >= start) & (t_mid < start + length)] += np.radians(size * burst_deg)
    return _turned_vo(gt, 0.0), t_mid, wrap_angle(0.5 * (yaw[1:] + yaw[:-1]) + error), yaw


def _yaw_rmse(result, yaw) -> float:
    return float(
        np.sqrt(np.mean(wrap_angle(yaw_of(result.vehicle.matrices[:, :3, :3]) - yaw) ** 2))
    )


@pytest.mark.parametrize("burst_deg", [30.0, 145.0])
def test_reflected_bursts_do_not_make_the_vo_follow_the_headings(burst_deg):
    """Under Huber's ρ the fit made the VO follow every heading (σ_d 0.02–0.06 rad/√m, the
    corrected yaw 2.9–15.6° RMS off); the contaminated likelihood and the wider start keep the
    drift-free VO and put the bursts down as outliers."""
    vo, t_heading, headings, yaw = _burst_headings(0, burst_deg)
    result = blend_heading(vo, t_heading, headings, np.radians(1.0))
    assert result.noise.sigma_distance == BlendConfig().min_sigma_distance_rad_per_sqrt_m
    assert result.noise.outlier_fraction >= 0.01
    assert _yaw_rmse(result, yaw) < np.radians(0.1)


@pytest.mark.slow
def test_persisting_faults_raise_the_correlation_floor_until_the_innovations_are_white():
    vo, t_heading, headings, yaw = _burst_headings(0, 145.0)
    whitened = blend_heading(vo, t_heading, headings, np.radians(1.0))
    as_given = blend_heading(
        vo, t_heading, headings, np.radians(1.0), config=BlendConfig(max_correlation_s=0.0)
    )
    assert as_given.noise.correlation_floor_s == 0.0
    assert whitened.noise.correlation_floor_s >= 0.5
    assert _yaw_rmse(whitened, yaw) < _yaw_rmse(as_given, yaw)
    noise = np.radians(1.0) * np.random.default_rng(0).standard_normal(len(t_heading))
    white = wrap_angle(0.5 * (yaw[1:] + yaw[:-1]) + noise)
    assert blend_heading(vo, t_heading, white, np.radians(1.0)).noise.correlation_floor_s == 0.0


@settings(max_examples=300, deadline=None)
@given(
    period_ms=st.sampled_from([10, 50, 100, 200, 1000]),
    steps=st.lists(st.integers(min_value=1, max_value=4), min_size=1, max_size=60),
    gaps=st.lists(st.integers(min_value=0, max_value=6), min_size=61, max_size=61),
    shift=st.one_of(st.just(1e9), st.floats(min_value=0.0, max_value=1e9, allow_nan=False)),
)
def test_decimate_keeps_the_same_measurements_whatever_the_time_origin(
    period_ms, steps, gaps, shift
):
    """Times and spacings in whole sampling periods (a receiver's or a camera's), so that a
    measurement often lies exactly one spacing after the last kept one: the kept indices are
    those of the rule on whole periods, at the origin 0 and after any shift up to 10⁹ s (GPS
    time), where a time carries 1.2·10⁻⁷ s of rounding."""
    periods = np.concatenate([[0], np.cumsum(steps)])
    t = 1e-3 * period_ms * periods
    spacing = 1e-3 * period_ms * np.asarray(gaps[: len(t)], dtype=float)
    kept, last = [], None
    for j in range(len(t)):
        if last is None or periods[j] - periods[last] >= gaps[j]:
            kept.append(j)
            last = j
    np.testing.assert_array_equal(decimate(t, spacing), kept)
    np.testing.assert_array_equal(decimate(t + shift, spacing), kept)


def test_a_10_hz_burst_is_kept_whole_at_image_time_and_at_gps_time():
    """Issue 30: 30 headings 0.1 s apart with a spacing of 0.1 s; at 10⁹ s rounding dropped 5
    (and at 0 s, 4: 0.1·k is not exact either)."""
    t = 0.1 * np.arange(30)
    for origin in (0.0, 1e9, 1.3e9 + 0.05):
        np.testing.assert_array_equal(decimate(t + origin, np.full(30, 0.1)), np.arange(30))


@pytest.mark.parametrize("method", ["kalman", "window"])
def test_the_correction_does_not_depend_on_the_time_origin(method):
    """The same drive and headings on image time (0 s) and on GPS time (10⁹ s): the same
    fitted noise and the same corrected poses."""
    vo, t_heading, headings, _ = _burst_headings(0, 30.0)
    heading = AbsoluteHeading(t_heading, headings, np.ones(len(t_heading), bool), 0.02)
    config = CorrectionConfig(method=method)
    at_zero = correct(vo, heading, config)
    shifted = Trajectory(vo.t + 1e9, vo.positions, vo.orientations)
    at_gps = correct(shifted, replace(heading, t=t_heading + 1e9), config)
    np.testing.assert_array_equal(at_gps.vehicle.t, shifted.t)
    np.testing.assert_array_equal(at_gps.has_absolute, at_zero.has_absolute)
    np.testing.assert_allclose(at_gps.vehicle.matrices, at_zero.vehicle.matrices, atol=1e-6)
    np.testing.assert_allclose(at_gps.correction, at_zero.correction, atol=1e-7)
    if method == "kalman":
        assert at_gps.noise == at_zero.noise
        assert at_gps.measurements == at_zero.measurements
