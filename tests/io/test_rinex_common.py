"""What every RINEX reader shares: plain, gzip and CRLF text, the header/body split and its
ASCII rule, the version record, epoch calendars, satellite number ranges and problem logging."""

from __future__ import annotations

import gzip
import logging
from pathlib import Path

import pytest

from vo_doppler.errors import InputError
from vo_doppler.io.rinex_common import (
    EXPANSION_RATIO,
    MAX_LOGGED_PROBLEMS,
    MIN_EXPANDED_LIMIT,
    add_problem,
    expanded_limit,
    parse_calendar,
    parse_version_line,
    prn_in_range,
    read_rinex_bytes,
    split_header,
)

VERSION = f"{'3.04':>9}{'':11}O{'':19}M{'':19}RINEX VERSION / TYPE"
END = f"{'':60}END OF HEADER"
TEXT = f"{VERSION}\n{'a comment':60}COMMENT\n{END}\n> 2024 06 24\nG05  1.0\n".encode()


def test_plain_gzip_and_crlf_files_give_the_same_text(tmp_path):
    plain, packed, crlf = tmp_path / "a.obs", tmp_path / "a.obs.gz", tmp_path / "b.obs"
    plain.write_bytes(TEXT)
    packed.write_bytes(gzip.compress(TEXT))
    crlf.write_bytes(TEXT.replace(b"\n", b"\r\n"))
    assert read_rinex_bytes(plain) == read_rinex_bytes(packed) == read_rinex_bytes(crlf) == TEXT


def test_a_gzip_stream_cut_short_keeps_its_whole_lines_when_problems_are_collected(tmp_path):
    path = tmp_path / "cut.obs.gz"
    path.write_bytes(gzip.compress(TEXT * 200)[:-30])
    with pytest.raises(InputError, match=r"cut\.obs\.gz: cannot decompress"):
        read_rinex_bytes(path)
    problems: list[str] = []
    text = read_rinex_bytes(path, problems)
    assert text.endswith(b"\n") and TEXT.startswith(text[: len(TEXT)])
    lines = text.count(b"\n")
    (problem,) = problems
    assert problem.startswith(f"{path}:{lines + 1}: gzip data damaged or cut short here")


def test_a_folder_is_refused(tmp_path):
    with pytest.raises(InputError, match="not a regular file"):
        read_rinex_bytes(tmp_path)


def test_the_expansion_cap_grows_with_the_compressed_size():
    assert expanded_limit(1000) == MIN_EXPANDED_LIMIT
    assert expanded_limit(10 << 20) == EXPANSION_RATIO * (10 << 20)


def test_header_and_body_are_split_and_non_ascii_bytes_refused_outside_free_text():
    header, body = split_header(Path("a.obs"), TEXT)
    assert [line[60:].strip() for line in header] == [
        "RINEX VERSION / TYPE",
        "COMMENT",
        "END OF HEADER",
    ]
    assert body == [b"> 2024 06 24", b"G05  1.0"]
    commented = TEXT.replace(b"a comment", "é comment".encode("latin-1"))
    assert split_header(Path("a.obs"), commented)[0][1].startswith("? comment")
    bad_body = TEXT.replace(b"G05  1.0", b"G05  1\xb70")
    with pytest.raises(InputError, match=r"a\.obs:5: byte 0xB7 in column 7 is not ASCII"):
        split_header(Path("a.obs"), bad_body)
    with pytest.raises(InputError, match="no 'END OF HEADER' record"):
        split_header(Path("a.obs"), TEXT.replace(b"END OF HEADER", b"END"))


def test_the_version_record_gives_version_type_and_system():
    assert parse_version_line(Path("a"), [VERSION], "O") == (3.04, "O", "M")
    nav = f"{'2.11':>9}{'':11}N{'':19}{'':20}RINEX VERSION / TYPE"
    assert parse_version_line(Path("a"), [nav], "N") == (2.11, "N", "G")  # blank: GPS
    with pytest.raises(InputError, match=r"type 'N' where 'O' is expected: .*navigation file "):
        parse_version_line(Path("a"), [nav], "O")
    with pytest.raises(InputError, match=r"unsupported RINEX version 5\.1"):
        parse_version_line(Path("a"), [VERSION.replace(" 3.04", " 5.10")], "O")
    with pytest.raises(InputError, match="first line is not a 'RINEX VERSION / TYPE' record"):
        parse_version_line(Path("a"), [END], "O")


def test_epoch_calendars():
    assert parse_calendar(b"2024 06 24 08 20 0.5000000") == (2024, 6, 24, 8, 20, 0.5)
    assert parse_calendar(b"24  2 29  0  0 60.0") == (2024, 2, 29, 0, 0, 60.0)  # leap second
    assert parse_calendar(b"85 1 1 0 0 0")[0] == 1985 and parse_calendar(b"79 1 1 0 0 0")[0] == 2079
    for text, words in [
        (b"2023 02 29 00 00 0", "day 29 of month 2"),
        (b"2024 13 01 00 00 0", "month 13"),
        (b"2024 01 01 24 00 0", "time 24:0:0"),
        (b"2024 01 01 00 00", "5 date fields instead of 6"),
        (b"2024 01 01.5 00 00 0", "not an integer"),
        (b"2024 01 01 00 00 nan", "not finite"),
        (b"1979 01 01 00 00 0", "year 1979 outside"),
    ]:
        with pytest.raises(ValueError, match=words):
            parse_calendar(text)


def test_satellite_numbers_per_system():
    assert prn_in_range("G", 32) and not prn_in_range("G", 33)
    assert prn_in_range("S", 20) and not prn_in_range("S", 19)
    assert prn_in_range("X", 99) and not prn_in_range("X", 0)


def test_problems_are_logged_one_by_one_then_only_counted(caplog):
    problems: list[str] = []
    with caplog.at_level(logging.WARNING):
        for line in range(MAX_LOGGED_PROBLEMS + 5):
            add_problem(problems, Path("a.obs"), line + 1, "skipped")
    assert problems[0] == "a.obs:1: skipped" and len(problems) == MAX_LOGGED_PROBLEMS + 5
    assert len(caplog.records) == MAX_LOGGED_PROBLEMS + 1
    assert (
        caplog.records[-1].getMessage() == "a.obs: more problems follow; only their count is logged"
    )
