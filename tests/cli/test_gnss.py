"""``vo-doppler gnss velocity|spp`` end to end on the u-blox walk."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from tests.conftest import require_shared
from tests.helpers.rinex_text import field, rinex3_epoch, rinex3_header
from vo_doppler.cli import main
from vo_doppler.io.gnss_csv import SPP_COLUMNS, VELOCITY_COLUMNS


def _read(path):
    with path.open() as handle:
        rows = list(csv.reader(handle))
    return rows[0], rows[1:]


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
    np.testing.assert_allclose(np.hypot(speed, table[:, 3]), table[:, 4], atol=2e-4)
    fast = table[:, 4] > 0.5
    np.testing.assert_allclose(course[fast], table[fast, 5], atol=0.05)
    assert (out.with_suffix(".png")).stat().st_size > 10_000
    spp_out = tmp_path / "pos.csv"
    args = ["gnss", "spp", str(obs), "--nav", str(nav), "--systems", "G", "-o", str(spp_out)]
    assert main(args) == 0
    header, rows = _read(spp_out)
    assert tuple(header) == SPP_COLUMNS
    assert np.array(rows, dtype=float)[:, -1].all()


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
