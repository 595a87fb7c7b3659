"""SP3-c/d and RINEX clock readers: round trips through the test writers (LF and CRLF),
bad input named by line, and the real IAC product beside the comma2k19 minute."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import require_shared
from tests.helpers.precise_text import clock_text, sp3_text
from vo_doppler.errors import InputError
from vo_doppler.io.rinex_clock import read_rinex_clock
from vo_doppler.io.sp3 import read_sp3, satellite_id, to_gps_seconds
from vo_doppler.model.gpstime import calendar_to_gps_seconds

T0 = float(calendar_to_gps_seconds(2018, 8, 2, 14, 0, 0))
SATS = ["G01", "R05", "E11", "C06", "J01"]


def _write(tmp_path, text: str, name: str = "orbit.sp3"):
    path = tmp_path / name
    path.write_bytes(text.encode("ascii"))
    return path


@settings(max_examples=25, deadline=None)
@given(
    n_epochs=st.integers(1, 6),
    seed=st.integers(0, 2**32 - 1),
    crlf=st.booleans(),
    n_sats=st.integers(1, 40),
)
def test_sp3_round_trip(tmp_path_factory, n_epochs, seed, crlf, n_sats):
    rng = np.random.default_rng(seed)
    sats = [f"{'GREC'[k % 4]}{k // 4 + 1:02d}" for k in range(n_sats)]
    t = T0 + 900.0 * np.arange(n_epochs)
    direction = rng.normal(size=(n_epochs, n_sats, 3))
    radius = rng.uniform(2.0e7, 4.5e7, (n_epochs, n_sats, 1))  # MEO to GEO
    position = np.round(radius * direction / np.linalg.norm(direction, axis=2, keepdims=True), 3)
    clock = np.round(rng.uniform(-1e-3, 1e-3, (n_epochs, n_sats)), 12)
    position[rng.random((n_epochs, n_sats)) < 0.1] = np.nan
    clock[rng.random((n_epochs, n_sats)) < 0.1] = np.nan
    text = sp3_text(t, sats, position, clock, newline="\r\n" if crlf else "\n")
    orbits = read_sp3(_write(tmp_path_factory.mktemp("sp3"), text))
    assert list(orbits.sat_id) == sats
    np.testing.assert_array_equal(orbits.t, t)
    np.testing.assert_allclose(orbits.position, position, atol=1e-3, equal_nan=True)
    np.testing.assert_allclose(orbits.clock_s, clock, atol=1e-12, equal_nan=True)
    assert orbits.agency == "TST" and orbits.coordinate_system == "IGS14"


@pytest.mark.parametrize(
    ("system", "offset"), [("GPS", 0.0), ("GAL", 0.0), ("BDT", 14.0), ("TAI", -19.0)]
)
def test_sp3_time_systems(tmp_path, system, offset):
    text = sp3_text(np.array([T0, T0 + 900.0]), ["G01"], np.full((2, 1, 3), 2e7), np.zeros((2, 1)))
    orbits = read_sp3(_write(tmp_path, text.replace("%c M  cc GPS", f"%c M  cc {system}")))
    np.testing.assert_array_equal(orbits.t, np.array([T0, T0 + 900.0]) + offset)


def test_utc_and_glonass_time_use_leap_seconds():
    # 2018: GPS − UTC = 18 s; GLONASS time = UTC + 3 h
    assert to_gps_seconds(np.array([T0]), "UTC")[0] == T0 + 18.0
    assert to_gps_seconds(np.array([T0]), "GLO")[0] == T0 + 18.0 - 10800.0


def test_old_style_satellite_ids():
    assert satellite_id(" 5 ") == "G05"
    assert satellite_id("G 5") == "G05"
    assert satellite_id("R24") == "R24"


@pytest.mark.parametrize("cut", ["", "P", "PG", "G0"])
def test_a_satellite_field_cut_short_is_a_value_error(cut):
    # a record line cut inside its satellite field (fuzz: IndexError in the trimmed-SP3 reader)
    with pytest.raises(ValueError, match="no satellite"):
        satellite_id(cut[1:4] if cut.startswith("P") else cut)


def test_a_record_line_cut_inside_its_satellite_names_the_line(tmp_path):
    lines = _good_text().splitlines(keepends=True)
    record = next(i for i, line in enumerate(lines) if line.startswith("PG02"))
    lines[record] = "PG\n"
    path = tmp_path / "cut.sp3"
    path.write_text("".join(lines))
    with pytest.raises(InputError, match=f"cut.sp3:{record + 1}: bad satellite identifier"):
        read_sp3(path)


def _good_text():
    return sp3_text(
        np.array([T0, T0 + 900.0]), ["G01", "G02"], np.full((2, 2, 3), 2e7), np.zeros((2, 2))
    )


@pytest.mark.parametrize(
    ("edit", "line", "message"),
    [
        (lambda s: s.replace("#dP", "#aP", 1), 1, "SP3-c/d"),
        (lambda s: s.replace("      2 ORBIT", "      1 ORBIT", 1), 1, "header declares 1"),
        (lambda s: s.replace("PG02  20000.000000", "PG02  2000x.000000", 1), 14, "bad position"),
        (lambda s: s.replace("PG02", "PG07", 1), 14, "G07 not in the header"),
        (lambda s: s.replace("*  2018  8  2 14 15", "*  2018  8  2 1x 15", 1), 16, "epoch"),
        (lambda s: s.replace("%c M  cc GPS", "%c M  cc XYZ", 1), None, "time system"),
        (lambda s: s.replace("VG01", "QG01", 1), 13, "unexpected record"),
    ],
)
def test_sp3_bad_input_named(tmp_path, edit, line, message):
    path = _write(tmp_path, edit(_good_text()))
    with pytest.raises(InputError, match=message) as info:
        read_sp3(path)
    assert info.value.path == path
    assert info.value.line == line


def test_sp3_missing_file(tmp_path):
    with pytest.raises(InputError, match="cannot read"):
        read_sp3(tmp_path / "absent.sp3")


@pytest.mark.parametrize("version", ["3.04", "3.00", "2.00"])
@pytest.mark.parametrize("newline", ["\n", "\r\n"])
def test_rinex_clock_round_trip(tmp_path, version, newline):
    t = T0 + 30.0 * np.arange(4)
    bias = np.array([[1e-4, -2e-5], [1.00001e-4, np.nan], [1.00002e-4, -2.1e-5], [1e-4, -2.2e-5]])
    path = _write(tmp_path, clock_text(t, ["G01", "E11"], bias, version, newline), "p.clk")
    clocks = read_rinex_clock(path)
    assert list(clocks.sat_id) == ["E11", "G01"]
    np.testing.assert_array_equal(clocks.t, t)
    np.testing.assert_allclose(clocks.bias_s, bias[:, ::-1], rtol=1e-12, equal_nan=True)


def test_rinex_clock_bad_record_named(tmp_path):
    t = T0 + 30.0 * np.arange(2)
    text = clock_text(t, ["G01"], np.full((2, 1), 1e-4)).replace("  4    1.0", "  x    1.0", 1)
    path = _write(tmp_path, text, "p.clk")
    with pytest.raises(InputError, match="bad clock record") as info:
        read_rinex_clock(path)
    assert info.value.line == 5


def test_rinex_clock_rejects_other_files(tmp_path):
    path = _write(tmp_path, "     3.04           O                   G      RINEX VERSION / TYPE\n")
    with pytest.raises(InputError, match="not a RINEX clock file"):
        read_rinex_clock(path)


def test_real_iac_sp3_crlf():
    path = require_shared("comma2k19_example1/Sta20124_1400_1845.sp3")
    assert b"\r\n" in path.read_bytes()[:200]
    orbits = read_sp3(path)
    assert orbits.position.shape == (20, 87, 3)
    assert orbits.interval_s == 900.0
    assert orbits.t[0] == T0 and orbits.time_system == "GPS"
    assert {s[0] for s in orbits.sat_id} == set("CEGJR")
    # every position is on a GNSS orbit: MEO ~25 500 km, GEO/IGSO ~42 200 km; the eccentric
    # Galileo E14/E18 (e = 0.16) dip to 23 300 km, QZSS J01 (e = 0.075) climbs to 45 300 km
    radius = np.linalg.norm(orbits.position, axis=2)
    assert np.all((radius > 2.3e7) & (radius < 4.6e7))
    # missing clocks (999999.999999) are NaN: C01 epochs 0–16, C03 all, C04 7–16, R07 17–19
    missing = np.isnan(orbits.clock_s)
    assert missing.sum() == 50
    assert missing[:, list(orbits.sat_id).index("C03")].all()
    assert orbits.clock_s[0, list(orbits.sat_id).index("C02")] == pytest.approx(-74.424289e-6)


REAL_304_HEADER = "".join(
    f"{content:65}{label}\n"  # 3.04: content in columns 1-65, the label from column 66
    for content, label in [
        ("3.04" + " " * 17 + "C" + " " * 20 + "M", "RINEX VERSION / TYPE"),
        ("CCLOCK               CODE AIUB            20240316 060412 UTC", "PGM / RUN BY / DATE"),
        ("     4    AS    AR    CR    DR", "# / TYPES OF DATA"),
        ("   GPS", "TIME SYSTEM ID"),
        ("    18", "LEAP SECONDS"),
        ("COD  CENTER FOR ORBIT DETERMINATION IN EUROPE (CODE), AIUB", "ANALYSIS CENTER"),
        ("     2", "# OF SOLN SATS"),
        ("G01 E11", "PRN LIST"),
        ("", "END OF HEADER"),
    ]
)


def test_rinex_clock_304_layout_as_distributed(tmp_path):
    """RINEX clock 3.04 (CODE/IGS products since 2023): the type 'C' in column 22, the labels
    from column 66 (the 3.04 format document); 3.02's column 21 read it as no clock file."""
    body = (
        "AS G01       2018 08 02 14 00  0.000000  2    0.100000000000E-03  0.1E-10\n"
        "AS E11       2018 08 02 14 00 30.000000  1   -0.200000000000E-04\n"
    )
    path = _write(tmp_path, REAL_304_HEADER + body, "COD0OPSFIN.CLK")
    clocks = read_rinex_clock(path)
    assert list(clocks.sat_id) == ["E11", "G01"]
    np.testing.assert_array_equal(clocks.t, [T0, T0 + 30.0])
    assert clocks.bias_s[0, 1] == pytest.approx(1e-4) and clocks.bias_s[1, 0] == pytest.approx(
        -2e-5
    )


