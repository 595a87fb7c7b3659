"""RINEX 3.04 writing: header records and D19.12 numbers, GPS calendar stamps, the
signal-strength digit, observation rows by (epoch, satellite) in signal order, and observation
and navigation files read back by the project's readers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vo_doppler.io.obs_rows import observations_from_rows
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.io.rinex_write import (
    GlonassRecord,
    gps_calendar,
    header_line,
    nav_number,
    observation_epochs,
    rounded_nav_value,
    signal_strength_digit,
    write_nav,
    write_obs,
)
from vo_doppler.sim.constellation import broadcast_ephemerides

T0 = 1_400_000_000.0


def test_header_records_and_navigation_numbers():
    line = header_line("x" * 70, "LABEL")
    assert len(line) == 81 and line[:60] == "x" * 60 and line[60:80] == "LABEL".ljust(20)
    assert nav_number(1.234567890123e-4) == " 1.234567890123D-04"
    assert nav_number(-6378137.0) == "-6.378137000000D+06"
    assert nav_number(1e-120) == " 0.000000000000D+00"  # no three-digit exponent
    assert rounded_nav_value(1.0 / 3.0) == 3.333333333333e-01


def test_gps_calendar_stamps():
    assert gps_calendar(0.0) == (1980, 1, 6, 0, 0, 0.0)
    assert gps_calendar(1e9 + 0.25) == (2011, 9, 14, 1, 46, 40.25)
    assert gps_calendar(59.9999996)[4:] == (1, 0.0)  # rounded to the microsecond


def test_the_signal_strength_digit_is_cn0_over_6_within_1_to_9():
    np.testing.assert_array_equal(
        signal_strength_digit([0.0, 11.9, 12.0, 35.0, 53.9, 54.0, 100.0]), [1, 1, 2, 5, 8, 9, 9]
    )


def _observations():
    return observations_from_rows(
        Path("x"),
        "r",
        time=[T0, T0, T0, T0, T0, T0 + 2.0],
        system=["G", "G", "G", "E", "G", "G"],
        prn=[5, 5, 5, 11, 5, 5],
        code=["S1C", "D1C", "C1C", "D5Q", "L1C", "C1C"],
        value=[45.0, -1234.567, 2.2e7, 321.5, 1.1e8, 2.2e7 + 10.0],
    )


def test_observation_rows_by_epoch_and_satellite_in_signal_order():
    data = observation_epochs(_observations())
    assert data.codes == ("C1C", "L1C", "D1C", "S1C", "D5Q")  # band 1: C, L, D, S; then band 5
    assert list(zip(data.epoch.tolist(), data.satellite.tolist(), strict=True)) == [
        (0, "E11"),
        (0, "G05"),
        (1, "G05"),
    ]
    np.testing.assert_array_equal(data.values[1], [2.2e7, 1.1e8, -1234.567, 45.0, np.nan])
    np.testing.assert_array_equal(data.values[0][:4], [np.nan] * 4)


def test_an_observation_file_reads_back(tmp_path):
    obs = _observations()
    path = tmp_path / "w.obs"
    write_obs(
        path, observation_epochs(obs), np.array([1.0, 2.0, 3.0]), 1.0, glonass_channels={3: -4}
    )
    back = read_obs(path)
    assert back.header.glonass_channels == {3: -4}
    np.testing.assert_array_equal(back.epoch_time, [T0, T0 + 2.0])
    got = {
        (t, s, p, back.codes[c]): (v, q)
        for t, s, p, c, v, q in zip(
            back.time, back.system, back.prn, back.code, back.value, back.ssi, strict=True
        )
    }
    assert got[(T0, "G", 5, "D1C")] == (-1234.567, 7)  # 45 dB-Hz: strength 7 on every field
    assert got[(T0, "G", 5, "L1C")] == (1.1e8, 7)
    assert got[(T0, "E", 11, "D5Q")][0] == 321.5
    assert got[(T0 + 2.0, "G", 5, "C1C")][0] == 2.2e7 + 10.0
    assert len(back) == len(obs)


def test_a_navigation_file_reads_back_with_glonass_in_utc(tmp_path):
    kepler = broadcast_ephemerides(T0, T0 + 600.0, "G")[:2]
    glonass = GlonassRecord(
        prn=3,
        toc=T0 + 900.0,
        params={
            "minus_tau_n": 1.5e-5,
            "gamma_n": 9.1e-13,
            "frame_time": 345600.0,
            "x": 1.2e7,
            "vx": -1500.0,
            "ax": 1e-6,
            "health": 0.0,
            "y": -1.5e7,
            "vy": 2500.0,
            "ay": 0.0,
            "channel": -4.0,
            "z": 1.8e7,
            "vz": 300.0,
            "az": -2e-6,
            "age": 0.0,
        },
    )
    klobuchar = np.array([1.1e-8, 2.2e-8, -6.0e-8, -1.2e-7, 9.0e4, 1.3e5, -6.6e4, -5.2e5])
    path = tmp_path / "w.nav"
    write_nav(path, [*kepler, glonass], leap_seconds=18, klobuchar=klobuchar)
    navigation = read_nav(path)
    assert navigation.leap_seconds == 18 and navigation.problems == ()
    np.testing.assert_allclose(navigation.klobuchar, klobuchar, rtol=1e-4)
    np.testing.assert_array_equal(navigation.kepler.toc, [r.toc for r in kepler])
    for name in ("sqrt_a", "e", "m0", "af0", "toe_sow"):
        expected = [rounded_nav_value(r.params[name]) for r in kepler]
        np.testing.assert_array_equal(navigation.kepler[name], expected)
    assert navigation.glonass.toc[0] == T0 + 900.0  # written 18 s earlier, in UTC
    assert navigation.glonass_channels() == {3: -4}
    assert navigation.glonass["x"][0] == pytest.approx(1.2e7, rel=1e-12)  # written in km
    assert navigation.glonass["vx"][0] == pytest.approx(-1500.0, rel=1e-12)
