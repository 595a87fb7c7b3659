"""The Hong Kong F9P canyon drive without ground truth (Kowloon Tong, u-blox F9P, 1 Hz, 205
epochs; ../shared/data), issue 29's acceptance: the tight heading available on ≥ 90 % of the
moving epochs and within 3° (p95) of the valid conventional headings whose σ < 1°.

The recording has no reference trajectory, so ``benchmarks/real_sequences.py`` derives one from
the receiver itself (its valid conventional Doppler velocities, running medians over 5 s) and
synthesises the vehicle signals from it: the figures are self-consistency, not accuracy
(``benchmarks/real_heading.py`` prints them). Measured with the receiver's σ model
(``--noise receiver``), seed 0: the robust method (what ``auto`` runs at 1 Hz) has the tight
heading on 100 % of the 104 moving epochs; against heading.csv's valid conventional headings
with σ < 1° (36 moving epochs) median 0.37°, p95 1.80°, none beyond 3°; against the GNSS
stage's (86) median 0.54°, p95 2.64°, 2 beyond 3°. The snooping method has it on 72.1 % only
(issue 29's 90 % does not hold for it), with p95 1.21° / 1.45° against the same two sets.
Calibration: gyro bias 0.499 °/s (synthesised 0.5), wheel scale 0.9814 (1/1.02 = 0.9804 of the
receiver's own speed). The first two tests check how the reference is made, on exact synthetic
velocities (fast)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from benchmarks.real_heading import evaluate_folder
from benchmarks.real_sequences import (
    HK_KLT_DRIVE,
    SELF_REFERENCE_FILE,
    WHEEL_SCALE,
    read_self_reference,
    self_reference,
    write_sequence,
)
from tests.conftest import require_shared
from vo_doppler.io.sequence import read_sequence


def _velocity(t, east, north, valid=None):
    """The fields of a velocity solution that :func:`self_reference` reads."""
    enu = np.column_stack([east, north, np.zeros(len(t))])
    valid = np.ones(len(t), dtype=bool) if valid is None else valid
    return SimpleNamespace(t=np.asarray(t, dtype=float), velocity_enu=enu, valid=valid)


def test_the_reference_ignores_an_outlying_and_an_invalid_epoch():
    t = np.arange(12.0)
    east, north = np.full(12, 4.0), np.full(12, 3.0)
    valid = np.ones(12, dtype=bool)
    east[4], north[4] = -20.0, 9.0  # valid, far off: the median outvotes it
    east[8], north[8], valid[8] = np.nan, np.nan, False  # not valid: its neighbours fill it
    speed, yaw = self_reference(_velocity(t, east, north, valid))
    np.testing.assert_allclose(speed, 5.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(yaw, np.arctan2(3.0, 4.0), rtol=0, atol=1e-12)


def test_the_reference_keeps_a_steady_turn_and_holds_the_course_through_a_stop():
    t = np.arange(30.0)
    yaw_true = 0.2 + np.radians(3.0) * t  # 3 °/s: both components monotone over 87°
    speed_true = np.where(t < 20, 6.0, 0.0)
    east, north = speed_true * np.cos(yaw_true), speed_true * np.sin(yaw_true)
    speed, yaw = self_reference(_velocity(t, east, north))
    inside = (t >= 2) & (t <= 17)  # full 5-s windows within the turn: the middle epoch's
    np.testing.assert_allclose(yaw[inside], yaw_true[inside], rtol=0, atol=1e-12)
    np.testing.assert_allclose(speed[inside], 6.0, rtol=0, atol=1e-12)
    stopped = t >= 20  # most of every window stands: speed 0, the course of t = 19 s held
    np.testing.assert_allclose(speed[stopped], 0.0, rtol=0, atol=0)
    np.testing.assert_allclose(yaw[stopped], yaw[19], rtol=0, atol=0)
    assert speed[19] >= 1.0 and abs(yaw[19] - yaw_true[19]) < np.radians(6.0)


@pytest.fixture(scope="module")
def drive(tmp_path_factory):
    require_shared(HK_KLT_DRIVE.folder)
    folder = write_sequence(HK_KLT_DRIVE, require_shared("."), tmp_path_factory.mktemp("hk"))
    figures = evaluate_folder(folder, None, ("receiver",), ("snooping", "robust"), "ls")
    return folder, figures["receiver"]


@pytest.mark.slow
def test_the_folder_has_no_ground_truth_and_a_reference_from_the_receiver(drive):
    folder, figures = drive
    sequence = read_sequence(folder)
    assert sequence.truth is None and not (folder / "ground_truth.tum").exists()
    reference = read_self_reference(folder)
    assert reference.t.size == figures["epochs"] == 205
    # about 730 m at 3 m/s median (the recording's description); measured 673 m, 3.07 m/s
    assert 600.0 < np.trapezoid(reference.value, reference.t) < 800.0
    assert 2.8 < np.median(reference.value) < 3.3
    # the wheels follow the reference: scale 1.02 and 0.02 m/s of noise
    wheel = np.interp(reference.t, sequence.wheel_speed.t, sequence.wheel_speed.value)
    moving = reference.value > 3.0
    ratio = wheel[moving] / reference.value[moving]
    assert np.median(ratio) == pytest.approx(WHEEL_SCALE, abs=0.005)
    assert (folder / SELF_REFERENCE_FILE).exists()


@pytest.mark.slow
def test_robust_tight_heading_is_available_and_agrees_with_confident_conventional_headings(drive):
    _, figures = drive
    robust = figures["methods"]["robust"]["self_consistency"]
    assert robust["moving_epochs"] == 104
    assert robust["tc_available"] >= 0.90  # measured 100 %
    for flags, compared in (("heading.csv", 30), ("GNSS stage", 80)):
        against = robust["against"][flags]
        assert against["compared_epochs"] >= compared  # measured 36 and 86
        assert against["tc_minus_conv_deg"]["median"] <= 1.0  # 0.37° and 0.54°
        assert against["tc_minus_conv_deg"]["p95"] <= 3.0  # 1.80° and 2.64°
    assert robust["against"]["heading.csv"]["beyond_consistent"] == 0
    assert robust["against"]["GNSS stage"]["beyond_consistent"] <= 3  # measured 2
    assert abs(robust["gyro_bias_dps"] - 0.5) <= 0.05
    assert abs(robust["wheel_scale"] * WHEEL_SCALE - 1.0) <= 0.005


@pytest.mark.slow
def test_snooping_tight_heading_agrees_where_it_is_available(drive):
    _, figures = drive
    snooping = figures["methods"]["snooping"]["self_consistency"]
    # measured 72.1 %: below issue 29's 90 %, which the robust method meets
    assert snooping["tc_available"] >= 0.65
    for flags in ("heading.csv", "GNSS stage"):
        assert snooping["against"][flags]["tc_minus_conv_deg"]["p95"] <= 3.0  # 1.21°, 1.45°
