"""The time span of ``--start`` / ``--end``: its two forms, its checks against the recording and
the trimming of every kind of input."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from vo_doppler.errors import InputError, UsageError
from vo_doppler.geo import EnuFrame
from vo_doppler.model.doppler_sigma import ReportedSigma
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.time_span import (
    GpsInterval,
    SpanBound,
    TimeSpan,
    reference_times,
    trim,
    trim_sequence,
)
from vo_doppler.model.trajectory import Trajectory

FIRST = 1_425_953_400.0


@pytest.mark.parametrize(
    ("text", "bound"),
    [
        ("30", SpanBound(30.0)),
        (" 0 ", SpanBound(0.0)),
        ("12.5", SpanBound(12.5)),
        ("gps:1425953430.5", SpanBound(1425953430.5, gps=True)),
        ("GPS:1e9", SpanBound(1e9, gps=True)),
    ],
)
def test_a_bound_is_seconds_from_the_first_epoch_or_a_gps_time(text, bound):
    assert SpanBound.parse(text) == bound


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("-1", "must be >= 0"),
        ("soon", "is not a time: expected seconds"),
        ("gps:", "is not a time"),
        ("inf", "is not a time"),
        ("utc:3", "is not a time"),
    ],
)
def test_other_bounds_are_refused(text, message):
    with pytest.raises(ValueError, match=message):
        SpanBound.parse(text)


def test_a_span_resolves_on_the_reference_times_both_ways():
    times = FIRST + np.arange(0.0, 20.01, 0.5)
    span = TimeSpan(SpanBound(2.0), SpanBound(FIRST + 7.0, gps=True))
    assert span.resolve(times, "GNSS epochs") == GpsInterval(FIRST + 2.0, FIRST + 7.0, FIRST)
    assert TimeSpan(SpanBound(3.0)).resolve(times, "x") == GpsInterval(
        FIRST + 3.0, FIRST + 20, FIRST
    )
    assert TimeSpan(end=SpanBound(3.0)).resolve(times, "x") == GpsInterval(
        FIRST, FIRST + 3.0, FIRST
    )
    assert TimeSpan().whole and not span.whole


@pytest.mark.parametrize(
    ("span", "message"),
    [
        (TimeSpan(SpanBound(21.0)), "--start 21 s lies outside the recording"),
        (TimeSpan(end=SpanBound(FIRST + 30, gps=True)), "--end gps:1425953430.000 lies outside"),
        (TimeSpan(SpanBound(FIRST - 1, gps=True)), "--start gps:1425953399.000 lies outside"),
        (TimeSpan(SpanBound(5.0), SpanBound(FIRST + 5, gps=True)), "is not before --end"),
        (TimeSpan(SpanBound(20.0)), "--start 20 s (gps:1425953420.000) is not before --end last"),
    ],
)
def test_a_span_outside_the_recording_is_a_usage_error(span, message):
    times = FIRST + np.arange(0.0, 20.01, 0.5)
    with pytest.raises(UsageError, match=message.replace("(", r"\(").replace(")", r"\)")) as info:
        span.resolve(times, "GNSS epochs")
    recording = (
        "the recording's GNSS epochs run from gps:1425953400.000 to gps:1425953420.000 (0 to "
        "20.000 s from the first epoch)"
    )
    assert recording in str(info.value)


def test_a_span_in_a_gap_holds_no_data():
    times = FIRST + np.array([0.0, 1.0, 9.0, 10.0])
    with pytest.raises(InputError, match="holds no GNSS epochs: choose --start / --end"):
        TimeSpan(SpanBound(2.0), SpanBound(8.0)).resolve(times, "GNSS epochs")


def test_the_problem_seen_before_reading_compares_bounds_of_one_kind():
    assert "is not before" in TimeSpan(SpanBound(5.0), SpanBound(5.0)).problem()
    assert TimeSpan(SpanBound(5.0), SpanBound(6.0)).problem() is None
    assert TimeSpan(SpanBound(50.0), SpanBound(6.0, gps=True)).problem() is None  # after reading


def test_trim_keeps_each_kind_of_input_inside_the_span_bounds_included():
    interval = GpsInterval(2.0, 4.0, 0.0)
    t = np.arange(0.0, 6.5, 0.5)
    series = trim(SensorSeries(t, t * 2, "speed", "m/s", 3), interval)
    assert series.t.tolist() == [2.0, 2.5, 3.0, 3.5, 4.0] and series.value[0] == 4.0
    assert (series.name, series.unit, series.n_skipped) == ("speed", "m/s", 3)
    path = Trajectory(t, np.column_stack([t, t, t]), Rotation.identity(len(t)))
    assert trim(path, interval).t.tolist() == series.t.tolist()
    sigma = ReportedSigma(t, np.full(len(t), "G05"), np.full(len(t), "D1C"), t / 10)
    assert trim(sigma, interval).sigma_mps.tolist() == pytest.approx([0.2, 0.25, 0.3, 0.35, 0.4])
    assert trim(None, interval) is None
    with pytest.raises(TypeError):
        trim(t, interval)


def _sequence(images: int = 11) -> Sequence:
    t = FIRST + np.arange(0.0, 10.01, 0.1)
    series = SensorSeries(t, np.ones(len(t)))
    return Sequence(
        name="s",
        image_paths=[Path(f"{i:03d}.png") for i in range(images)],
        image_times=FIRST + np.arange(images, dtype=float),
        camera=object(),  # the trimming does not look at it
        observations=None,
        navigation=None,
        yaw_rate=series,
        wheel_speed=series,
        enu=EnuFrame(0.6, 2.4, 0.0),
    )


def test_a_sequence_without_gnss_is_cut_on_its_image_times():
    sequence = _sequence()
    assert reference_times(sequence)[1] == "images"
    cut, interval = trim_sequence(sequence, TimeSpan(SpanBound(2.5), SpanBound(6.0)))
    assert interval == GpsInterval(FIRST + 2.5, FIRST + 6.0, FIRST)
    assert interval.to_dict()["start_from_first_epoch_s"] == 2.5
    assert [p.name for p in cut.image_paths] == ["003.png", "004.png", "005.png", "006.png"]
    assert cut.image_times.tolist() == (FIRST + np.arange(3.0, 7.0)).tolist()
    assert len(cut.yaw_rate) == len(cut.wheel_speed) == 36
    assert cut.truth is None and len(sequence.yaw_rate) == 101  # the recording is left as it was


def test_a_sequence_span_without_vehicle_samples_says_so():
    sequence = _sequence()
    few = SensorSeries(FIRST + np.array([0.0, 0.1]), np.ones(2))
    sequence.yaw_rate = sequence.wheel_speed = few
    with pytest.raises(InputError, match="holds no yaw-rate sample and no wheel-speed sample"):
        trim_sequence(sequence, TimeSpan(SpanBound(2.0)))
