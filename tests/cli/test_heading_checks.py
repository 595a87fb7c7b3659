"""``vo-doppler heading`` gives the calibration warnings ``run`` gives (one shared check): a
CAN clock off by 2 s and wheels reading 3.6 times fast (a speed in km/h) on an open-sky
simulated drive, whose true CAN offset is the GPS-Unix offset."""

from __future__ import annotations

import json

import numpy as np
import pytest

from vo_doppler.cli import main
from vo_doppler.io.gnss_results_csv import read_velocity_csv
from vo_doppler.io.heading_csv import read_heading_csv

GPS_MINUS_UNIX_S = -315964782.0


@pytest.fixture(scope="module")
def kmh_drive(tmp_path_factory):
    """40 s with the wheel speed scaled by 3.6 (scale error 2.6), low buildings, no NLOS."""
    folder = tmp_path_factory.mktemp("sim") / "kmh"
    argv = ["-q", "simulate", "--no-images", "--duration", "40", "--heights", "1,2"]
    argv += ["--no-nlos", "--wheel-scale-error", "2.6", "--gnss-rate", "5", "-o", str(folder)]
    assert main(argv) == 0
    return folder


def _heading(folder, offset_s: float, out, capsys, caplog, extra=()) -> dict:
    capsys.readouterr()
    caplog.clear()
    argv = ["-q", "heading", str(folder / "gnss/rover.obs"), "--nav", str(folder / "gnss/brdc.nav")]
    argv += ["--can", str(folder / "can/vehicle.log"), "--dbc", str(folder / "can/vehicle.dbc")]
    argv += ["--yaw-rate", "VEHICLE_DYNAMICS.YAW_RATE"]
    argv += ["--wheel-speed", "WHEEL_SPEEDS.WHEEL_SPEED_RL,WHEEL_SPEEDS.WHEEL_SPEED_RR"]
    argv += ["--time-offset-can", f"{offset_s}", "-o", str(out), *extra]
    assert main(argv) == 0
    summary = json.loads(capsys.readouterr().out)
    for warning in summary["warnings"]:
        assert warning in caplog.text  # logged as well
    return summary


@pytest.mark.slow
def test_a_wheel_scale_far_from_one_is_a_warning(kmh_drive, tmp_path, capsys, caplog):
    summary = _heading(kmh_drive, GPS_MINUS_UNIX_S, tmp_path / "h.csv", capsys, caplog)
    assert summary["wheel_scale"] == pytest.approx(1 / 3.6, abs=0.02)
    (warning,) = [w for w in summary["warnings"] if w.startswith("wheel scale")]
    assert f"wheel scale: the calibration gives {summary['wheel_scale']:.3f}" in warning


@pytest.mark.slow
def test_the_car_checked_velocity_is_written_when_asked(kmh_drive, tmp_path, capsys, caplog):
    """``--vel``: the conventional velocity with the car's verdict (design (I1c)), the share the
    summary gives, moving the table's conventional verdict; without ``--vel`` nothing else is
    written."""
    vel = tmp_path / "v.csv"
    summary = _heading(
        kmh_drive, GPS_MINUS_UNIX_S, tmp_path / "h.csv", capsys, caplog, ["--vel", str(vel)]
    )
    velocity = read_velocity_csv(vel)
    assert summary["vel"] == str(vel)
    assert summary["conv_velocity_valid"] == pytest.approx(velocity.valid.mean(), abs=1e-12)
    assert 0.5 < velocity.valid.mean() < 1.0
    fast = velocity.speed_mps > 3.0
    assert velocity.valid[fast].mean() > 0.9  # open sky
    # the table written with the km/h wheels' scale (0.287) reads back (correct reads it too)
    table = read_heading_csv(tmp_path / "h.csv")
    np.testing.assert_array_equal(velocity.valid[fast], table.conv_valid[fast])
    plain = _heading(kmh_drive, GPS_MINUS_UNIX_S, tmp_path / "p.csv", capsys, caplog)
    assert plain["vel"] is None
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "h.csv",
        "h.png",
        "p.csv",
        "p.png",
        "v.csv",
    ]


