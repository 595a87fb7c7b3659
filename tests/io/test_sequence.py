"""Sequence manifests: clear errors that name the file and the missing piece."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from vo_doppler.errors import InputError, ManifestError
from vo_doppler.io.sensor_csv import SPEED_COLUMN, YAW_RATE_COLUMN, write_sensor_csv
from vo_doppler.io.sequence import (
    manifest_inputs,
    read_manifest,
    read_sequence,
    read_sequence_with_report,
)
from vo_doppler.model.series import SensorSeries
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon


def write_manifest(folder, data) -> None:
    (folder / "sequence.yaml").write_text(yaml.safe_dump(data))


def test_missing_manifest(tmp_path):
    with pytest.raises(InputError, match=r"sequence.yaml: cannot read the sequence manifest"):
        read_manifest(tmp_path)


def test_manifest_inputs_are_every_existing_path_it_names(tmp_path):
    """Paths in any section and in lists, inside the folder or outside it; signal names and
    paths that do not exist name no input."""
    folder = tmp_path / "seq"
    (folder / "gnss").mkdir(parents=True)
    for name in ("gnss/a.obs", "gnss/b.nav"):
        (folder / name).write_text("x")
    (tmp_path / "shared.sp3").write_text("x")
    (folder / "sequence.yaml").write_text(
        "format: vo-doppler-sequence/1\n"
        "gnss: {obs: gnss/a.obs, nav: [gnss/b.nav, gnss/missing.nav], orbits: ../shared.sp3}\n"
        "can: {yaw_rate: YAW.RATE, wheel_speed: [WHEEL.FL]}\n"
        "ground_truth: {trajectory: truth.tum}\n"
    )
    assert manifest_inputs(folder) == [
        folder,
        folder / "sequence.yaml",
        folder / "gnss/a.obs",
        folder / "gnss/b.nav",
        folder / "../shared.sp3",
    ]
    with pytest.raises(InputError, match="sequence"):
        manifest_inputs(tmp_path)


def test_wrong_format_is_named(tmp_path):
    write_manifest(tmp_path, {"format": "something-else/2"})
    with pytest.raises(InputError, match=r"not a vo-doppler-sequence/1 manifest.*something-else"):
        read_manifest(tmp_path)
    (tmp_path / "sequence.yaml").write_text("a: [1, 2\n")
    with pytest.raises(InputError, match="not valid YAML"):
        read_manifest(tmp_path)


def test_missing_section_and_key_are_named(tmp_path):
    write_manifest(tmp_path, {"format": "vo-doppler-sequence/1", "camera": {"images": "x"}})
    with pytest.raises(InputError, match="no 'origin' section"):
        read_sequence(tmp_path)
    write_manifest(
        tmp_path,
        {
            "format": "vo-doppler-sequence/1",
            "camera": {"times": "times.txt"},
            "gnss": {},
            "can": {},
            "origin": {},
        },
    )
    with pytest.raises(InputError, match="section 'camera' lacks 'images'"):
        read_sequence(tmp_path)


@pytest.mark.slow
def test_antenna_lever_arm_is_read_and_defaults_to_zero(tmp_path):
    config = UrbanCanyonConfig(
        duration_s=1.0, seed=1, image_size_px=(64, 36), antenna_lever_arm_m=(1.2, -0.3, 1.5)
    )
    simulate_urban_canyon(tmp_path, config)
    assert read_sequence(tmp_path).antenna_lever_arm_m == (1.2, -0.3, 1.5)
    manifest = yaml.safe_load((tmp_path / "sequence.yaml").read_text())
    del manifest["gnss"]["antenna_lever_arm_m"]
    write_manifest(tmp_path, manifest)
    assert read_sequence(tmp_path).antenna_lever_arm_m == (0.0, 0.0, 0.0)
    for bad in ([1.0, 2.0], "1,2,3", [1.0, None, 2.0]):
        manifest["gnss"]["antenna_lever_arm_m"] = bad
        write_manifest(tmp_path, manifest)
        with pytest.raises(InputError, match=r"gnss\.antenna_lever_arm_m .* not three numbers"):
            read_sequence(tmp_path)
    manifest["gnss"]["antenna_lever_arm_m"] = [19.0, 0.0, 5.0]  # 19.6 m: an articulated bus
    write_manifest(tmp_path, manifest)
    assert read_sequence(tmp_path).antenna_lever_arm_m == (19.0, 0.0, 5.0)
    manifest["gnss"]["antenna_lever_arm_m"] = [1000, 0, 0]  # millimetres, or a typo
    write_manifest(tmp_path, manifest)
    with pytest.raises(ManifestError) as info:
        read_sequence(tmp_path)
    assert info.value.key == "gnss.antenna_lever_arm_m"
    assert "[1000.0, 0.0, 0.0]: the lever arm is 1000 m long, beyond any road vehicle (20 m)" in (
        str(info.value)
    )


@pytest.mark.slow
def test_a_ground_truth_file_named_but_absent_is_an_error_naming_the_key(tmp_path):
    simulate_urban_canyon(
        tmp_path, UrbanCanyonConfig(duration_s=1.0, seed=1, image_size_px=(64, 36))
    )
    assert read_sequence(tmp_path).truth is not None
    manifest = yaml.safe_load((tmp_path / "sequence.yaml").read_text())
    manifest["ground_truth"]["trajectory"] = "nothere.tum"
    write_manifest(tmp_path, manifest)
    with pytest.raises(ManifestError, match=r"nothere\.tum: cannot read") as info:
        read_sequence(tmp_path)
    assert info.value.key == "ground_truth.trajectory"
    del manifest["ground_truth"]  # no ground truth at all: a run without evaluation
    write_manifest(tmp_path, manifest)
    assert read_sequence(tmp_path).truth is None


@pytest.mark.slow
def test_forward_acceleration_from_the_can_bus_or_a_csv_but_not_both(tmp_path):
    simulate_urban_canyon(
        tmp_path, UrbanCanyonConfig(duration_s=2.0, seed=1, image_size_px=(64, 36))
    )
    sequence = read_sequence(tmp_path)
    acceleration = sequence.forward_acceleration
    assert acceleration.unit == "m/s^2" and len(acceleration) > 100
    inside = (acceleration.t > acceleration.t[0] + 0.5) & (
        acceleration.t < acceleration.t[-1] - 0.5
    )
    t0, t1 = acceleration.t[inside][[0, -1]]
    wheel = sequence.wheel_speed

    def speed(t):  # the generating speed: the rear wheels' mean over ±50 ms, less their +2 %
        return np.mean(wheel.value[np.abs(wheel.t - t) < 0.05]) / 1.02

    gained = (speed(t1) - speed(t0)) / (t1 - t0)
    # the mean reading is the mean dv/dt plus the simulator's bias (0.1 m/s²)
    assert float(acceleration.value[inside].mean()) - gained == pytest.approx(0.1, abs=0.02)
    manifest = yaml.safe_load((tmp_path / "sequence.yaml").read_text())
    del manifest["can"]["forward_acceleration"]
    write_manifest(tmp_path, manifest)
    assert read_sequence(tmp_path).forward_acceleration is None
    (tmp_path / "acc.csv").write_text("t,forward_acceleration_mps2\n0.0,0.1\n1.0,0.2\n")
    manifest["imu"] = {"forward_acceleration": "acc.csv"}
    manifest["can"]["forward_acceleration"] = "VEHICLE_DYNAMICS.LONG_ACCEL"
    write_manifest(tmp_path, manifest)
    with pytest.raises(InputError, match=r"can\.forward_acceleration.*given twice"):
        read_sequence(tmp_path)
    manifest["can"]["forward_acceleration"] = "VEHICLE_DYNAMICS.YAW_RATE"
    del manifest["imu"]
    write_manifest(tmp_path, manifest)
    with pytest.raises(InputError, match="not m/s²"):
        read_sequence(tmp_path)


@pytest.mark.slow
def test_vehicle_signals_from_sensor_csvs_instead_of_a_can_log(tmp_path):
    simulate_urban_canyon(
        tmp_path, UrbanCanyonConfig(duration_s=2.0, seed=1, image_size_px=(64, 36))
    )
    from_can = read_sequence(tmp_path)
    offset = 1.0e9
    (tmp_path / "vehicle").mkdir()
    write_sensor_csv(
        tmp_path / "vehicle" / "yaw.csv",
        SensorSeries(from_can.yaw_rate.t - offset, from_can.yaw_rate.value),
        YAW_RATE_COLUMN,
    )
    write_sensor_csv(
        tmp_path / "vehicle" / "speed.csv",
        SensorSeries(from_can.wheel_speed.t - offset, from_can.wheel_speed.value),
        SPEED_COLUMN,
    )
    manifest = yaml.safe_load((tmp_path / "sequence.yaml").read_text())
    can = manifest.pop("can")
    manifest["vehicle"] = {
        "yaw_rate": "vehicle/yaw.csv",
        "wheel_speed": "vehicle/speed.csv",
        "time_offset_s": offset,
    }
    write_manifest(tmp_path, manifest)
    sequence, report = read_sequence_with_report(tmp_path)
    for name in ("yaw_rate", "wheel_speed"):
        np.testing.assert_allclose(getattr(sequence, name).t, getattr(from_can, name).t, atol=1e-6)
        np.testing.assert_array_equal(getattr(sequence, name).value, getattr(from_can, name).value)
    assert report.can is None and report.vehicle_time_offset_s == offset
    assert sequence.clock_offsets_s["vehicle"] == offset
    assert sequence.forward_acceleration is None
    names = sequence.vehicle_source  # what the checks' messages say: the CSV and its fix
    assert names.yaw_rate == f"{tmp_path / 'vehicle' / 'yaw.csv'} (the yaw rate, vehicle.yaw_rate)"
    assert names.yaw_rate_unit_fix.startswith("the yaw_rate_rad_s column must be in rad/s")
    assert "yaw_rate_rad_s column must be counter-clockwise positive" in names.yaw_rate_sign_fix
    assert (names.sensor, names.offset_s) == ("vehicle signals", offset)
    assert "DBC" not in names.yaw_rate_unit_fix
    assert from_can.vehicle_source.yaw_rate.endswith(
        "vehicle.dbc: the yaw rate, CAN signal VEHICLE_DYNAMICS.YAW_RATE (can.yaw_rate)"
    )
    assert from_can.vehicle_source.yaw_rate_sign_fix.startswith("set can.yaw_rate_sign in ")
    manifest["can"] = can
    write_manifest(tmp_path, manifest)
    with pytest.raises(InputError, match="given twice"):
        read_sequence(tmp_path)
    del manifest["can"], manifest["vehicle"]
    write_manifest(tmp_path, manifest)
    with pytest.raises(InputError, match="neither a 'can' nor a 'vehicle' section"):
        read_sequence(tmp_path)
    manifest["vehicle"] = {"yaw_rate": "vehicle/yaw.csv", "wheel_speed": "vehicle/yaw.csv"}
    write_manifest(tmp_path, manifest)
    with pytest.raises(InputError, match=r"yaw\.csv.*lacks column\(s\) speed_mps"):
        read_sequence(tmp_path)
    del manifest["vehicle"]["wheel_speed"]
    write_manifest(tmp_path, manifest)
    with pytest.raises(InputError, match="section 'vehicle' lacks 'wheel_speed'"):
        read_sequence(tmp_path)


@pytest.mark.slow
def test_vehicle_rows_skipped_by_the_readers_are_warnings_of_the_run(tmp_path):
    simulate_urban_canyon(
        tmp_path, UrbanCanyonConfig(duration_s=2.0, seed=1, image_size_px=(64, 36))
    )
    from_can = read_sequence(tmp_path)
    speed = from_can.wheel_speed.value.copy()
    speed[50] = 1.0e9  # one corrupt row: 5,174 km of dead reckoning if it were integrated
    write_sensor_csv(
        tmp_path / "speed.csv", SensorSeries(from_can.wheel_speed.t, speed), SPEED_COLUMN
    )
    write_sensor_csv(tmp_path / "yaw.csv", from_can.yaw_rate, YAW_RATE_COLUMN)
    yaw_lines = (tmp_path / "yaw.csv").read_text().splitlines(keepends=True)
    (tmp_path / "yaw.csv").write_text("".join(yaw_lines[:11] + yaw_lines[10:]))  # line 12 = 11
    manifest = yaml.safe_load((tmp_path / "sequence.yaml").read_text())
    del manifest["can"]
    manifest["vehicle"] = {"yaw_rate": "yaw.csv", "wheel_speed": "speed.csv"}
    write_manifest(tmp_path, manifest)
    sequence, report = read_sequence_with_report(tmp_path)
    assert len(sequence.wheel_speed) == len(speed) - 1
    assert np.max(sequence.wheel_speed.value) == np.max(np.delete(speed, 50))
    np.testing.assert_array_equal(sequence.yaw_rate.value, from_can.yaw_rate.value)
    assert report.warnings() == [
        f"{tmp_path / 'yaw.csv'}: dropped 1 rows repeating the row before exactly (lines 12)",
        f"{tmp_path / 'speed.csv'}: skipped 0 malformed, 0 non-finite and 1 out-of-range rows "
        "(speed_mps 1e+09 beyond [-10, 150] m/s) (first lines: 52)",
    ]
