"""``vo-doppler gnss velocity|spp`` end to end on the u-blox walk."""

from __future__ import annotations

import csv
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import REPO_ROOT, require_shared
from tests.helpers.precise_text import clock_text, sp3_text
from tests.helpers.rinex_text import field, rinex3_epoch, rinex3_header
from vo_doppler.cli import main
from vo_doppler.commands import gnss_command
from vo_doppler.commands.gnss_command import _glonass_dropped, _systems_solved
from vo_doppler.io.gnss_csv import SPP_COLUMNS, VELOCITY_COLUMNS
from vo_doppler.io.receiver_file import read_observation_file
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.model.gnss_solutions import SppSolution
from vo_doppler.model.gpstime import calendar_to_gps_seconds


def _read(path):
    with path.open() as handle:
        rows = list(csv.reader(handle))
    return rows[0], rows[1:]


@pytest.mark.slow
@pytest.mark.shared_data
def test_velocity_and_spp_commands(tmp_path):
    obs = require_shared("yamatogawa_ublox_walk/yamatogawa_rover.obs")
    nav = require_shared("yamatogawa_ublox_walk/brdc0060.10n")
    out = tmp_path / "vel.csv"
    code = main(["gnss", "velocity", str(obs), "--nav", str(nav), "--systems", "G", "-o", str(out)])
    assert code == 0
    header, rows = _read(out)
    assert tuple(header) == VELOCITY_COLUMNS
    assert len(rows) == 203
    table = np.array(rows, dtype=float)
    speed = np.hypot(table[:, 1], table[:, 2])
    course = np.mod(np.rad2deg(np.arctan2(table[:, 1], table[:, 2])), 360.0)
    np.testing.assert_allclose(speed, table[:, 4], atol=2e-4)  # speed_mps is horizontal
    fast = table[:, 4] > 0.5
    np.testing.assert_allclose(course[fast], table[fast, 5], atol=0.05)
    assert (out.with_suffix(".png")).stat().st_size > 10_000
    spp_out = tmp_path / "pos.csv"
    args = ["gnss", "spp", str(obs), "--nav", str(nav), "--systems", "G", "-o", str(spp_out)]
    assert main(args) == 0
    header, rows = _read(spp_out)
    assert tuple(header) == SPP_COLUMNS
    assert np.array(rows, dtype=float)[:, -1].all()


@pytest.mark.slow
@pytest.mark.shared_data
def test_the_summary_line_counts_the_input_problems_the_reader_warned(tmp_path, caplog):
    """A time system the RINEX version lacks is read as GPS and warned: a problem, not a
    skipped record."""
    text = require_shared("yamatogawa_ublox_walk/yamatogawa_rover.obs").read_text()
    obs = tmp_path / "utc.obs"
    obs.write_text(
        text.replace("     GPS         TIME OF FIRST OBS", "     UTC         TIME OF FIRST OBS")
    )
    nav = require_shared("yamatogawa_ublox_walk/brdc0060.10n")
    out = tmp_path / "vel.csv"
    assert main(["gnss", "velocity", str(obs), "--nav", str(nav), "-o", str(out)]) == 0
    assert "TIME OF FIRST OBS time system 'UTC'" in caplog.text
    assert "; 1 input problems (warned above)" in caplog.text
    assert "skipped" not in caplog.records[-1].getMessage()


def test_unknown_system_letter_is_a_usage_error(tmp_path):
    with pytest.raises(SystemExit) as stop:
        main(["gnss", "velocity", "x.obs", "--nav", "x.nav", "--systems", "GX", "-o", "v.csv"])
    assert stop.value.code == 2


def test_missing_file_is_a_runtime_error(tmp_path, capsys):
    code = main(["gnss", "spp", str(tmp_path / "none.obs"), "--nav", "x", "-o", "p.csv"])
    assert code == 1
    assert "none.obs" in capsys.readouterr().err


def test_systems_or_bands_without_doppler_in_the_file_name_what_it_has(tmp_path, capsys):
    """Checked before the navigation file is read: --systems E or --bands 2 on a GPS L1 file
    named the file's Doppler observables (was: 'too few satellites with ephemerides', or an
    internal error for a system absent from the file)."""
    obs = tmp_path / "gps.obs"
    obs.write_text(
        rinex3_header({"G": ["C1C", "D1C"]})
        + rinex3_epoch("2024 06 24 08 20  0.0000000", [("G05", [field(2.1e7), field(-500.0)])])
    )
    for option in (["--systems", "E"], ["--bands", "2"]):
        out = str(tmp_path / "v.csv")
        argv = ["gnss", "velocity", str(obs), "--nav", "none.nav", *option, "-o", out]
        assert main(argv) == 1
        err = capsys.readouterr().err
        assert "gps.obs: the file has no Doppler of the systems" in err
        assert err.strip().endswith("its Doppler observables: G D1C")


SAMPLE_GNSS = REPO_ROOT / "sample_sequences" / "urban_canyon_small" / "gnss"


