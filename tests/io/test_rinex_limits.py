"""Opening RINEX files: compression within limits, encoding, every failure an InputError naming
the file (never zlib.error, HatanakaException, UnicodeDecodeError or MemoryError)."""

from __future__ import annotations

import gzip
import re
import resource

import hatanaka
import ncompress
import numpy as np
import pytest

from tests.helpers.rinex_text import field, rinex3_epoch, rinex3_header
from vo_doppler.errors import InputError
from vo_doppler.io.rinex_common import expanded_limit, parse_calendar, read_rinex_bytes
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs

TYPES = {"G": ["C1C", "D1C"], "E": ["C1C", "D1C"]}


def _text(n_epochs: int = 3) -> str:
    text = rinex3_header(TYPES)
    for k in range(n_epochs):
        records = [(s, [field(2.0e7 + k), field(-1000.0 - k)]) for s in ("G05", "G07", "E11")]
        text += rinex3_epoch(f"2024 06 24 08 {20 + k // 60:2d} {k % 60:2d}.0000000", records)
    return text


def test_gzip_unix_compress_and_hatanaka_read_the_same(tmp_path):
    plain = _text().encode()
    expected = read_obs(_write(tmp_path, "plain.24o", plain))
    for name, data in [
        ("a.24o.gz", gzip.compress(plain)),
        ("a.24o.Z", ncompress.compress(plain)),
        ("a.crx", hatanaka.rnx2crx(plain)),
        ("a.crx.gz", gzip.compress(hatanaka.rnx2crx(plain))),
    ]:
        obs = read_obs(_write(tmp_path, name, data))
        np.testing.assert_array_equal(obs.value, expected.value, err_msg=name)
        np.testing.assert_array_equal(obs.epoch_time, expected.epoch_time, err_msg=name)


def _write(tmp_path, name: str, data: bytes):
    path = tmp_path / name
    path.write_bytes(data)
    return path


@pytest.mark.parametrize(
    ("name", "data", "message"),
    [
        ("cut.24o.gz", gzip.compress(_text().encode(), mtime=0)[:14], "cannot decompress"),
        (
            "flip.24o.gz",
            gzip.compress(_text().encode(), mtime=0)[:12] + b"\xff" * 40,
            "cannot decompress",
        ),
        ("cut.crx", hatanaka.rnx2crx(_text().encode())[:-25], "cannot decompress"),
        ("bad.crx", b"1.0                 COMPACT RINEX FORMAT\ngarbage\n", "cannot decompress"),
        ("bad.Z", b"\x1f\x9d\x90garbage", "cannot decompress"),
    ],
)
def test_corrupt_compressed_files_are_input_errors(tmp_path, name, data, message):
    path = _write(tmp_path, name, data)
    with pytest.raises(InputError, match=message) as error:
        read_obs(path)
    assert str(path) in str(error.value)


@pytest.mark.parametrize("damage", ["cut", "flipped"])
def test_a_damaged_gzip_keeps_the_epochs_before_the_damage(tmp_path, damage):
    """As for a truncated plain file (QA report: a truncated .obs.gz was rejected whole): the
    complete lines decoded before the damage are read, and a problem names the first line
    lost; the navigation reader does the same."""
    plain = _text(400).encode()
    packed = gzip.compress(plain, compresslevel=1)
    middle = len(packed) // 2
    if damage == "cut":
        packed = packed[:middle]
    else:
        packed = packed[:middle] + bytes(b ^ 0x5A for b in packed[middle : middle + 64])
    obs = read_obs(_write(tmp_path, "damaged.24o.gz", packed))
    full = read_obs(_write(tmp_path, "plain.24o", plain))
    n = obs.epoch_time.size
    assert 50 < n < 400
    np.testing.assert_array_equal(obs.epoch_time, full.epoch_time[:n])
    np.testing.assert_array_equal(obs.value[: len(obs) - 6], full.value[: len(obs) - 6])
    (lost,) = [p for p in obs.problems if "gzip data damaged or cut short here" in p]
    where = re.match(rf"{re.escape(str(tmp_path))}/damaged.24o.gz:(\d+): .*: the (\d+) lines", lost)
    assert where is not None and int(where[1]) == int(where[2]) + 1
    if damage == "cut":  # flipped bytes may inflate to wrong text before deflate fails
        assert plain.startswith(read_rinex_bytes(tmp_path / "damaged.24o.gz", []))