@pytest.mark.slow
def test_a_can_clock_2_s_off_is_a_warning_with_the_right_offset(
    kmh_drive, tmp_path, capsys, caplog
):
    summary = _heading(kmh_drive, GPS_MINUS_UNIX_S + 2.0, tmp_path / "h.csv", capsys, caplog)
    clock = [w for w in summary["warnings"] if w.startswith("CAN clock")]
    assert len(clock) == 1
    assert "shifted by -2.00 s" in clock[0]
    assert f"--time-offset-can {GPS_MINUS_UNIX_S + 2.0:.3f} s should be about" in clock[0]
    suggested = float(clock[0].rsplit("about ", 1)[1].removesuffix(" s"))
    assert suggested == pytest.approx(GPS_MINUS_UNIX_S, abs=0.05)


HEADING = ["heading", "r.obs", "--nav", "r.nav", "-o", "h.csv"]
CAN_SOURCE = ["--can", "c.log", "--dbc", "c.dbc", "--yaw-rate", "M.Y", "--wheel-speed", "M.W"]
CSV_SOURCE = ["--yaw-rate-csv", "y.csv", "--speed-csv", "s.csv"]


@pytest.mark.parametrize(
    ("sensors", "message"),
    [
        ([], "no vehicle sensors: give --can LOG --dbc DBC"),
        (["--can", "c.log"], "--can needs --dbc, --yaw-rate, --wheel-speed"),
        (CAN_SOURCE[:6], "--can, --dbc, --yaw-rate needs --wheel-speed"),
        (["--yaw-rate-csv", "y.csv"], "--yaw-rate-csv needs --speed-csv"),
        (["--speed-csv", "s.csv"], "--speed-csv needs --yaw-rate-csv"),
        (
            [*CAN_SOURCE, "--speed-csv", "s.csv"],
            "give the CAN log or the CSV files, not both (--can, --dbc, --yaw-rate, "
            "--wheel-speed and --speed-csv)",
        ),
        # CAN-only options with the CSV files were silently ignored (the same heading):
        ([*CSV_SOURCE, "--can-channel", "can1"], "--can-channel applies to a CAN log (--can) only"),
        ([*CSV_SOURCE, "--yaw-rate-sign", "-1"], "--yaw-rate-sign applies to a CAN log (--can)"),
        ([*CSV_SOURCE, "--can-short-frames", "pad"], "--can-short-frames applies to a CAN log"),
        (
            [*CSV_SOURCE, "--time-offset-can", "-315964782"],
            "--time-offset-can applies to a CAN log (--can) only, and the sensors are the CSV "
            "files (drop it); the CSV times take --time-offset-yaw and --time-offset-speed",
        ),
        (
            [*CSV_SOURCE, "--time-offset-can", "5", "--can-channel", "x", "--yaw-rate-sign", "-1"],
            "--yaw-rate-sign, --can-channel and --time-offset-can apply to a CAN log (--can) "
            "only, and the sensors are the CSV files (drop them);",
        ),
    ],
)
def test_sensor_options_that_name_no_one_source_are_exit_2(
    sensors, message, capsys, tmp_path, monkeypatch
):
    """Checked before anything is read: none of the named files exists. An option of the
    other source is refused too, as it would be ignored."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as stop:
        main([*HEADING, *sensors])
    assert stop.value.code == 2
    assert f"vo-doppler heading: error: {message}" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "sensors",
    [
        CAN_SOURCE,
        CSV_SOURCE,
        [*CSV_SOURCE, "--time-offset-can", "0", "--yaw-rate-sign", "1"],  # the defaults
        [*CSV_SOURCE, "--time-offset-yaw", "0.5", "--time-offset-speed", "0.2"],
        [*CAN_SOURCE, "--can-channel", "can1", "--time-offset-can", "5", "--yaw-rate-sign", "-1"],
        [*CAN_SOURCE, "--time-offset-yaw", "0.5", "--time-offset-speed", "0.2"],  # add to CAN's
    ],
)
def test_one_whole_sensor_source_passes_the_check(sensors, capsys, tmp_path, monkeypatch):
    """Past the check, the missing input is the failure (exit 1, naming it). The yaw and speed
    offsets apply to the CAN signals as well as to the CSV files."""
    monkeypatch.chdir(tmp_path)
    assert main([*HEADING, *sensors]) == 1
    err = capsys.readouterr().err
    assert "No such file or directory" in err and "usage:" not in err