def _without_doppler(tmp_path):
    """The u-blox walk (RINEX 2.10, C1 L1 S1 D1) without its Doppler column: C1 L1 S1."""
    lines = require_shared("yamatogawa_ublox_walk/yamatogawa_rover.obs").read_text().splitlines()
    end = next(k for k, line in enumerate(lines) if "END OF HEADER" in line)
    header = [
        line.replace("     4    C1    L1    S1    D1", "     3    C1    L1    S1      ")
        for line in lines[: end + 1]
    ]
    body = [
        line if re.match(r"^ \d\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d [ \d]\d\.\d", line) else line[:48]
        for line in lines[end + 1 :]
    ]
    obs = tmp_path / "no_doppler.10o"
    obs.write_text("\n".join(header + body) + "\n")
    return obs


@pytest.mark.slow
@pytest.mark.shared_data
def test_a_file_without_doppler_is_solved_from_its_carrier_phase(tmp_path, capsys):
    """A RINEX 2 with carrier phase but no Doppler: the refusal names --range-rate phase, and
    --range-rate phase solves it (it was refused 'no Doppler' in phase mode too)."""
    obs = _without_doppler(tmp_path)
    nav = require_shared("yamatogawa_ublox_walk/brdc0060.10n")
    out = tmp_path / "vel.csv"
    argv = ["gnss", "velocity", str(obs), "--nav", str(nav), "--systems", "G", "-o", str(out)]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "no Doppler of the systems 'G'" in err and "--range-rate phase" in err and "L1" in err
    assert not out.exists()
    assert main([*argv, "--range-rate", "phase"]) == 0
    header, rows = _read(out)
    assert sum(int(row[header.index("valid")]) for row in rows) > 100


def _wrong_day_nav(tmp_path):
    """The sample's navigation file with every record moved from 2025-03-14 to 2021-01-01."""
    text = (SAMPLE_GNSS / "brdc.nav").read_text()
    nav = tmp_path / "wrong_day.nav"
    nav.write_text(re.sub(r"(?m)^([A-Z]\d\d) 2025 03 14", r"\1 2021 01 01", text))
    return nav


@pytest.mark.parametrize("action", ["velocity", "spp"])
def test_navigation_of_another_day_is_one_error_and_writes_nothing(
    tmp_path, capsys, caplog, action
):
    """One error naming both date spans and the file, not one 'no healthy ephemeris' line per
    satellite and 'no epoch could be solved'; the CSV and the PNG are not written, and an
    earlier run's files stay as they were."""
    nav = _wrong_day_nav(tmp_path)
    out = tmp_path / "out.csv"
    out.write_text("earlier run\n")
    argv = ["gnss", action, str(SAMPLE_GNSS / "rover.obs"), "--nav", str(nav), "-o", str(out)]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "wrong_day.nav: ephemerides valid 2020-12-31 22:00:00 to 2021-01-01" in err
    assert "rover.obs run 2025-03-14 02:10:00 to 2025-03-14 02:10:38 GPS time" in err
    assert "no ephemeris at any observation epoch" in err
    assert "no healthy ephemeris" not in caplog.text
    assert out.read_text() == "earlier run\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.csv", "wrong_day.nav"]


def test_a_run_that_solves_no_epoch_leaves_no_output(tmp_path, capsys):
    """Exit 1 with every epoch invalid (here the elevation mask removes every satellite):
    neither vel.csv nor vel.png of that run is left (they were written, every row invalid)."""
    out = tmp_path / "vel.csv"
    argv = ["gnss", "velocity", str(SAMPLE_GNSS / "rover.obs"), "--nav"]
    argv += [str(SAMPLE_GNSS / "brdc.nav"), "--elev-mask", "89.9", "-o", str(out)]
    assert main(argv) == 1
    assert "nothing written" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def _orbit_file(tmp_path, name: str, start: float, n: int) -> Path:
    t = start + 900.0 * np.arange(n)
    path = tmp_path / name
    path.write_text(sp3_text(t, ["G10", "G29"], np.full((n, 2, 3), 1.5e7), np.zeros((n, 2))))
    return path


SAMPLE_T0 = float(calendar_to_gps_seconds(2025, 3, 14, 2, 10, 0))


