"""The real canyon (``simulate --canyon-realism real``) against the figures measured on a real
1-Hz canyon drive (u-blox M8T, Hong Kong Tsim Sha Tsui; residuals against ground truth, the
clock removed): Doppler error per C/N0 bin and per speed, the C/N0 mix, the satellites biased
per 5-s window, the clock drift's epoch-to-epoch jumps; and a written 1-Hz sequence that
``vo-doppler run`` reads."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from vo_doppler.cli import main
from vo_doppler.geo import SPEED_OF_LIGHT
from vo_doppler.sim.canyon_realism import (
    knife_edge_loss_db,
    real_canyon_config,
    thermal_sigma_mps,
)
from vo_doppler.sim.gnss_observations import GnssSimConfig
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

MOVING_MPS = 3.0
STANDSTILL_MPS = 0.2


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    """A 300-s, 1-Hz realistic canyon drive at city speeds (at most 36 km/h, as in Tsim Sha
    Tsui), fixed seed; per row its Doppler error against the direct path, C/N0 and speed."""
    config = UrbanCanyonConfig(
        duration_s=300.0,
        seed=0,
        render=False,
        max_speed_mps=10.0,
        gnss=real_canyon_config(GnssSimConfig(rate_hz=1.0)),
    )
    sim = simulate_urban_canyon(tmp_path_factory.mktemp("real_canyon"), config)
    gnss = sim.gnss
    error = -gnss.wavelength_m * gnss.doppler_hz - gnss.range_rate_direct_mps
    speed = sim.vehicle(gnss.t_true).speed[gnss.epoch]
    return sim, error, gnss.cn0_dbhz, speed


def _mad(values: np.ndarray) -> float:
    return float(np.median(np.abs(values)))


REAL_BINS = [
    (0.0, 25.0, 2.0, 1.3, 3.2),
    (25.0, 30.0, 1.1, 0.6, 1.8),
    (30.0, 35.0, 0.28, 0.15, 0.5),
    (35.0, 99.0, 0.15, 0.08, 0.25),
]
"""C/N0 bin (dB-Hz), the real drive's MAD (m/s) and the range accepted here."""


@pytest.mark.slow
@pytest.mark.parametrize(("low", "high", "real_mad", "lowest", "highest"), REAL_BINS)
def test_doppler_error_per_cn0_bin_is_the_real_drives(drive, low, high, real_mad, lowest, highest):
    """Moving rows: MAD 2.0 / 1.1 / 0.28 / 0.13–0.17 m/s on the real drive."""
    _, error, cn0, speed = drive
    rows = (speed > MOVING_MPS) & (cn0 >= low) & (cn0 < high)
    assert rows.sum() > 100
    mad = _mad(error[rows])
    assert lowest <= mad <= highest, f"MAD {mad:.2f} m/s, real {real_mad:g}"


@pytest.mark.slow
def test_weak_rows_are_heavy_tailed_and_strong_ones_are_not(drive):
    """Real: 22 % of the rows below 25 dB-Hz beyond 3 m/s; none of the strong ones."""
    _, error, cn0, speed = drive
    moving = speed > MOVING_MPS
    beyond = np.abs(error) > 3.0
    assert 0.15 <= beyond[moving & (cn0 < 25.0)].mean() <= 0.5
    assert beyond[moving & (cn0 >= 35.0)].mean() < 0.01


@pytest.mark.slow
def test_weak_signal_error_grows_with_speed(drive):
    """Real rows below 30 dB-Hz: MAD 0.18 m/s at standstill, 1.6 m/s at 3–10 m/s."""
    _, error, cn0, speed = drive
    weak = cn0 < 30.0
    standing = weak & (speed < STANDSTILL_MPS)
    driving = weak & (speed >= MOVING_MPS) & (speed < 10.0)
    assert standing.sum() > 20 and driving.sum() > 100
    assert 0.1 <= _mad(error[standing]) <= 0.3
    assert 1.0 <= _mad(error[driving]) <= 2.4


@pytest.mark.slow
def test_speed_coefficient_falls_about_tenfold_per_ten_db(drive):
    """k(C/N0) of σ² = σ_th² + (k·speed)²: 0.22 at 25 dB-Hz, 0.023 at 35 on the real drive.
    Here k from the moving rows' robust σ of error/speed within ±2 dB."""
    _, error, cn0, speed = drive
    moving = speed > MOVING_MPS

    def k(center: float) -> float:
        rows = moving & (np.abs(cn0 - center) < 2.0)
        return 1.4826 * _mad(error[rows] / speed[rows])

    assert 0.1 <= k(25.0) <= 0.5
    assert 4.0 <= k(25.0) / k(35.0) <= 25.0


