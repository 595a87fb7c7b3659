"""Time messages name the likely cause and the option that fixes it, in plain numbers."""

from __future__ import annotations

import re

import numpy as np

from vo_doppler.errors import InputError
from vo_doppler.time_hints import (
    UNIX_OFFSET_S,
    frame_index_hint,
    offset_hint,
    overlap_error,
    overlaps,
    span,
)

NUMPY_REPR = re.compile(r"\[\s*-?\d[\d.e+]*\s*\]")


def test_a_unix_time_log_gets_the_gps_minus_unix_offset():
    gps_t0 = 1425953400.0
    unix_t0 = gps_t0 - UNIX_OFFSET_S
    hint = offset_hint(unix_t0, gps_t0, "--time-offset-can")
    assert "Unix time" in hint and "--time-offset-can -315964782" in hint
    assert UNIX_OFFSET_S == -315964782.0


def test_times_since_the_log_start_get_the_start_hint():
    assert "since the start of the log" in offset_hint(0.0, 1425953400.0, "--time-offset")


def test_frame_numbers_suggest_times():
    assert "--times" in frame_index_hint(np.arange(10.0))
    assert frame_index_hint(0.1 * np.arange(10.0)) == ""


def test_overlap_error_shows_plain_spans_without_numpy_brackets():
    t = np.array([1.74191818e09, 1.74191819e09])
    error = overlap_error("CAN", t, np.array([1.4e9, 1.4e9 + 10]), "--time-offset-can")
    text = str(error)
    assert isinstance(error, InputError)
    assert not NUMPY_REPR.search(text), text
    assert span(t) in text and "1741918180.000..1741918190.000 s" in text
    assert overlaps(np.array([0.0, 2.0]), np.array([1.0, 3.0]))
    assert not overlaps(np.array([0.0, 0.5]), np.array([1.0, 3.0]))


def test_overlap_error_without_samples_has_no_dangling_hint():
    text = str(overlap_error("CAN", np.array([]), np.array([1.4e9, 1.4e9 + 10]), "--time-offset"))
    assert text.endswith("GPS time)"), text
