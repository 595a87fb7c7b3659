"""Real Doppler, emulated street canyon (issue 4 acceptance) on the Yamatogawa u-blox walk.

Construction: the all-satellite conventional Doppler velocity gives the reference course
(where the horizontal speed is ≥ 0.3 m/s) and the speed series (horizontal speed). A gyro
series is synthesised from that course (rate between consecutive epochs = course change over
the interval, zero where no course exists such as the first-minute standstill) plus a bias of
0.5 deg/s and white noise of 0.1 deg/s at 10 Hz. After the first 60 s only the two
highest-elevation satellites are kept at each epoch, and line-of-sight vectors come from the
last fix before the canyon. Calibration happens in the open part (here a standstill, so the
bias comes from the stationary-run extension of sec. 3.4).

Window: this receiver logs at 1 Hz, so the design's "≈2 s" window holds only two epochs (four
rows for three unknowns). The acceptance run uses an 8 s window (8 epochs, 16 rows); the 2 s
figures are asserted as what they are (see test_two_second_window_is_too_short_at_1hz).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.conftest import require_shared
from vo_doppler.cli import main
from vo_doppler.geo import wrap_angle
from vo_doppler.gnss.pipeline import gnss_velocity
from vo_doppler.heading.conventional import ConventionalVelocity, heading_from_velocity
from vo_doppler.heading.from_gnss import emulated_canyon
from vo_doppler.heading.pipeline import HeadingPipelineConfig, heading_pipeline
from vo_doppler.heading.smoother import HeadingSmootherConfig
from vo_doppler.heading.tight_heading import TightHeadingConfig
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.sensor_csv import write_sensor_csv
from vo_doppler.io.trajectory import write_tum
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.sim.doppler_rows import gyro_from_heading

pytestmark = [pytest.mark.shared_data, pytest.mark.slow]

FOLDER = "yamatogawa_ublox_walk"
BIAS = np.radians(0.5)
OPEN_SKY_S = 60.0
WALKING_SPEED_MPS = 0.3


@pytest.fixture(scope="module")
def walk():
    obs = read_obs(require_shared(f"{FOLDER}/yamatogawa_rover.obs"))
    nav = read_nav([require_shared(f"{FOLDER}/yamatogawa_rover.nav")])
    # the reference: the open-sky Doppler velocity weighted by the a-priori σ, as measured when
    # this test was written (the rest factor and speed share fitted to this walker move it)
    reference = gnss_velocity(obs, nav, "G", moving_noise=False).velocity
    t = obs.epoch_time
    horizontal = np.hypot(reference.velocity_enu[:, 0], reference.velocity_enu[:, 1])
    course_ok = reference.valid & (horizontal >= WALKING_SPEED_MPS)
    yaw_ref, _ = heading_from_velocity(reference.velocity_enu, course_ok, WALKING_SPEED_MPS)
    t_gyro, rate = gyro_from_heading(t, yaw_ref, course_ok, BIAS, np.radians(0.1), 10.0, seed=1)
    canyon_rows, canyon_conv = emulated_canyon(obs, nav, 2, t[0] + OPEN_SKY_S, "G")
    return {
        "obs": obs,
        "t": t,
        "yaw_ref": yaw_ref,
        "walking": (t >= t[0] + OPEN_SKY_S) & course_ok,
        "speed": SensorSeries(t[reference.valid], horizontal[reference.valid]),
        "yaw_rate": SensorSeries(t_gyro, rate),
        "rows": canyon_rows,
        "conventional": canyon_conv,
    }


def _run(walk, window_s):
    return _with_config(walk, HeadingPipelineConfig(tight=TightHeadingConfig(window_s=window_s)))


def _with_config(walk, config):
    return heading_pipeline(
        walk["t"],
        walk["rows"].in_enu(),
        ConventionalVelocity(walk["conventional"].velocity_enu, walk["conventional"].valid),
        VehicleSignals(walk["speed"], walk["yaw_rate"]),
        config,
    )


def test_emulated_canyon_heading(walk):
    walking = walk["walking"]
    assert walking.sum() > 120  # about 140 walking epochs after the standstill
    rows = walk["rows"]
    late = rows.t >= walk["t"][0] + OPEN_SKY_S
    per_epoch = np.bincount(rows.epoch[late])
    assert per_epoch[per_epoch > 0].max() == 2
    table = _run(walk, 8.0)
    assert not table.conv_valid[walking].any()  # conventional: 0 % in the canyon
    available = table.tc_available[walking].mean()
    difference = np.degrees(np.abs(wrap_angle(table.yaw_tc - walk["yaw_ref"])))[walking]
    assert available >= 0.90
    assert np.nanmedian(difference) <= 3.0
    bias_in_canyon = table.gyro_bias[walking]
    assert np.all(bias_in_canyon == bias_in_canyon[0])  # calibrated in the open part, held
    assert abs(np.degrees(bias_in_canyon[0] - BIAS)) <= 0.05


def test_two_second_window_is_too_short_at_1hz(walk):
    table = _run(walk, 2.0)
    walking = walk["walking"]
    difference = np.degrees(np.abs(wrap_angle(table.yaw_tc - walk["yaw_ref"])))[walking]
    # Measured 0.89: windows of 4 rows for 3 unknowns often have a cost so flat that the
    # profile-based σ exceeds the 20° limit (the curvature alone gave 0.93 available).
    assert table.tc_available[walking].mean() >= 0.85
    assert np.nanmedian(difference) > 3.0  # measured 5.4°: 4 rows for 3 unknowns per window


def test_heading_cli_on_the_walk(walk, tmp_path):
    write_sensor_csv(tmp_path / "yaw.csv", walk["yaw_rate"], "yaw_rate_rad_s")
    write_sensor_csv(tmp_path / "speed.csv", walk["speed"], "speed_mps")
    known = np.isfinite(walk["yaw_ref"])  # the reference course stands in for ground truth
    truth = Trajectory(
        walk["t"][known],
        np.zeros((known.sum(), 3)),
        Rotation.from_euler("z", walk["yaw_ref"][known][:, None]),
    )
    write_tum(tmp_path / "truth.tum", truth)
    folder = require_shared(FOLDER)
    out = tmp_path / "heading.csv"
    code = main(
        [
            "heading",
            str(folder / "yamatogawa_rover.obs"),
            "--nav",
            str(folder / "yamatogawa_rover.nav"),
            "--systems",
            "G",
            "--yaw-rate-csv",
            str(tmp_path / "yaw.csv"),
            "--speed-csv",
            str(tmp_path / "speed.csv"),
            "--max-sats",
            "2",
            "--max-sats-after",
            "60",
            "--window-s",
            "8",
            "--heading-method",
            "snooping",
            "--gt",
            str(tmp_path / "truth.tum"),
            "-o",
            str(out),
        ]
    )
    assert code == 0
    assert out.with_suffix(".png").stat().st_size > 10_000
    table = read_heading_csv(out)
    expected = _run(walk, 8.0)
    np.testing.assert_array_equal(table.tc_available, expected.tc_available)
    ok = expected.tc_available
    np.testing.assert_allclose(wrap_angle(table.yaw_tc[ok] - expected.yaw_tc[ok]), 0.0, atol=1e-5)


CAN_DBC = """VERSION ""
BS_:
BU_: XXX
BO_ 36 KIN: 8 XXX
 SG_ YAW_RATE : 7|16@0- (0.01,0) [-300|300] "deg/s" XXX
