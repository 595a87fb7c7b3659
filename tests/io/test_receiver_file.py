"""Observation files recognised by content: each format's signature, RINEX read through the one
entry, and anything else refused with its first line and the formats the toolkit reads."""

from __future__ import annotations

import numpy as np
import pytest

from tests.helpers.rinex_text import field, rinex3_epoch, rinex3_header
from vo_doppler.errors import InputError
from vo_doppler.io.receiver_file import (
    READABLE,
    read_observation_file,
    sniff_format,
    unknown_format_message,
)


@pytest.mark.parametrize(
    ("head", "kind"),
    [
        (b"junk\xb5\x62\x02\x15\x00\x00", "ubx"),
        (b"MessageType,utcTimeMillis,ArrivalTimeNanosSinceGpsEpoch,Svid\n", "gsdc"),
        (b"# Header\n# Raw,utcTimeMillis,TimeNanos\nRaw,1,2\n", "gnsslogger"),
        (b"# Header\nRaw,1,2\n", "gnsslogger"),
        (b"GPSWeek [weeks];x (doMes);y (gnssId);NLOS (1 == no, 0 == yes)\n", "smartloc"),
        (b"     3.04           OBSERVATION DATA    M   RINEX VERSION / TYPE\n", "rinex"),
        (b"\x1f\x8b\x08\x00compressed", "rinex"),
        (b"BZh91AY&SY", "rinex"),
    ],
)
def test_each_format_is_recognised_by_its_first_bytes(tmp_path, head, kind):
    path = tmp_path / "f"
    path.write_bytes(head)
    assert sniff_format(path) == kind


def test_a_sync_in_text_is_not_ubx(tmp_path):
    path = tmp_path / "f.txt"
    path.write_bytes(b"     3.04  \xb5\x62 OBSERVATION DATA    RINEX VERSION / TYPE\n")
    assert sniff_format(path) == "rinex"  # no NUL byte: text, not a binary UBX log


def test_anything_else_is_refused_with_its_first_line_and_the_readable_formats(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_bytes(b"time,lat,lon\n1,2,3\n")
    with pytest.raises(InputError) as refused:
        sniff_format(path)
    message = str(refused.value)
    assert message.startswith(
        f"{path}: not a GNSS observation file of a format this toolkit reads "
        "(first line 'time,lat,lon'). Readable: RINEX 2/3/4 observations"
    )
    assert all(name in message and command in message for name, command in READABLE)
    long = unknown_format_message(b"x" * 80 + b"\nrest")
    assert "(first line '" + "x" * 60 + "…')" in long
    with pytest.raises(InputError, match="cannot read"):
        sniff_format(tmp_path / "missing.obs")


def test_a_rinex_file_is_read_through_the_one_entry(tmp_path):
    path = tmp_path / "r.obs"
    text = rinex3_header({"G": ["C1C", "D1C"]})
    text += rinex3_epoch("2024 06 24 08 20  0.0000000", [("G05", [field(2.1e7), field(-1234.5)])])
    path.write_text(text)
    observations, navigation = read_observation_file(path)
    assert navigation is None
    codes = np.array(observations.codes)[observations.code]
    assert sorted(zip(codes, observations.value, strict=True)) == [
        ("C1C", 2.1e7),
        ("D1C", -1234.5),
    ]
