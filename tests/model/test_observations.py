"""Columnar observations: satellite names, codes per system, row masks and subsets, one
observable as an epoch × satellite array, and the row keys used to join per-row tables."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vo_doppler.io.obs_rows import observations_from_rows
from vo_doppler.model.observations import lookup, row_keys

OBS = observations_from_rows(
    Path("x.obs"),
    "r",
    time=[1.0, 1.0, 1.0, 2.0, 2.0, 3.0],
    system=["G", "G", "E", "G", "R", "G"],
    prn=[5, 5, 11, 7, 3, 5],
    code=["C1C", "D1C", "D1C", "D1C", "D1C", "D1C"],
    value=[2.0e7, -100.0, 50.0, 20.0, 30.0, -90.0],
    row_fields={"flag": np.arange(6)},
)


def test_satellite_names_and_codes():
    assert len(OBS) == 6
    np.testing.assert_array_equal(OBS.satellites(), ["E11", "G05", "G05", "G07", "R03", "G05"])
    assert OBS.codes == ("C1C", "D1C")
    assert (OBS.code_index("D1C"), OBS.code_index("L1C")) == (1, -1)
    assert OBS.codes_of("G") == ["C1C", "D1C"] and OBS.codes_of("E") == ["D1C"]
    assert OBS.codes_of("C") == []


def test_epochs_only_keeps_header_codes_epochs_and_problems_and_no_row():
    noted = observations_from_rows(
        Path("x.obs"),
        "r",
        time=[1.0, 2.0],
        system=["G", "G"],
        prn=[5, 5],
        code=["D1C", "D1C"],
        value=[-100.0, -90.0],
        problems=("line 7: skipped",),
        row_fields={"flag": np.arange(2)},
    )
    bare = noted.epochs_only()
    assert len(bare) == 0 and bare.satellites().size == 0
    assert bare.header is noted.header and bare.codes == noted.codes
    assert bare.problems == ("line 7: skipped",)
    np.testing.assert_array_equal(bare.epoch_time, [1.0, 2.0])
    assert bare.row_fields["flag"].size == 0
    assert len(noted) == 2


def test_masks_and_subsets_keep_the_header_epochs_and_row_fields():
    # rows by time, system, satellite, code: E11, G05 C1C, G05 D1C, G07, R03, G05 at 3 s
    np.testing.assert_array_equal(OBS.mask("G", "D1C"), [False, False, True, True, False, True])
    np.testing.assert_array_equal(OBS.mask("G"), [False, True, True, True, False, True])
    gps_doppler = OBS.select("G", "D1C")
    np.testing.assert_array_equal(gps_doppler.value, [-100.0, 20.0, -90.0])
    np.testing.assert_array_equal(gps_doppler.row_fields["flag"], [1, 3, 5])
    # a subset keeps every epoch of the file, also those it has no row of
    np.testing.assert_array_equal(OBS.select("E").epoch_time, [1.0, 2.0, 3.0])
    assert gps_doppler.header is OBS.header and gps_doppler.codes == OBS.codes
    assert OBS.mask(code="L1C").sum() == 0
    assert len(OBS.select()) == 6


def test_one_observable_as_epochs_by_satellites():
    names, values = OBS.matrix("D1C", "G")
    np.testing.assert_array_equal(names, ["G05", "G07"])
    np.testing.assert_array_equal(values, [[-100.0, np.nan], [np.nan, 20.0], [-90.0, np.nan]])
    names, values = OBS.matrix("D1C")
    np.testing.assert_array_equal(names, ["E11", "G05", "G07", "R03"])
    assert values.shape == (3, 4) and np.isfinite(values).sum() == 5


def test_row_keys_join_rows_of_the_same_epoch_satellite_and_code():
    epochs = np.array([1.0, 2.0])
    mine = row_keys(epochs, [1.0, 2.0, 2.0], np.array(["G", "G", "E"]), [5, 5, 5], [0, 0, 0])
    wanted = row_keys(
        epochs, [2.0, 2.0, 1.0, 1.0], np.array(["E", "G", "G", "G"]), [5, 5, 5, 5], [0, 0, 0, 1]
    )
    assert len(set(mine.tolist())) == 3
    np.testing.assert_array_equal(
        lookup(mine, np.array([10.0, 20.0, 30.0]), wanted), [30.0, 20.0, 10.0, np.nan]
    )
    assert np.isnan(lookup(mine[:0], np.zeros(0), wanted)).all()
