"""Time messages name the likely cause and the option that fixes it, in plain numbers."""

from __future__ import annotations

import re

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.time_hints import (
    FRAME_NUMBER_FIX,
    UNIX_OFFSET_S,
    TimeBase,
    coverage,
    epochs_offset_fix,
    looks_like_frame_numbers,
    offset_hint,
    overlap_error,
    overlaps,
    span,
    time_base_check,
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


def test_frame_numbers_are_told_by_their_steps_whatever_the_origin():
    frames = np.arange(801.0)
    assert looks_like_frame_numbers(frames) and looks_like_frame_numbers(frames + 1e9 + 0.3)
    assert not looks_like_frame_numbers(0.1 * frames)  # a 10-Hz camera
    assert not looks_like_frame_numbers(np.array([0.0, 1.0]))  # two times say nothing
    assert not looks_like_frame_numbers(np.r_[frames, 800.5])


def test_coverage_is_the_share_of_the_times_inside_the_epochs():
    t = np.arange(801.0)
    assert coverage(t, np.arange(0.0, 80.01, 0.2)) == pytest.approx(0.1, abs=1e-12)
    assert coverage(t, np.array([-5.0, 900.0])) == 1.0
    assert coverage(t, np.array([900.0, 901.0])) == 0.0
    assert coverage(np.array([3.0]), np.array([0.0, 5.0])) == 1.0


def test_frame_numbers_half_covered_by_headings_on_image_time_are_an_error_naming_times():
    """Issue 30: KITTI poses read without --times (0..800) against headings on image time
    (0..80 s): they overlap, yet only frame numbers 0..80 would get a heading."""
    verdict = time_base_check(
        np.arange(801.0), np.arange(0.0, 80.01, 0.2), "trajectory", "heading epochs", "--x"
    )
    assert verdict.warning is None and verdict.coverage == pytest.approx(0.1)
    assert verdict.error == (
        "the trajectory times (0.000..800.000 s) and the heading epochs (0.000..80.000 s, GPS "
        "time) meet over 10% of the trajectory: the trajectory times step by exactly 1 s: they "
        "are frame numbers, not seconds; " + FRAME_NUMBER_FIX
    )
    assert "--times" in FRAME_NUMBER_FIX


def test_frame_numbers_the_epochs_cover_are_joined_with_a_warning():
    verdict = time_base_check(np.arange(81.0), np.arange(0.0, 80.01, 0.2), "a", "b", "--x")
    assert verdict.error is None and verdict.coverage == 1.0
    assert verdict.warning.startswith("the a times step by exactly 1 s, as frame numbers do")
    assert verdict.warning.endswith(FRAME_NUMBER_FIX)


@pytest.mark.parametrize(
    ("last_epoch", "error", "warning"),
    [(1.0, "meet over 1.0% of the trajectory only", None), (30.0, None, "meet over 30%")],
)
def test_little_coverage_is_an_error_some_a_warning_naming_the_offset_option(
    last_epoch, error, warning
):
    t = 0.1 * np.arange(1001)  # a 10-Hz camera, 100 s
    verdict = time_base_check(t, np.arange(0.0, last_epoch + 0.01, 0.2), "trajectory", "e", "--o")
    for message, expected in ((verdict.error, error), (verdict.warning, warning)):
        if expected is None:
            assert message is None
        else:
            assert expected in message and "pass --o" in message


def test_times_the_epochs_cover_mostly_pass_and_disjoint_ones_are_an_error():
    t = 0.1 * np.arange(1001)
    assert time_base_check(t, np.arange(-1.0, 60.0, 0.2), "t", "e", "--o") == TimeBase(
        pytest.approx(0.598, abs=1e-12)
    )
    disjoint = time_base_check(t + 1e9, np.arange(0.0, 60.0, 0.2), "t", "e", "--o")
    assert disjoint.coverage == 0.0 and "do not overlap" in disjoint.error
    assert "pass --o" in disjoint.error


def test_epochs_on_another_clock_name_the_offset_to_add_to_them():
    """``run --heading FILE``: the file is on the wrong clock, not the recording; the fix given
    instead of an option's adds the recording's start to the file's times."""
    recording = np.array([1425953404.1, 1425953412.0])
    epochs = np.arange(0.0, 8.0, 0.1)
    fix = epochs_offset_fix(recording, epochs)
    assert fix.endswith(
        "add the GPS time of its first row to each (about 1425953404 s if it "
        "starts with the recording)"
    )
    verdict = time_base_check(
        recording, epochs, "recording", "heading epochs", "--o", offset_fix=fix
    )
    assert verdict.error.endswith(f"do not overlap; {fix}") and "--o" not in verdict.error
    part = time_base_check(
        recording, epochs + recording[0] - 5.0, "recording", "e", "--o", offset_fix=fix
    )
    assert part.warning.endswith(f"if the two clocks differ, {fix}")
