"""Reading a text input safely: a bounded regular file, not binary, UTF-8, bounded lines; every
failure an InputError naming the file and, for encoding and line length, the line."""

from __future__ import annotations

import os

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.errors import InputError
from vo_doppler.io.textfile import (
    MIB,
    binary_kind,
    check_line_lengths,
    decode_text,
    read_bytes,
    read_text,
    regular_file,
    text_lines,
)


def test_a_text_file_is_read_as_utf8_without_its_bom(tmp_path):
    path = tmp_path / "a.txt"
    path.write_bytes("\ufeffx,y\n1,é\n".encode())
    assert regular_file(path, "the table") == path.stat().st_size
    assert read_text(path, "the table") == "x,y\n1,é\n"
    assert read_bytes(path, "the table") == path.read_bytes()


def test_a_folder_a_device_and_a_missing_file_are_refused_by_name(tmp_path):
    (tmp_path / "a.txt").mkdir()
    with pytest.raises(InputError, match=r"a\.txt: the table is a folder$") as folder:
        regular_file(tmp_path / "a.txt", "the table")
    assert folder.value.path == tmp_path / "a.txt"
    if os.path.exists("/dev/zero"):
        with pytest.raises(InputError, match=r"^/dev/zero: the log is not a regular file$"):
            read_text("/dev/zero", "the log")
    with pytest.raises(InputError, match=r"nope\.txt: cannot read the table: No such file"):
        read_text(tmp_path / "nope.txt", "the table")


def test_a_file_beyond_the_bound_is_refused_with_its_size(tmp_path):
    path = tmp_path / "big.txt"
    path.write_bytes(b"a" * (MIB + 1))
    with pytest.raises(InputError, match=rf"the log is {MIB + 1} bytes, more than the 1 MiB"):
        read_bytes(path, "the log", max_bytes=MIB)
    assert len(read_bytes(path, "the log", max_bytes=2 * MIB)) == MIB + 1


@pytest.mark.parametrize(
    ("head", "kind"),
    [
        (b"\x89PNG\r\n\x1a\n....", "PNG image"),
        (b"\xff\xd8\xff\xe0", "JPEG image"),
        (b"%PDF-1.7", "PDF document"),
        (b"\x1f\x8b\x08", "gzip archive"),
        (b"PK\x03\x04", "zip archive"),
        (b"\x93NUMPY\x01", "numpy array"),
        (b"text then a \0 byte", "binary file (NUL bytes)"),
        (b"plain,text\n1,2\n", None),
    ],
)
def test_binary_formats_are_named_by_their_first_bytes(head, kind):
    assert binary_kind(head) == kind


def test_binary_content_is_refused_naming_its_format(tmp_path):
    with pytest.raises(InputError, match=r"^f\.csv: the table is a gzip archive, not a text file$"):
        decode_text(b"\x1f\x8b\x08\x00", "f.csv", "the table")


def test_a_byte_that_is_not_utf8_names_its_line_and_value():
    data = b"first\nsecond\nthird \xe9 line\n"
    with pytest.raises(InputError, match=r"^f\.csv:3: the table is not UTF-8 text \(byte 0xE9\)"):
        decode_text(data, "f.csv", "the table")


def test_the_first_line_too_long_is_named_with_its_length():
    data = b"short\n" + b"x" * 12 + b"\nok\n" + b"y" * 20
    with pytest.raises(InputError, match=r"^f:2: the log line has 12 bytes, more than 10$"):
        check_line_lengths(data, "f", "the log", max_line=10)
    check_line_lengths(b"0123456789\n0123456789", "f", "the log", max_line=10)  # at the bound
    with pytest.raises(InputError, match=r"^f:1: the log line has 11 bytes"):
        decode_text(b"0123456789A\n" * 3, "f", "the log", max_line=10)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.sampled_from(["1.5 2", "", " ", "#c", "\n", "\r", "\r\n", "\x0b", "\x85", "\u2028"]),
        max_size=40,
    ).map("".join),
    st.integers(min_value=0, max_value=9),
)
def test_lines_split_in_pieces_are_those_of_splitlines(text, piece_chars):
    assert list(text_lines(text, piece_chars)) == text.splitlines()
