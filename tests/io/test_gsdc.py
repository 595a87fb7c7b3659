"""GSDC device_gnss.csv reader on the real Pixel 7 Pro fixture and on damaged copies of it."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.errors import InputError
from vo_doppler.geo import geodetic_to_ecef
from vo_doppler.io.gsdc import read_device_gnss

pytestmark = pytest.mark.shared_data


def fixture():
    return require_shared("android_pixel7pro/device_gnss.csv")


def test_reads_observations_satellite_states_and_wls_positions():
    recording = read_device_gnss(fixture())
    obs = recording.observations
    assert obs.epoch_time.size == 5
    np.testing.assert_allclose(np.diff(obs.epoch_time), 1.0, atol=1e-5)
    assert set(obs.codes) >= {"C1C", "D1C", "L1C", "S1C", "C5Q", "D5Q"}
    assert any("11 Raw rows without an arrival time" in p for p in recording.problems)
    table = recording.satellites
    radius = np.linalg.norm(table.position, axis=1)
    assert np.all((radius > 2.5e7) & (radius < 4.3e7))  # MEO to BeiDou GEO/IGSO
    assert np.all(np.linalg.norm(table.velocity, axis=1) < 4500.0)
    assert np.all(np.abs(table.clock_drift) < 1e-8)
    assert np.all((table.travel_time_s > 0.06) & (table.travel_time_s < 0.1))
    # one state per (epoch, satellite), every Doppler row has one
    doppler = obs.select(code="D1C")
    assert np.all(table.rows_for(doppler.time, doppler.system, doppler.prn) >= 0)
    truth = geodetic_to_ecef(np.radians(37.692231), np.radians(-122.0884199), 20.97)
    distance = np.linalg.norm(recording.receiver_ecef - truth, axis=1)
    assert np.all(distance < 30.0)


def test_missing_column_and_broken_rows_name_file_and_line(tmp_path):
    lines = fixture().read_text().splitlines()
    path = tmp_path / "device_gnss.csv"
    path.write_text("\n".join([lines[0].replace("SvClockBiasMeters", "Other"), *lines[1:]]))
    with pytest.raises(InputError, match=r"device_gnss.csv:1: not a GSDC .* SvClockBiasMeters"):
        read_device_gnss(path)
    broken = list(lines)
    broken[3] = broken[3] + ",extra"
    path.write_text("\n".join(broken))
    with pytest.raises(InputError, match=r"device_gnss.csv:4: \d+ fields for \d+ columns"):
        read_device_gnss(path)
    names = lines[0].split(",")
    fields = lines[1].split(",")
    fields[names.index("SvPositionXEcefMeters")] = "9.0e7"
    damaged = list(lines)
    damaged[1] = ",".join(fields)
    path.write_text("\n".join(damaged))
    with pytest.raises(
        InputError, match=r"device_gnss.csv:2: satellite position off any GNSS orbit"
    ):
        read_device_gnss(path)
