"""The GPS-fix readers: CSV fixes outside the Earth's coordinates; NMEA VTG speeds."""

from __future__ import annotations

import datetime as dt
import logging
import re

import numpy as np
import pytest

from tests.helpers.nmea import gga, rmc, vtg
from vo_doppler.errors import InputError
from vo_doppler.io.gps_fixes import read_gps_fixes, read_nmea

START = dt.datetime(2024, 6, 24, 8, 20, 0)


def test_fixes_with_lat_and_lon_swapped_are_an_error_suggesting_the_swap(tmp_path):
    """Every fix out of range (lat -122°): an error naming the file, not an empty track that
    failed later in the dead reckoning with exit 3."""
    path = tmp_path / "gps.csv"
    path.write_text("t,lat_deg,lon_deg\n" + "".join(f"{k},-122.4,37.7\n" for k in range(5)))
    with pytest.raises(InputError, match=r"gps.csv: all 5 fixes .* columns swapped\?"):
        read_gps_fixes(path)


def test_some_fixes_out_of_range_are_skipped_and_counted(tmp_path):
    path = tmp_path / "gps.csv"
    path.write_text("t,lat_deg,lon_deg\n0,37.7,-122.4\n1,-122.4,37.7\n2,37.8,-122.4\n")
    fixes = read_gps_fixes(path)
    np.testing.assert_allclose(fixes.t, [0.0, 2.0])
    assert fixes.n_skipped == 1


def _at(k: float) -> dt.datetime:
    return START + dt.timedelta(seconds=k)


def _write(tmp_path, lines: list[str]):
    path = tmp_path / "log.nmea"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize(
    "form",
    [
        lambda kmh: vtg(kmh),  # km/h and knots, mode A
        lambda kmh: vtg(None, kmh / 1.852),  # knots only
        lambda kmh: vtg(kmh, 0.0, mode=None),  # NMEA 2.2 (no mode); km/h wins over knots
    ],
)
def test_gga_and_vtg_give_each_fix_the_speed_of_the_vtg_after_it(tmp_path, form):
    """A receiver logging GGA+VTG gave no speed at all: VTG was ignored."""
    lines = []
    for k in range(5):
        lines += [gga(_at(k).time(), 48.1, -11.5), form(36.0 + 3.6 * k), "$GPGSA,ignored"]
    fixes = read_gps_fixes(_write(tmp_path, lines))
    seconds = 8 * 3600 + 20 * 60
    np.testing.assert_array_equal(fixes.t, seconds + np.arange(5.0))
    np.testing.assert_allclose(fixes.speed, 10.0 + np.arange(5.0), atol=1e-6)
    assert fixes.time_system == "utc-seconds-of-day"


def test_rmc_speed_wins_and_only_the_first_vtg_of_an_epoch_counts(tmp_path):
    lines = [rmc(_at(0), 48.1, -11.5, 10.0), vtg(72.0), gga(_at(0).time(), 48.1, -11.5)]
    lines += [gga(_at(1).time(), 48.1, -11.5), vtg(36.0), vtg(90.0)]
    fixes = read_nmea(_write(tmp_path, lines))
    np.testing.assert_allclose(fixes.speed, [10.0 * 1852 / 3600, 10.0])
    assert fixes.time_system == "gps" and fixes.n_skipped == 0


def test_vtg_without_a_fix_before_it_is_skipped_counted_and_warned(tmp_path, caplog):
    """Before any time, after a fix-less GGA or an unreadable one (not paired one epoch back),
    or with mode N (data not valid)."""
    lines = [vtg(50.0)]  # line 1: nothing before it
    lines += [gga(_at(0).time(), 48.1, -11.5), vtg(36.0)]
    lines += [gga(_at(1).time(), 48.1, -11.5, quality=0), vtg(40.0)]  # line 5
    lines += [gga(_at(2).time(), 48.1, -11.5).replace("*", "0*"), vtg(44.0)]  # line 7
    lines += [gga(_at(3).time(), 48.1, -11.5), vtg(48.0, mode="N")]
    with caplog.at_level(logging.WARNING):
        fixes = read_nmea(_write(tmp_path, lines))
    np.testing.assert_allclose(fixes.speed, [10.0, np.nan], atol=1e-9)
    assert fixes.n_skipped == 6  # 3 unpaired VTG, the fix-less GGA and VTG, the bad checksum
    assert (
        f"{tmp_path / 'log.nmea'}: skipped 3 VTG sentences with no GGA or RMC fix before them "
        "to take the time of (VTG has none; first line 1)"
    ) in caplog.text


def test_vtg_speeds_beyond_a_vehicle_are_skipped_or_an_error_like_rmc(tmp_path, caplog):
    lines = []
    for k in range(200):
        lines += [gga(_at(k).time(), 48.1, -11.5), vtg(1e4 if k == 50 else 36.0)]
    with caplog.at_level(logging.WARNING):
        fixes = read_nmea(_write(tmp_path, lines))
    assert len(fixes.t) == 200 and np.isnan(fixes.speed[50]) and fixes.n_skipped == 1
    assert "skipped 1 VTG sentences with a speed over ground outside [0, 150] m/s " in caplog.text
    assert "(first 2777.78 m/s; lines 102)" in caplog.text
    lines[41] = lines[61] = vtg(1e4)  # 1.5 % of the speeds: the receiver's output is wrong
    expected = (
        f"{tmp_path / 'log.nmea'}:42: VTG speed over ground 2777.78 m/s (10000 km/h) is outside "
        "what a vehicle can report, [0, 150] m/s, and so are 3 of the 200 VTG speeds"
    )
    with pytest.raises(InputError, match=f"^{re.escape(expected)}"):
        read_nmea(_write(tmp_path, lines))
