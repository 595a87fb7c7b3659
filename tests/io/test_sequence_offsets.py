"""sequence.yaml clock offsets beyond any GPS time (``camera``, ``can``, ``vehicle`` or
``imu.time_offset_s`` of ±1e20, 1e308) are a ManifestError naming the manifest and the key,
not an error without a file from deep inside; image times that stop increasing once shifted are
named the same way."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from tests.conftest import REPO_ROOT
from vo_doppler.errors import ManifestError
from vo_doppler.io.sensor_csv import (
    FORWARD_ACCELERATION_COLUMN,
    SPEED_COLUMN,
    YAW_RATE_COLUMN,
    write_sensor_csv,
)
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.series import SensorSeries

SAMPLE = REPO_ROOT / "sample_sequences" / "urban_canyon_small"


def sample_manifest() -> dict:
    """The sample's manifest with its paths made absolute, to be written anywhere."""
    manifest = yaml.safe_load((SAMPLE / "sequence.yaml").read_text())
    for section, key in (
        ("camera", "images"),
        ("camera", "times"),
        ("camera", "calib"),
        ("gnss", "obs"),
        ("can", "log"),
        ("can", "dbc"),
        ("ground_truth", "trajectory"),
    ):
        manifest[section][key] = str(SAMPLE / manifest[section][key])
    manifest["gnss"]["nav"] = [str(SAMPLE / p) for p in manifest["gnss"]["nav"]]
    return manifest


def write_manifest(tmp_path, change) -> object:
    manifest = sample_manifest()
    change(manifest, tmp_path)
    path = tmp_path / "sequence.yaml"
    path.write_text(yaml.safe_dump(manifest, sort_keys=False))
    return path


def vehicle_section(manifest: dict, folder, offset: float = 0.0) -> None:
    """The CAN section replaced by sensor CSVs (a 'vehicle' section)."""
    t = np.arange(0.0, 40.0, 0.1)
    for name, column, value in (
        ("yaw_rate.csv", YAW_RATE_COLUMN, 0.01),
        ("wheel_speed.csv", SPEED_COLUMN, 10.0),
        ("forward_acceleration.csv", FORWARD_ACCELERATION_COLUMN, 0.1),
    ):
        write_sensor_csv(folder / name, SensorSeries(t, np.full(t.size, value)), column)
    del manifest["can"]
    manifest["vehicle"] = {
        "yaw_rate": str(folder / "yaw_rate.csv"),
        "wheel_speed": str(folder / "wheel_speed.csv"),
        "time_offset_s": offset,
    }
    manifest["imu"] = {
        "forward_acceleration": str(folder / "forward_acceleration.csv"),
        "time_offset_s": 1425953400.0,
    }


def _set(section: str, value: float):
    def change(manifest, folder):
        if section in ("vehicle", "imu"):
            vehicle_section(manifest, folder, 1425953400.0)
        manifest[section]["time_offset_s"] = value

    return change


@pytest.mark.parametrize(
    ("section", "value"),
    [
        ("camera", 1e20),
        ("camera", 1e308),
        ("camera", -1e20),
        ("can", 1e20),
        ("vehicle", 1e20),
        ("vehicle", -1e20),
        ("imu", 1e20),
    ],
)
def test_an_offset_beyond_any_gps_time_names_manifest_and_key(tmp_path, section, value):
    path = write_manifest(tmp_path, _set(section, value))
    with pytest.raises(ManifestError, match=rf"{section}\.time_offset_s: .* is outside"):
        read_sequence(path, allow_outside=True)
    try:
        read_sequence(path, allow_outside=True)
    except ManifestError as exc:
        assert str(path) in str(exc)


def test_the_sensor_csv_manifest_reads_with_real_offsets(tmp_path):
    path = write_manifest(tmp_path, _set("vehicle", 1425953400.0))
    sequence = read_sequence(path, allow_outside=True)
    assert sequence.wheel_speed.t[0] == pytest.approx(1425953400.0)


def test_image_times_that_stop_increasing_once_shifted_name_the_offset(tmp_path):
    def change(manifest, folder):
        times = folder / "times.txt"
        times.write_text("\n".join(f"{k * 1e-7:.7f}" for k in range(570)) + "\n")
        manifest["camera"]["times"] = str(times)
        manifest["camera"]["time_offset_s"] = 3.0e9

    path = write_manifest(tmp_path, change)
    with pytest.raises(ManifestError, match=r"camera\.time_offset_s: .* stop increasing"):
        read_sequence(path, allow_outside=True)
