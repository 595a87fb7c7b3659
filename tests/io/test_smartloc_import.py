"""``import_smartloc``: the sequence folder of a smartLoc raw CSV, on the real Berlin file (ground
truth to 1 mm, vehicle signals, Doppler σ and NLOS table) and on synthetic ones (with and
without a navigation file)."""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest
import yaml

from tests.conftest import REPO_ROOT, require_shared
from tests.helpers.smartloc_text import Measurement, Truth, smartloc_text
from vo_doppler.errors import InputError
from vo_doppler.geo import EnuFrame, ecef_to_geodetic
from vo_doppler.io.doppler_sigma import read_doppler_sigma
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.sensor_csv import read_speed_csv, read_yaw_rate_csv
from vo_doppler.io.sequence import read_sequence
from vo_doppler.io.smartloc import read_smartloc
from vo_doppler.io.smartloc_import import import_smartloc
from vo_doppler.io.trajectory import read_tum
from vo_doppler.model.gpstime import SECONDS_PER_WEEK

REAL = "smartloc_berlin/tu_chemnitz_berlin_1_raw.csv"
SAMPLE_NAV = REPO_ROOT / "sample_sequences" / "urban_canyon_small" / "gnss" / "brdc.nav"
EARTH_MM_PER_DEG = 111_320_000.0  # mm per degree of latitude (and of longitude × cos(lat))


@pytest.fixture(scope="module")
def berlin(tmp_path_factory):
    source = require_shared(REAL)
    folder = tmp_path_factory.mktemp("smartloc") / "seq"
    summary = import_smartloc(source, folder)
    return source, folder, summary


def _file_columns(source):
    with source.open(encoding="utf-8", newline="") as handle:
        reader = csv.reader(handle, delimiter=";")
        header = next(reader)
        rows = list(reader)

    def column(name: str) -> np.ndarray:
        k = next(i for i, h in enumerate(header) if name in h and " Cov " not in h)
        return np.array([float(r[k]) for r in rows])

    return column


@pytest.mark.shared_data
def test_the_ground_truth_equals_the_files_to_a_millimetre(berlin):
    source, folder, summary = berlin
    column = _file_columns(source)
    manifest = yaml.safe_load((folder / "sequence.yaml").read_text())
    origin = manifest["origin"]
    frame = EnuFrame(
        math.radians(origin["lat_deg"]), math.radians(origin["lon_deg"]), origin["height_m"]
    )
    truth = read_tum(folder / manifest["ground_truth"]["trajectory"])
    assert len(truth) == summary.ground_truth_poses == 31
    lat, lon, height = ecef_to_geodetic(frame.enu_to_ecef(truth.positions))
    t_file = column("GPSWeek") * SECONDS_PER_WEEK + column("GPSSecondsOfWeek")
    epochs, first = np.unique(t_file, return_index=True)
    np.testing.assert_allclose(truth.t, epochs, atol=1e-6)
    lat_file, lon_file = column("(GT Lat)")[first], column("(GT Lon)")[first]
    north_mm = (np.degrees(lat) - lat_file) * EARTH_MM_PER_DEG
    east_mm = (np.degrees(lon) - lon_file) * EARTH_MM_PER_DEG * np.cos(np.radians(lat_file))
    assert np.abs(north_mm).max() < 1.0 and np.abs(east_mm).max() < 1.0
    assert np.abs(height - column("(GT Height)")[first]).max() < 1e-3
    np.testing.assert_allclose(truth.yaw(), column("(GT Heading)")[first], atol=1e-9)
    moved = np.linalg.norm(truth.positions[-1, :2])
    assert 20.0 < moved < 60.0  # about 6 s … 8 m/s over 6 s


@pytest.mark.shared_data
def test_vehicle_signals_are_the_files_speed_and_yaw_rate(berlin):
    source, folder, _ = berlin
    column = _file_columns(source)
    t_file = column("GPSWeek") * SECONDS_PER_WEEK + column("GPSSecondsOfWeek")
    _, first = np.unique(t_file, return_index=True)
    speed = read_speed_csv(folder / "vehicle" / "wheel_speed.csv")
    yaw_rate = read_yaw_rate_csv(folder / "vehicle" / "yaw_rate.csv")
    np.testing.assert_allclose(speed.value, column("(GT Velocity)")[first], rtol=1e-15)
    np.testing.assert_allclose(yaw_rate.value, column("(GT Yaw-rate)")[first], rtol=1e-15)
    np.testing.assert_allclose(speed.t, t_file[first], atol=1e-6)


