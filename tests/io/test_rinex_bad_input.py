"""Bad RINEX input: a clear message with file and line, and everything else still read."""

from __future__ import annotations

import resource

import numpy as np
import pytest

from tests.conftest import require_shared
from tests.helpers.rinex_text import field, rinex2_epoch, rinex2_header, rinex3_epoch, rinex3_header
from vo_doppler.errors import InputError
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs

TYPES = {"G": ["C1C", "D1C"], "E": ["C1C", "D1C"]}


def _epoch(second: int, sats=("G05", "G07", "E11")) -> str:
    records = [(sat, [field(2.0e7 + k), field(-1000.0 - k, ssi=7)]) for k, sat in enumerate(sats)]
    return rinex3_epoch(f"2024 06 24 08 20 {second:2d}.0000000", records)


def _write(tmp_path, text: str, name: str = "bad.24o"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _line_of(text: str, fragment: str) -> int:
    return next(i for i, line in enumerate(text.splitlines(), start=1) if fragment in line)


def test_corrupt_number_is_skipped_with_its_line(tmp_path):
    text = rinex3_header(TYPES) + _epoch(0) + _epoch(1)
    text = text.replace("  20000001.000", "  200x0001.000", 1)
    path = _write(tmp_path, text)
    obs = read_obs(path)
    line = _line_of(text, "200x0001")
    assert len(obs.problems) == 1
    assert f"{path}:{line}:" in obs.problems[0]
    assert "corrupt number" in obs.problems[0]
    assert len(obs) == 2 * 3 * 2 - 1


def test_unknown_system_letter_is_skipped_with_its_line(tmp_path):
    text = rinex3_header(TYPES) + _epoch(0, ("G05", "X07", "E11")) + _epoch(1)
    path = _write(tmp_path, text)
    obs = read_obs(path)
    assert obs.problems == (
        f"{path}:{_line_of(text, 'X07')}: unknown satellite system letter 'X': record skipped",
    )
    assert len(obs) == 2 * 2 + 3 * 2


def test_rinex3_satellite_count_mismatch_skips_the_epoch_only(tmp_path):
    """Lines that do not match the count may belong to another epoch: none of them is used."""
    epoch = _epoch(0).replace("  0  3\n", "  0  4\n", 1)
    text = rinex3_header(TYPES) + epoch + _epoch(1)
    path = _write(tmp_path, text)
    obs = read_obs(path)
    assert obs.problems == (
        f"{path}:{_line_of(text, '> 2024 06 24 08 20  0.0')}: "
        "epoch says 4 satellites but 3 lines follow: epoch skipped",
    )
    assert obs.epoch_time.size == 1
    assert len(obs) == 6


def test_rinex3_truncated_last_epoch_reads_the_lines_present(tmp_path):
    epoch = _epoch(1).replace("  0  3\n", "  0  4\n", 1)
    text = rinex3_header(TYPES) + _epoch(0) + epoch
    path = _write(tmp_path, text)
    obs = read_obs(path)
    assert len(obs.problems) == 1
    assert "says 4 satellites but 3 lines follow before the end of the file" in obs.problems[0]
    assert len(obs) == 12


def test_rinex2_satellite_count_mismatch_skips_the_epoch_only(tmp_path):
    records = [(f"G{k:2d}", [field(2.0e7 + k), field(-1000.0)]) for k in range(1, 5)]
    bad = rinex2_epoch(" 10  1  6  5 57  3.0000000", records)
    bad = bad.replace("  0  4G", "  0  5G", 1)
    text = rinex2_header(["C1", "D1"]) + bad + rinex2_epoch(" 10  1  6  5 57  4.0000000", records)
    path = _write(tmp_path, text, "bad.10o")
    obs = read_obs(path)
    assert len(obs.problems) == 1
    assert f"{path}:{_line_of(text, '57  3.0')}:" in obs.problems[0]
    assert obs.epoch_time.size == 1
    assert len(obs) == 8


def test_truncated_real_file_keeps_complete_records(tmp_path):
    source = require_shared("septentrio_static/rover.obs").read_bytes()
    cut = source[: len(source) // 2]
    cut = cut[: cut.rfind(b"\n") + 40]  # stop 40 characters into a line
    path = tmp_path / "truncated.24o"
    path.write_bytes(cut)
    obs = read_obs(path)
    last_line = cut.count(b"\n") + 1
    assert any(f"{path}:{last_line}:" in p for p in obs.problems)
    assert any("lines follow" in p for p in obs.problems)
    full = read_obs(require_shared("septentrio_static/rover.obs"))
    assert 140 <= obs.epoch_time.size <= 160
    # every value read from the truncated file equals the full file's value
    full_keys = zip(full.time, full.satellites(), full.code, strict=True)
    keys_full = dict(zip(full_keys, full.value, strict=True))
    keys = zip(obs.time, obs.satellites(), obs.code, strict=True)
    for key, value in zip(keys, obs.value, strict=True):
        assert keys_full[key] == value


def test_truncated_rinex2_file(tmp_path):
    source = require_shared("yamatogawa_ublox_walk/yamatogawa_rover.obs").read_text()
    lines = source.splitlines(keepends=True)
    path = _write(tmp_path, "".join(lines[:-3]), "truncated.10o")
    obs = read_obs(path)
    assert any("file ends inside this epoch" in p for p in obs.problems)
    assert obs.epoch_time.size == 203


@pytest.mark.parametrize(
    ("first_line", "message"),
    [
        ("     3.04           OBSERVATION DATA    M                   RINEX VERSION", "first line"),
        (
            "     9.99           OBSERVATION DATA    M                   RINEX VERSION / TYPE",
            "9.99",
        ),
        (
            "     3.x4           OBSERVATION DATA    M                   RINEX VERSION / TYPE",
            "3.x4",
        ),
        (
            "     3.04           N: GNSS NAV DATA    M                   RINEX VERSION / TYPE",
            "type",
        ),
    ],
)
def test_wrong_version_line_is_refused_with_line_one(tmp_path, first_line, message):
    text = rinex3_header(TYPES).split("\n", 1)[1]
    path = _write(tmp_path, first_line + "\n" + text + _epoch(0))
    with pytest.raises(InputError, match=message) as error:
        read_obs(path)
    assert error.value.line == 1
    assert str(path) in str(error.value)


def test_missing_header_end_is_refused(tmp_path):
    path = _write(tmp_path, rinex3_header(TYPES).replace("END OF HEADER", "END OF HEDER"))
    with pytest.raises(InputError, match="END OF HEADER"):
        read_obs(path)


def test_nav_corrupt_and_truncated_records(tmp_path):
    source = require_shared("septentrio_static/base.nav").read_text().splitlines(keepends=True)
    header_end = next(i for i, line in enumerate(source) if "END OF HEADER" in line)
    first_record = header_end + 1
    corrupt = source[first_record + 1].replace("E+01", "X+01", 1)
    lines = [*source[: first_record + 1], corrupt, *source[first_record + 2 : -2]]
    path = tmp_path / "bad.nav"
    path.write_text("".join(lines))
    nav = read_nav(path)
    full = read_nav(require_shared("septentrio_static/base.nav"))
    assert (
        f"{path}:{first_record + 2}: number '7.200000000000X+01' not in D19.12 form"
        in (nav.problems[1][: nav.problems[1].index(": record skipped")])
    )
    assert "record has 6 of its 8 lines (the file ends): skipped" in nav.problems[0]
    assert len(nav.kepler) + len(nav.glonass) == len(full.kepler) + len(full.glonass) - 2


def test_unknown_system_in_nav_is_reported(tmp_path):
    source = require_shared("septentrio_static/base.nav").read_text()
    text = source.replace("\nG05 2024", "\nX05 2024", 1)
    path = tmp_path / "x.nav"
    path.write_text(text)
    nav = read_nav(path)
    assert any("unknown satellite system 'X'" in p for p in nav.problems)
    full = read_nav(require_shared("septentrio_static/base.nav"))
    assert len(nav.kepler) == len(full.kepler) - 1


def test_epochs_out_of_order_are_refused_naming_the_epoch(tmp_path):
    text = rinex3_header(TYPES) + _epoch(0) + _epoch(5) + _epoch(3)
    path = _write(tmp_path, text)
    with pytest.raises(InputError, match="2 s before the epoch above it") as error:
        read_obs(path)
    assert error.value.line == _line_of(text, "08 20  3.0")


def test_repeated_epochs_are_dropped_with_a_count(tmp_path):
    text = rinex3_header(TYPES) + _epoch(0) + _epoch(1) + _epoch(1) + _epoch(1) + _epoch(2)
    path = _write(tmp_path, text)
    obs = read_obs(path)
    assert len(obs.problems) == 1
    assert "2 epochs repeat the time of the epoch above and are dropped" in obs.problems[0]
    np.testing.assert_array_equal(np.diff(obs.epoch_time), [1.0, 1.0])
    assert len(obs) == 3 * 3 * 2


@pytest.mark.parametrize(
    ("date", "reason"),
    [("2024 13 24 08 20  1.0000000", "month 13"), ("2024 06 24 25 20  1.0000000", "time 25")],
)
def test_impossible_epoch_date_skips_the_epoch(tmp_path, date, reason):
    text = rinex3_header(TYPES) + _epoch(0) + _epoch(1).replace("2024 06 24 08 20  1.0000000", date)
    path = _write(tmp_path, text)
    obs = read_obs(path)
    assert obs.problems == (
        f"{path}:{_line_of(text, date)}: epoch date unusable ({reason}"
        + obs.problems[0].split(reason, 1)[1],
    )
    assert obs.epoch_time.size == 1


@pytest.mark.parametrize("sat", ["G00", "G33", "E37", "R28"])
def test_satellite_numbers_outside_their_system_are_skipped(tmp_path, sat):
    text = rinex3_header(TYPES | {"R": ["C1C", "D1C"]}) + _epoch(0, ("G05", sat, "E11"))
    path = _write(tmp_path, text)
    obs = read_obs(path)
    assert obs.problems == (
        f"{path}:{_line_of(text, sat)}: satellite number '{sat[1:]}' of {sat[0]}: record skipped",
    )
    assert sorted(obs.satellites().tolist()) == ["E11", "E11", "G05", "G05"]


def test_satellite_twice_in_an_epoch_keeps_its_first_record(tmp_path):
    epoch = _epoch(0, ("G05", "G07", "G05"))
    path = _write(tmp_path, rinex3_header(TYPES) + epoch)
    obs = read_obs(path)
    assert len(obs.problems) == 1
    assert "G05 listed twice in one epoch: second skipped" in obs.problems[0]
    np.testing.assert_array_equal(obs.value[obs.satellites() == "G05"], [2.0e7, -1000.0])


def test_number_cut_short_is_not_read_as_a_shorter_number(tmp_path):
    text = rinex3_header(TYPES) + _epoch(0)
    line = next(x for x in text.splitlines() if x.startswith("E11"))
    cut = line[: 3 + 16 + 13]  # the D1C value loses its last decimal
    path = _write(tmp_path, text.replace(line, cut))
    obs = read_obs(path)
    assert len(obs.problems) == 1
    assert "corrupt number '-1002.00' (D1C) skipped" in obs.problems[0]
    assert (obs.value[obs.satellites() == "E11"] == [2.0e7 + 2]).all()


def test_thousands_of_extra_observation_type_lines_are_refused_quickly(tmp_path):
    header = rinex3_header(TYPES)
    extra = "".join(line for line in header.splitlines(keepends=True) if "G    2" in line)
    extra = extra.replace("G    2", "      ") * 3000
    text = header.replace("E    2", extra + "E    2") + _epoch(0)
    path = _write(tmp_path, text)
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(InputError, match="more observation types than the 2 declared") as error:
        read_obs(path)
    assert error.value.line == _line_of(text, "SYS / # / OBS TYPES") + 1
    assert (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024 < 100


def test_garbage_glonass_slot_line_is_reported_and_the_rest_read(tmp_path):
    slots = "  3 R01  1 R02 -4 Rxx  9 R05  1".ljust(60) + "GLONASS SLOT / FRQ #".ljust(20) + "\n"
    text = rinex3_header(TYPES).replace("     1.000", slots + "     1.000", 1)
    text = text.replace(slots + "     1.000", slots.rstrip("\n") + "\n" + "     1.000", 1)
    path = _write(tmp_path, text + _epoch(0))
    obs = read_obs(path)
    assert obs.header.glonass_channels == {1: 1, 2: -4, 5: 1}
    assert obs.problems == (
        f"{path}:{_line_of(text, 'R01')}: unreadable GLONASS slot/channel 'Rxx  9' ignored",
    )


def _brdc_lines():
    return require_shared("yamatogawa_ublox_walk/brdc0060.10n").read_text().splitlines(True)


def test_duplicated_line_in_rinex2_nav_costs_one_record(tmp_path):
    """The issue's case: one duplicated line made 417 records into 1 wrong one."""
    lines = _brdc_lines()
    k = next(i for i, line in enumerate(lines) if "END OF HEADER" in line) + 8 * 100 + 3
    path = tmp_path / "dup.10n"
    path.write_text("".join([*lines[: k + 1], lines[k], *lines[k + 1 :]]))
    nav = read_nav(path)
    full = read_nav(require_shared("yamatogawa_ublox_walk/brdc0060.10n"))
    assert len(full.kepler) == 417
    assert len(nav.kepler) == 416
    assert nav.problems == (
        f"{path}:{k - 1}: record has 9 lines where 8 are expected (misaligned): skipped",
    )
    kept = np.ones(417, dtype=bool)
    kept[100] = False
    for name in ("sqrt_a", "e", "m0", "toe"):
        np.testing.assert_array_equal(nav.kepler[name], full.kepler[name][kept])


def test_deleted_line_in_rinex2_nav_costs_one_record(tmp_path):
    lines = _brdc_lines()
    k = next(i for i, line in enumerate(lines) if "END OF HEADER" in line) + 8 * 7 + 5
    path = tmp_path / "del.10n"
    path.write_text("".join(lines[:k] + lines[k + 1 :]))
    nav = read_nav(path)
    assert len(nav.kepler) == 416
    assert nav.problems == (
        f"{path}:{k - 3}: record has 7 of its 8 lines "
        "(a line that does not continue it follows): skipped",
    )


@pytest.mark.parametrize(
    ("old", "new", "reason"),
    [
        ("0.515365295982E+04", "               inf", "not in D19.12 form"),
        ("0.515365295982E+04", "0.515365295982E+09", "sqrt_a = 5.15365e+08 outside"),
        ("0.384141004179E-02", "0.384141004179E+02", "e = 38.4141 outside"),
        ("0.515365295982E+04", "0.515365295982E+0 ", "not in D19.12 form"),
    ],
)
def test_impossible_orbital_parameters_skip_the_record(tmp_path, old, new, reason):
    lines = _brdc_lines()
    first = next(i for i, line in enumerate(lines) if "END OF HEADER" in line) + 1
    lines[first + 2] = lines[first + 2].replace(old, new)
    path = tmp_path / "inf.10n"
    path.write_text("".join(lines))
    nav = read_nav(path)
    assert len(nav.kepler) == 416
    assert len(nav.problems) == 1
    assert f"{path}:{first + 1 + 9 - 8}:" in nav.problems[0] or reason in nav.problems[0]
    assert reason in nav.problems[0]


def test_prn_zero_in_nav_is_skipped(tmp_path):
    lines = _brdc_lines()
    first = next(i for i, line in enumerate(lines) if "END OF HEADER" in line) + 1
    lines[first] = " 0" + lines[first][2:]
    path = tmp_path / "prn0.10n"
    path.write_text("".join(lines))
    nav = read_nav(path)
    assert nav.problems == (f"{path}:{first + 1}: satellite number '0' of G: record skipped",)
    assert 0 not in nav.kepler.prn


def test_file_without_any_observation_is_refused(tmp_path):
    """Every epoch lists 0 satellites: nothing to read, said once instead of empty arrays."""
    text = rinex3_header(TYPES) + "".join(
        rinex3_epoch(f"2024 06 24 08 20 {k:2d}.0000000", []) for k in range(5)
    )
    path = _write(tmp_path, text)
    with pytest.raises(InputError, match=r"no observation could be read \(5 epochs") as error:
        read_obs(path)
    assert str(path) in str(error.value)


def test_nav_file_without_any_readable_record_gives_empty_tables(tmp_path):
    lines = _brdc_lines()
    end = next(i for i, line in enumerate(lines) if "END OF HEADER" in line) + 1
    body = [line.replace("E+", "X+") for line in lines[end : end + 16]]
    path = tmp_path / "none.10n"
    path.write_text("".join(lines[:end] + body))
    nav = read_nav(path)
    assert len(nav.kepler) == len(nav.glonass) == 0
    assert len(nav.problems) == 2


def test_many_problems_are_all_listed_but_not_all_logged(tmp_path, caplog):
    epochs = "".join(_epoch(k, ("G05", "X07", "E11")) for k in range(50))
    path = _write(tmp_path, rinex3_header(TYPES) + epochs)
    obs = read_obs(path)
    assert len(obs.problems) == 50
    warnings = [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]
    assert len(warnings) == 22
    assert warnings[20] == f"{path}: more problems follow; only their count is logged"
    assert warnings[21] == f"{path}: 50 problems in all"