def test_a_damaged_gzip_without_a_problem_list_is_still_an_error(tmp_path):
    packed = gzip.compress(_text(400).encode())
    path = _write(tmp_path, "cut.24o.gz", packed[: len(packed) // 2])
    with pytest.raises(InputError, match="cannot decompress"):
        read_rinex_bytes(path)


def test_gzip_bomb_is_refused_without_filling_memory(tmp_path):
    """40 MB of zeros compress to 40 kB: more than 40x, refused after 16 MiB are expanded."""
    path = _write(tmp_path, "bomb.24o.gz", gzip.compress(b"0" * 40_000_000, compresslevel=9))
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(InputError, match="decompressed data exceed 16 MiB") as error:
        read_obs(path)
    assert str(path) in str(error.value)
    grown_mb = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
    assert grown_mb < 100


def test_expanded_limit():
    assert expanded_limit(1000) == 16 << 20
    assert expanded_limit(10 << 20) == 400 << 20
    assert expanded_limit(1 << 30) == 1 << 30


def test_latin1_byte_in_the_body_names_line_and_column(tmp_path):
    text = _text().encode()
    lines = text.split(b"\n")
    number = next(i for i, line in enumerate(lines) if line.startswith(b"G07")) + 1
    lines[number - 1] = lines[number - 1][:5] + b"\xe9" + lines[number - 1][6:]
    path = _write(tmp_path, "latin1.24o", b"\n".join(lines))
    with pytest.raises(InputError, match="byte 0xE9 in column 6 is not ASCII") as error:
        read_obs(path)
    assert error.value.line == number
    assert str(path) in str(error.value)


def test_latin1_byte_in_a_comment_is_replaced(tmp_path):
    comment = "Zürich".encode("latin-1").ljust(60) + b"COMMENT".ljust(20) + b"\n"
    text = _text().encode().replace(b"\n", b"\n" + comment, 1)
    obs = read_obs(_write(tmp_path, "comment.24o", text))
    assert obs.problems == ()
    assert obs.epoch_time.size == 3


def test_latin1_byte_in_a_header_value_is_refused(tmp_path):
    text = _text().encode().replace(b"     1.000", b"     1.\xb00", 1)
    path = _write(tmp_path, "interval.24o", text)
    with pytest.raises(InputError, match="0xB0") as error:
        read_obs(path)
    assert (
        error.value.line
        == text.split(b"\n").index(next(line for line in text.split(b"\n") if b"\xb0" in line)) + 1
    )


def test_nav_decompression_errors_name_the_file(tmp_path):
    path = _write(tmp_path, "brdc.nav.gz", b"\x1f\x8b\x08\x00garbage")
    with pytest.raises(InputError, match="cannot decompress") as error:
        read_nav(path)
    assert str(path) in str(error.value)


def test_missing_file_is_an_input_error(tmp_path):
    with pytest.raises(InputError, match="cannot read file"):
        read_rinex_bytes(tmp_path / "absent.24o")


@pytest.mark.parametrize("path", ["/dev/zero", "/tmp"])
def test_device_or_folder_is_not_read(path):
    with pytest.raises(InputError, match="not a regular file"):
        read_obs(path)


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        (b"2024 13 24 08 20  0.0", "month 13"),
        (b"2024 02 30 08 20  0.0", "day 30 of month 2"),
        (b"2024 06 24 25 20  0.0", "time 25:20:0"),
        (b"2024 06 24 08 60  0.0", "time 8:60:0"),
        (b"2024 06 24 08 20 61.0", "time 8:20:61"),
        (b"2024 06 24 08 20  nan", "not finite"),
        (b"inf 06 24 08 20  0.0", "not finite"),
        (b"2024 06.5 24 08 20 0.0", "not an integer"),
        (b"2024 06 24 08 20", "5 date fields"),
        (b"1e30 06 24 08 20 0.0", "year"),
        (b"2024 06 2x 08 20 0.0", "not a number"),
    ],
)
def test_parse_calendar_refuses_impossible_dates(text, reason):
    with pytest.raises(ValueError, match=reason):
        parse_calendar(text)


def test_parse_calendar_reads_two_digit_years_and_leap_days():
    assert parse_calendar(b"10  1  6  5 57  3.0000000") == (2010, 1, 6, 5, 57, 3.0)
    assert parse_calendar(b"99 12 31 23 59 60.5") == (1999, 12, 31, 23, 59, 60.5)
    assert parse_calendar(b"2024 02 29 00 00 00") == (2024, 2, 29, 0, 0, 0.0)