def test_precise_orbits_or_clocks_of_another_time_are_named(tmp_path, capsys, caplog):
    """Orbits or a clock file that cover no observation epoch: one error naming both spans
    and the file; a clock file covering part of them: a warning naming both spans."""
    obs = str(SAMPLE_GNSS / "rover.obs")
    out = str(tmp_path / "vel.csv")
    day_before = _orbit_file(tmp_path, "before.sp3", SAMPLE_T0 - 86400.0, 8)
    assert main(["gnss", "velocity", obs, "--orbits", str(day_before), "-o", out]) == 1
    err = capsys.readouterr().err
    assert "the precise orbits " in err and "before.sp3: epochs 2025-03-13 02:10:00" in err
    assert "no orbit at any observation epoch" in err
    orbits = _orbit_file(tmp_path, "around.sp3", SAMPLE_T0 - 1800.0, 5)
    clocks = tmp_path / "late.clk"
    late = SAMPLE_T0 + 3600.0 + 30.0 * np.arange(3)
    clocks.write_text(clock_text(late, ["G10", "G29"], np.zeros((3, 2))))
    argv = ["gnss", "velocity", obs, "--orbits", str(orbits), "--clocks", str(clocks)]
    assert main([*argv, "-o", out]) == 1
    err = capsys.readouterr().err
    assert "the clock file " in err and "late.clk: epochs 2025-03-14 03:10:00" in err
    assert "2025-03-14 02:10:38 GPS time: no clock at any observation epoch" in err
    half = tmp_path / "half.clk"
    clock_t = SAMPLE_T0 - 60.0 + 30.0 * np.arange(4)  # to 02:10:30, the last 8 s uncovered
    half.write_text(clock_text(clock_t, ["G10", "G29"], np.zeros((4, 2))))
    main(["gnss", "velocity", obs, "--orbits", str(orbits), "--clocks", str(half), "-o", out])
    assert "half.clk: epochs 2025-03-14 02:09:00 to 2025-03-14 02:10:30" in caplog.text
    assert "of the 761 observation epochs (the first at 2025-03-14 02:10:30) have no clock" in (
        caplog.text
    )


def _glonass_without_channels(tmp_path):
    """The canyon's rover.obs with its Galileo satellites renamed GLONASS: GLONASS Doppler with
    no GLONASS SLOT / FRQ # entry, and brdc.nav has no GLONASS record."""
    text = (SAMPLE_GNSS / "rover.obs").read_text()
    obs = tmp_path / "glonass.obs"
    obs.write_text(re.sub(r"(?m)^E(\d\d)", r"R\1", text.replace("E    3 C1C", "R    3 C1C")))
    return obs


@pytest.mark.parametrize("action", ["velocity", "spp"])
def test_glonass_rows_without_a_frequency_channel_are_said_once_and_left_out_of_the_title(
    action, tmp_path, caplog, monkeypatch
):
    """GLONASS Doppler without a channel (no GLONASS SLOT / FRQ # entry, no GLONASS record in
    the navigation file): ``velocity`` says once, with the count and the satellites, that it
    drops them (they were dropped without a word); ``spp``, which reads pseudoranges and needs
    no channel, says nothing of Doppler rows. Each figure's title names the systems used, not R
    (issue 30: it read "GREJC", the systems asked for): here GLONASS has no ephemeris either."""
    obs = _glonass_without_channels(tmp_path)
    titles = []

    def drawn(path, solution, title=""):
        titles.append(title)
        Path(path).write_bytes(b"")

    monkeypatch.setattr(gnss_command, f"{action}_figure", drawn)
    out = tmp_path / "out.csv"
    main(["gnss", action, str(obs), "--nav", str(SAMPLE_GNSS / "brdc.nav"), "-o", str(out)])
    said = [r.getMessage() for r in caplog.records if r.getMessage().startswith("GLONASS:")]
    if action == "velocity":
        assert len(said) == 1
        start = "GLONASS: 1606 Doppler rows of R02, R03, R04, R10, R19, R21 dropped"
        assert said[0].startswith(start)
    else:
        assert said == []
    assert titles == ["glonass.obs (G)"]


def test_the_spp_title_names_the_systems_whose_clock_was_solved():
    """GLONASS pseudoranges need no frequency channel: where the SPP solved a GLONASS clock
    (SP3 orbits, which carry no channel), R stays in the title."""
    n = 3
    nan = np.full(n, np.nan)
    clocks = {"G": np.array([1.0, np.nan, 2.0]), "R": np.array([np.nan, 3.0, np.nan]), "E": nan}
    solution = SppSolution(
        np.arange(n, dtype=float),
        np.zeros((n, 3)),
        clocks,
        np.full(n, 6),
        nan,
        nan,
        np.ones(n, dtype=bool),
        0,
    )
    assert _systems_solved(solution, "GREJC") == "GR"
    assert _systems_solved(solution, "RG") == "RG"
    assert _systems_solved(solution, "EJ") == "no system solved"


def test_glonass_with_a_channel_for_some_satellites_stays_in_the_title(tmp_path, caplog):
    """Only the satellites without a channel are dropped: GLONASS keeps its place among the
    systems used."""
    obs, _ = read_observation_file(_glonass_without_channels(tmp_path))
    nav = read_nav(SAMPLE_GNSS / "brdc.nav")
    assert _glonass_dropped(obs, nav, "GREJC", None) == "G"
    some = replace(obs, header=replace(obs.header, glonass_channels={2: 1, 3: -4}))
    assert _glonass_dropped(some, nav, "GREJC", None) == "GR"
    assert _glonass_dropped(some, nav, "R", None) == "R"
    said = [r.getMessage() for r in caplog.records if r.getMessage().startswith("GLONASS:")]
    assert (
        said[-1].startswith("GLONASS: ")
        and " Doppler rows of R04, R10, R19, R21 dropped" in said[-1]
    )