@pytest.mark.slow
def test_the_cn0_mix_is_weak_while_moving(drive):
    """Real: 37 % of the moving rows below 30 dB-Hz, most between 25 and 35. With GPS + Galileo
    the simulated sky has half the real GPS + BeiDou satellites, so fewer strong ones."""
    _, _, cn0, speed = drive
    moving = cn0[speed > MOVING_MPS]
    assert 0.3 <= np.mean(moving < 30.0) <= 0.65
    assert np.mean(moving >= 35.0) >= 0.2
    assert cn0.min() >= 22.0 - 5.0


@pytest.mark.slow
def test_three_to_seven_satellites_are_biased_per_five_second_window(drive):
    """A satellite is biased in a window when its median error exceeds 3 σ_th of its rows."""
    sim, error, cn0, speed = drive
    gnss = sim.gnss
    sigma = thermal_sigma_mps(sim.config.gnss, cn0)
    window = ((gnss.epoch_time[gnss.epoch] - gnss.epoch_time[0]) // 5.0).astype(int)
    satellite = gnss.satellite
    counts = []
    for w in np.unique(window):
        rows = window == w
        if np.median(speed[rows]) < MOVING_MPS:
            continue
        counts.append(
            sum(
                abs(np.median(error[rows & (satellite == s)]))
                > 3.0 * np.median(sigma[rows & (satellite == s)])
                for s in np.unique(satellite[rows])
            )
        )
    assert len(counts) > 40
    assert 3.0 <= np.median(counts) <= 7.0
    assert np.mean((np.array(counts) >= 3) & (np.array(counts) <= 7)) > 0.6


@pytest.mark.slow
def test_clock_drift_jumps_about_0_17_mps_per_epoch(drive):
    sim, error, _, _ = drive
    steps = np.diff(SPEED_OF_LIGHT * sim.gnss.clock.drift)  # as range rates (m/s)
    assert np.std(steps) == pytest.approx(0.17, rel=0.15)
    # the jumps are common to every satellite of an epoch: one clock per epoch removes them
    gnss = sim.gnss
    drift = SPEED_OF_LIGHT * gnss.clock.drift[gnss.epoch]
    with_clock = -gnss.wavelength_m * gnss.doppler_hz - (gnss.range_rate_direct_mps - drift)
    assert np.allclose(with_clock - error, drift)


def test_knife_edge_loss_is_itu_r_p526():
    """6 dB at grazing incidence (ν = 0), 0 below ν = −0.78, about 13 dB at ν = 1."""
    loss = knife_edge_loss_db(np.array([-1.0, 0.0, 1.0, 2.4]))
    assert loss[0] == 0.0
    assert loss[1] == pytest.approx(6.0, abs=0.1)
    assert loss[2] == pytest.approx(13.9, abs=0.1)
    assert loss[3] == pytest.approx(20.4, abs=0.2)


@pytest.mark.slow
def test_a_1_hz_realistic_canyon_from_the_command_line_is_a_sequence_run_reads(tmp_path):
    seq, out = tmp_path / "seq", tmp_path / "out"
    argv = ["-q", "simulate", "--duration", "40", "--seed", "1", "--gnss-rate", "1"]
    argv += ["--max-speed", "36", "--canyon-realism", "real", "--no-images", "-o", str(seq)]
    assert main(argv) == 0
    manifest = yaml.safe_load((seq / "sequence.yaml").read_text())
    assert manifest["gnss"]["rate_hz"] == 1.0
    assert "--canyon-realism real" in manifest["command"]
    assert manifest["truth"]["gnss"]["canyon"]["scatter_loss_db"] == 20.0
    assert manifest["truth"]["gnss"]["clock_drift_walk_mps_per_sqrt_s"] == 0.17
    assert main(["-q", "run", str(seq), "-o", str(out)]) == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["gnss_epochs"] == 41


@pytest.mark.slow
def test_without_the_option_the_manifest_has_no_canyon_settings(tmp_path):
    assert main(["-q", "simulate", "--duration", "3", "--no-images", "-o", str(tmp_path)]) == 0
    manifest = yaml.safe_load((tmp_path / "sequence.yaml").read_text())
    assert "canyon" not in manifest["truth"]["gnss"]
    assert "--canyon-realism" not in manifest["command"]
