"""Observations from flat rows: NaN values dropped, rows sorted by time, system, satellite and
code, repeats dropped (the first kept) and counted, per-row fields kept with their rows, and the
header the formats without one get."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.io.obs_rows import observations_from_rows

PATH = Path("log.csv")


def _observations(**extra):
    return observations_from_rows(
        PATH,
        "a phone",
        time=[2.0, 1.0, 1.0, 1.0, 2.0, 1.0, 1.0],
        system=["G", "G", "E", "G", "G", "G", "G"],
        prn=[5, 7, 3, 5, 5, 5, 5],
        code=["D1C", "C1C", "D5Q", "D1C", "D1C", "C1C", "D1C"],
        value=[1.0, 2.0, 3.0, 4.0, 5.0, np.nan, 6.0],
        lli=[0, 0, 1, 0, 0, 0, 1],
        glonass_channels={4: -2},
        problems=("reader: one",),
        n_lines=40,
        **extra,
    )


def test_rows_are_sorted_and_repeats_dropped_keeping_the_first():
    obs = _observations(row_fields={"label": np.array(list("abcdefg"))})
    codes = np.array(obs.codes)[obs.code]
    got = list(zip(obs.time, obs.system, obs.prn, codes, obs.value, strict=True))
    assert got == [
        (1.0, "E", 3, "D5Q", 3.0),
        (1.0, "G", 5, "D1C", 4.0),  # the later (1.0, G05, D1C) row 6.0 is a repeat
        (1.0, "G", 7, "C1C", 2.0),
        (2.0, "G", 5, "D1C", 1.0),  # and so is (2.0, G05, D1C) 5.0
    ]
    np.testing.assert_array_equal(obs.lli, [1, 0, 0, 0])
    np.testing.assert_array_equal(obs.ssi, -1)
    np.testing.assert_array_equal(obs.row_fields["label"], ["c", "d", "b", "a"])
    np.testing.assert_array_equal(obs.epoch_time, [1.0, 2.0])
    np.testing.assert_array_equal(obs.epoch_flag, [0, 0])
    assert obs.problems == (
        "reader: one",
        "log.csv: 2 repeated observations (same epoch, satellite and signal) dropped, the "
        "first kept",
    )


def test_the_header_lists_each_systems_codes():
    header = _observations().header
    assert header.obs_types == {"E": ("D5Q",), "G": ("C1C", "D1C")}
    assert header.receiver_type == "a phone" and header.glonass_channels == {4: -2}
    assert (header.time_system, header.n_lines, header.path) == ("GPS", 40, PATH)


def test_without_lli_every_row_has_none_and_a_non_finite_time_is_refused():
    obs = observations_from_rows(PATH, "r", [1.0], ["G"], [1], ["D1C"], [0.5])
    np.testing.assert_array_equal(obs.lli, [-1])
    assert obs.problems == ()
    with pytest.raises(InputError, match=r"^log\.csv: non-finite epoch time$"):
        observations_from_rows(PATH, "r", [np.nan], ["G"], [1], ["D1C"], [0.5])