@pytest.mark.parametrize(
    ("first", "column"),
    [
        ("     3.04           C                   G                   RINEX VERSION / TYPE", 22),
        ("3.02                 C                    G                   RINEX VERSION / TYPE", 21),
    ],
)
def test_rinex_clock_layout_of_another_version_named(tmp_path, first, column):
    """A first line in the layout of another version is refused naming the column the version's
    layout puts the type in, and line 1."""
    path = _write(tmp_path, first + "\n" + REAL_304_HEADER.split("\n", 1)[1], "p.clk")
    with pytest.raises(InputError, match=f"type C in column {column}") as info:
        read_rinex_clock(path)
    assert info.value.line == 1 and info.value.path == path


def test_rinex_clock_unpublished_version_refused(tmp_path):
    path = _write(tmp_path, "3.05" + REAL_304_HEADER[4:], "p.clk")
    with pytest.raises(InputError, match=r"version 3\.05 is not one of"):
        read_rinex_clock(path)


@settings(max_examples=30, deadline=None)
@given(
    version=st.sampled_from(["2.00", "3.00", "3.01", "3.02", "3.04"]),
    n_epochs=st.integers(1, 5),
    bias=st.floats(-9e-3, 9e-3, allow_nan=False),
    crlf=st.booleans(),
)
def test_rinex_clock_every_version_round_trips(tmp_path_factory, version, n_epochs, bias, crlf):
    """Every published version, each in its own header layout, reads back its clocks."""
    t = T0 + 30.0 * np.arange(n_epochs)
    table = np.full((n_epochs, 1), bias)
    text = clock_text(t, ["G01"], table, version, "\r\n" if crlf else "\n")
    clocks = read_rinex_clock(_write(tmp_path_factory.mktemp("clk"), text, "p.clk"))
    np.testing.assert_array_equal(clocks.t, t)
    np.testing.assert_allclose(clocks.bias_s, table, rtol=1e-11, atol=1e-22)


