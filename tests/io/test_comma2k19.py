"""comma2k19 layout readers on synthetic segment folders (extensionless numpy arrays)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.io.comma2k19 import RAW_GNSS, gps_minus_log, gps_minus_mono

WEEK_S = 604800.0


def _save(base: Path, parts: tuple[str, ...], array: np.ndarray) -> None:
    path = base.joinpath(*parts)
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("wb") as handle:  # np.save on a handle keeps the name without ".npy"
        np.save(handle, array)


def _segment(base: Path, log_t: np.ndarray, tow: np.ndarray, pose_offset_s: float) -> Path:
    raw = np.zeros((log_t.size, 10))
    raw[:, 0], raw[:, 1], raw[:, 2] = 5, 2012, tow
    _save(base, (*RAW_GNSS, "t"), log_t)
    _save(base, (*RAW_GNSS, "value"), raw)
    frame_t = np.linspace(log_t[0], log_t[-1], 7)
    gps = np.column_stack([np.full(7, 2012.0), frame_t + pose_offset_s - 2012 * WEEK_S])
    _save(base, ("global_pose", "frame_times"), frame_t)
    _save(base, ("global_pose", "frame_gps_times"), gps)
    return base


def test_log_clock_offset_from_the_receiver_time_tags(tmp_path):
    """GPS − log time from raw_gnss_ublox's (week, time of week) against its ``t``; the pose's
    own offset is read separately (on the example segment the two differ by 0.126 s)."""
    log_t = 46408.5 + 0.1 * np.arange(20)
    offset = 2012 * WEEK_S + 357697.75
    base = _segment(tmp_path, log_t, log_t + offset - 2012 * WEEK_S, offset + 0.125)
    assert gps_minus_log(base) == pytest.approx(offset, abs=1e-6)
    assert gps_minus_mono(base) == pytest.approx(offset + 0.125, abs=1e-6)


def test_varying_offset_is_an_input_error(tmp_path):
    log_t = 46408.5 + 0.1 * np.arange(20)
    tow = log_t + 357697.75
    tow[10:] += 0.01  # a 10 ms jump: log times that are arrival times, not one clock offset
    base = _segment(tmp_path, log_t, tow, 357697.75)
    with pytest.raises(InputError, match="raw_gnss_ublox"):
        gps_minus_log(base)