BO_ 170 WHEELS: 8 XXX
 SG_ WL : 7|16@0+ (0.001,0) [0|60] "km/h" XXX
 SG_ WR : 23|16@0+ (0.001,0) [0|60] "km/h" XXX
"""


def test_heading_cli_from_a_can_log(walk, tmp_path):
    """The same run with the sensors packed into a candump log on a clock 1000 s behind GPS,
    the yaw rate clockwise-positive on the bus (flipped by --yaw-rate-sign -1)."""
    import can
    import cantools

    db = cantools.database.load_string(CAN_DBC, "dbc")
    (tmp_path / "car.dbc").write_text(CAN_DBC)
    kin, wheels = db.get_message_by_name("KIN"), db.get_message_by_name("WHEELS")
    offset = 1000.0
    yaw, speed = walk["yaw_rate"], walk["speed"]
    with can.Logger(str(tmp_path / "car.log")) as log:
        for t, w in zip(yaw.t, yaw.value, strict=True):
            data = kin.encode({"YAW_RATE": -np.degrees(w)})
            log.on_message_received(
                can.Message(
                    timestamp=t - offset, arbitration_id=36, data=data, is_extended_id=False
                )
            )
        for t, v in zip(speed.t, speed.value, strict=True):
            data = wheels.encode({"WL": 3.6 * v, "WR": 3.6 * v})
            log.on_message_received(
                can.Message(
                    timestamp=t - offset + 0.01, arbitration_id=170, data=data, is_extended_id=False
                )
            )
    folder = require_shared(FOLDER)
    out = tmp_path / "heading.csv"
    args = [
        "heading",
        str(folder / "yamatogawa_rover.obs"),
        "--nav",
        str(folder / "yamatogawa_rover.nav"),
        "--systems",
        "G",
        "--max-sats",
        "2",
        "--max-sats-after",
        "60",
        "--window-s",
        "8",
        "--heading-method",
        "snooping",
        "-o",
        str(out),
        "--can",
        str(tmp_path / "car.log"),
        "--dbc",
        str(tmp_path / "car.dbc"),
        "--yaw-rate",
        "KIN.YAW_RATE",
        "--wheel-speed",
        "WHEELS.WL,WHEELS.WR",
        "--yaw-rate-sign",
        "-1",
        "--time-offset-can",
        str(offset),
    ]
    assert main(args) == 0
    table = read_heading_csv(out)
    walking = walk["walking"]
    difference = np.degrees(np.abs(wrap_angle(table.yaw_tc - walk["yaw_ref"])))[walking]
    assert table.tc_available[walking].mean() >= 0.90 and np.nanmedian(difference) <= 3.0
    assert abs(np.degrees(table.gyro_bias[walking][0] - BIAS)) <= 0.05
    with pytest.raises(SystemExit) as usage:  # --dbc etc. missing: a usage error
        main([*args[:-12], "--can", str(tmp_path / "car.log")])
    assert usage.value.code == 2


def test_the_robust_method_keeps_the_windows_where_the_gyro_does_not_link_them(walk):
    """A walker's course leaves the body's yaw at every stop: the smoother's variance factor
    is far above its limit, and the robust method keeps its windows' headings with a warning
    (it gave no heading at all before the limit)."""
    robust = HeadingPipelineConfig.robust()
    table = _with_config(walk, robust)
    windows_only = _with_config(walk, replace(robust, smoother=HeadingSmootherConfig()))
    assert [w for w in table.warnings if w.startswith("heading smoother:")]
    np.testing.assert_array_equal(table.tc_available, windows_only.tc_available)
    assert table.tc_available.mean() > 0.7