def _trimmed(text: str, keep: int) -> str:
    """An SP3 text cut after its first ``keep`` epochs (header untouched), ending in EOF."""
    lines = text.splitlines(keepends=True)
    starts = [i for i, line in enumerate(lines) if line.startswith("*")]
    cut = starts[keep] if keep < len(starts) else len(lines) - 1
    return "".join(lines[:cut]) + "EOF\n"


@settings(max_examples=20, deadline=None)
@given(n_epochs=st.integers(2, 12), data=st.data())
def test_trimmed_sp3_reads_the_epochs_it_has(tmp_path_factory, n_epochs, data):
    """A product trimmed to a recording's hours (the header still declaring the whole day) is
    read with a warning: the epochs it holds, exactly as in the whole file; it was refused as
    '73 epochs, header declares 289'."""
    keep = data.draw(st.integers(1, n_epochs - 1))
    sats = ["G01", "E11"]
    t = T0 + 900.0 * np.arange(n_epochs)
    position = np.tile([2.0e7, 1.0e7, 1.0e7], (n_epochs, 2, 1)) + np.arange(n_epochs)[:, None, None]
    clock = np.full((n_epochs, 2), 1e-4)
    text = sp3_text(t, sats, position, clock)
    folder = tmp_path_factory.mktemp("trim")
    whole = read_sp3(_write(folder, text, "whole.sp3"))
    trimmed = read_sp3(_write(folder, _trimmed(text, keep), "trim.sp3"))
    np.testing.assert_array_equal(trimmed.t, whole.t[:keep])
    np.testing.assert_array_equal(trimmed.position, whole.position[:keep])
    np.testing.assert_array_equal(trimmed.clock_s, whole.clock_s[:keep])


