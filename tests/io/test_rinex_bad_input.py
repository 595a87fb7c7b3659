"""Bad RINEX input: a clear message with file and line, and everything else still read."""

from __future__ import annotations

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


def test_rinex3_satellite_count_mismatch_reads_the_lines_present(tmp_path):
    epoch = _epoch(0).replace("  0  3\n", "  0  4\n", 1)
    text = rinex3_header(TYPES) + epoch + _epoch(1)
    path = _write(tmp_path, text)
    obs = read_obs(path)
    assert len(obs.problems) == 1
    assert f"{path}:{_line_of(text, '> 2024 06 24 08 20  0.0')}:" in obs.problems[0]
    assert "says 4 satellites but 3 lines follow" in obs.problems[0]
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
    assert any(f"{path}:{first_record + 2}: unreadable number" in p for p in nav.problems)
    assert any("incomplete record" in p for p in nav.problems)
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