@pytest.mark.shared_data
def test_the_observations_sigma_and_nlos_table_are_written(berlin):
    source, folder, summary = berlin
    recording = read_smartloc(source)
    assert (summary.rows, summary.epochs) == (545, 31)
    assert (summary.nlos, summary.line_of_sight, summary.unlabelled) == (263, 279, 3)
    manifest = yaml.safe_load((folder / "sequence.yaml").read_text())
    assert "gnss" not in manifest and "camera" not in manifest  # no navigation, no images
    assert "re-import with --nav" in manifest["smartloc"]["navigation"]
    obs = read_obs(folder / "gnss" / f"{source.stem}.obs")
    assert obs.epoch_time.size == 31
    doppler = obs.select(code="D1C")
    original = recording.observations.select(code="D1C")
    assert len(doppler) == len(original) == 545
    np.testing.assert_allclose(doppler.value, original.value, atol=5e-4)  # RINEX's 1e-3
    assert obs.header.glonass_channels == recording.glonass_channels
    sigma = read_doppler_sigma(folder / "gnss" / "doppler_sigma.csv")
    assert len(sigma) == 545
    np.testing.assert_allclose(
        sigma.sigma_mps, original.row_fields["range_rate_sigma_mps"], rtol=1e-5
    )
    with (folder / "gnss" / "doppler_nlos.csv").open(newline="") as handle:
        table = list(csv.DictReader(handle))
    assert len(table) == 545
    assert [sum(r["nlos"] == v for r in table) for v in ("1", "0", "-1")] == [263, 279, 3]
    rate = np.array([float(r["range_rate_mps"]) for r in table])
    np.testing.assert_allclose(rate, original.row_fields["range_rate_mps"], atol=1e-6)


@pytest.mark.shared_data
def test_the_folder_reads_as_a_sequence_without_gnss(berlin):
    _, folder, _ = berlin
    sequence = read_sequence(folder)
    assert not sequence.has_camera
    assert not sequence.has_gnss
    assert len(sequence.wheel_speed) == 31


def test_with_a_navigation_file_the_manifest_gets_a_gnss_section(tmp_path):
    source = tmp_path / "drive_raw.csv"
    source.write_text(
        smartloc_text(
            [(Truth(10.0 + 0.2 * k), [Measurement(sv=5), Measurement(sv=7)]) for k in range(5)]
        )
    )
    folder = tmp_path / "seq"
    summary = import_smartloc(source, folder, [SAMPLE_NAV])
    manifest = yaml.safe_load((folder / "sequence.yaml").read_text())
    assert manifest["gnss"] == {
        "obs": "gnss/drive_raw.obs",
        "nav": ["gnss/brdc.nav"],
        "doppler_sigma": "gnss/doppler_sigma.csv",
    }
    assert summary.navigation == (folder / "gnss" / "brdc.nav",)
    sequence = read_sequence(folder)
    assert sequence.observations.select(code="D1C").satellites().tolist() == ["G05", "G07"] * 5
    assert len(sequence.doppler_sigma) == 10
    assert sequence.has_gnss


def test_nothing_is_written_when_the_csv_or_a_navigation_file_is_refused(tmp_path):
    source = tmp_path / "drive_raw.csv"
    source.write_text(smartloc_text([(Truth(10.0), [Measurement(nlos="x")])]))
    with pytest.raises(InputError, match="NLOS label"):
        import_smartloc(source, tmp_path / "seq")
    assert not (tmp_path / "seq").exists()
    source.write_text(smartloc_text([(Truth(10.0), [Measurement()])]))
    bad_nav = tmp_path / "bad.nav"
    bad_nav.write_text("not a navigation file\n")
    with pytest.raises(InputError):
        import_smartloc(source, tmp_path / "seq", [bad_nav])
    assert not (tmp_path / "seq").exists()