def test_trimmed_sp3_warns_with_its_span(tmp_path, caplog):
    t = T0 + 900.0 * np.arange(4)
    text = sp3_text(t, ["G01"], np.full((4, 1, 3), 2e7), np.zeros((4, 1)))
    path = _write(tmp_path, _trimmed(text, 2))
    with caplog.at_level("WARNING"):
        assert read_sp3(path).t.size == 2
    assert "2 of the 4 epochs the header declares" in caplog.text
    assert "2018-08-02 14:00:00 to 2018-08-02 14:15:00" in caplog.text and str(path) in caplog.text


@pytest.mark.parametrize(
    ("edit", "reason"),
    [
        (lambda s: s.replace("*  2018  8  2 14  0", "*  2018  8  2 13 45", 1), "start time"),
        (lambda s: s.replace("*  2018  8  2 14 15", "*  2018  8  2 14 20", 1), "interval of 900"),
    ],
)
def test_trimmed_sp3_inconsistent_with_its_header_refused(tmp_path, edit, reason):
    """Fewer epochs than declared and epochs that do not fit the header's start and interval:
    a damaged file, refused naming line 1."""
    t = T0 + 900.0 * np.arange(4)
    text = sp3_text(t, ["G01"], np.full((4, 1, 3), 2e7), np.zeros((4, 1)))
    path = _write(tmp_path, edit(_trimmed(text, 3)))
    with pytest.raises(InputError, match=f"3 epochs, header declares 4, and .*{reason}") as info:
        read_sp3(path)
    assert info.value.line == 1
