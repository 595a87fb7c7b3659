"""NMEA fixes off the globe (longitude 181°, latitude 100.7°) are skipped with a warning naming
the file and the line; a log of nothing else is an InputError naming the file."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import shared_data_dir
from tests.io.fuzz_families import _nmea, nmea_text
from vo_doppler.errors import InputError
from vo_doppler.io.gps_fixes import read_gps_fixes

OFF_GLOBE = (
    _nmea("GPRMC,120000.00,A,3741.60000,N,18100.00000,E,10.5,90.0,140325,,,A"),
    _nmea("GPGGA,120000.00,9999.99990,N,13942.204,E,1,08,0.9,40.0,M,39.0,M,,"),
)


@pytest.mark.parametrize("sentence", OFF_GLOBE)
def test_a_fix_off_the_globe_is_skipped_and_named(tmp_path, sentence, caplog):
    path = tmp_path / "fixes.nmea"
    path.write_bytes(sentence.encode() + b"\r\n" + nmea_text())
    fixes = read_gps_fixes(path)
    assert np.abs(np.degrees(fixes.lat)).max() <= 90.0
    assert np.abs(np.degrees(fixes.lon)).max() <= 180.0
    assert fixes.t.size == 120
    assert any(f"{path}:1: latitude" in r.getMessage() for r in caplog.records)


def test_the_shared_minimal_log_is_an_input_error_naming_it():
    path = shared_data_dir() / "bad_inputs_found" / "lon181.nmea"
    if not path.is_file():
        pytest.skip(f"{path} absent")
    with pytest.raises(InputError, match=str(path)):
        read_gps_fixes(path)


def test_a_negative_speed_over_ground_in_a_gps_csv_reads_as_unknown(tmp_path):
    path = tmp_path / "gps.csv"
    path.write_text("t,lat_deg,lon_deg,speed_mps\n0,35.0,139.0,-1\n1,35.0,139.0,10.0\n")
    fixes = read_gps_fixes(path)
    assert np.isnan(fixes.speed[0]) and fixes.speed[1] == 10.0
