"""Every observable, LLI and signal-strength value of the shared RINEX files equals georinex's.

georinex (test-only dependency) is slow — 42 s for the whole Septentrio file (301 epochs of six
systems, 3.5 MB) on an idle core — so each file is read once per test session, and the
Septentrio file at georinex's ``interval`` of 4 s: 76 epochs spread over the whole file (12 s),
every observable of every system, compared with the same epochs of our reading of the whole
file.
"""

from __future__ import annotations

import warnings
from dataclasses import replace

import numpy as np
import pytest

from tests.conftest import require_shared
from tests.helpers.rinex_text import field, rinex2_epoch, rinex2_header
from vo_doppler.io.rinex_obs import read_obs

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("georinex")]

FILES = {"septentrio_static/rover.obs": 4.0, "yamatogawa_ublox_walk/yamatogawa_rover.obs": None}
"""Each file and the interval (s) georinex reads it at: None for every epoch."""


@pytest.fixture(scope="session", params=list(FILES))
def both_readers(request):
    georinex = pytest.importorskip("georinex")
    path = require_shared(request.param)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = georinex.load(path, useindicators=True, interval=FILES[request.param])
    obs = read_obs(path)
    if FILES[request.param] is not None:
        times = _gps_seconds(reference.time.values)
        assert times.size > 0.2 * obs.epoch_time.size
        read = np.isin(np.round(obs.epoch_time, 6), np.round(times, 6))
        obs = replace(
            obs.subset(np.isin(np.round(obs.time, 6), np.round(times, 6))),
            epoch_time=obs.epoch_time[read],
            epoch_flag=obs.epoch_flag[read],
        )
    return obs, reference


def _gps_seconds(times: np.ndarray) -> np.ndarray:
    return (times - np.datetime64("1980-01-06T00:00:00")) / np.timedelta64(1, "ns") * 1e-9


def _ours_as_grid(obs, code, attribute, reference):
    """Our values of one observable on georinex's (time, sv) grid; NaN where we have none."""
    times = _gps_seconds(reference.time.values)
    svs = [str(s) for s in reference.sv.values]
    grid = np.full((times.size, len(svs)), np.nan)
    rows = obs.mask(code=code)
    sat = obs.satellites()[rows]
    t_index = np.searchsorted(times, obs.time[rows])
    assert np.all(np.abs(times[t_index] - obs.time[rows]) < 1e-6)
    sv_index = np.array([svs.index(s) for s in sat])
    values = getattr(obs, attribute)[rows].astype(float)
    if attribute != "value":
        values[values < 0] = np.nan
    grid[t_index, sv_index] = values
    return grid


@pytest.mark.shared_data
def test_same_epochs_and_satellites(both_readers):
    obs, reference = both_readers
    np.testing.assert_allclose(obs.epoch_time, _gps_seconds(reference.time.values), atol=1e-6)
    assert set(np.unique(obs.satellites())) <= {str(s) for s in reference.sv.values}
    assert obs.problems == ()


@pytest.mark.shared_data
def test_every_observable_equal(both_readers):
    obs, reference = both_readers
    compared = 0
    for name in reference.data_vars:
        name = str(name)
        code, attribute = name, "value"
        if name.endswith(("lli", "ssi")):
            code, attribute = name[:-3], name[-3:]
        ours = _ours_as_grid(obs, code, attribute, reference)
        theirs = reference[name].values
        np.testing.assert_array_equal(ours, theirs, err_msg=name)
        compared += int(np.isfinite(theirs).sum())
    assert compared > 1000
    assert np.isfinite(obs.value).all()


def _assert_equal_to_georinex(path) -> int:
    georinex = pytest.importorskip("georinex")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        reference = georinex.load(path, useindicators=True)
    obs = read_obs(path)
    compared = 0
    for name in reference.data_vars:
        name = str(name)
        if name.endswith(("lli", "ssi")):
            continue
        ours = _ours_as_grid(obs, name, "value", reference)
        theirs = reference[name].values
        np.testing.assert_array_equal(ours, theirs, err_msg=name)
        compared += int(np.isfinite(theirs).sum())
    return compared


def test_truncated_last_rinex2_record_kept_as_far_as_it_goes(tmp_path):
    """Seven observables take two lines a satellite; the file ends after the first line of the
    last satellite: its five values are kept, as georinex keeps them."""
    types = ["C1", "L1", "D1", "S1", "P2", "L2", "D2"]
    records = [(f"G{k:2d}", [field(2.0e7 + k + j) for j in range(len(types))]) for k in range(1, 5)]
    text = rinex2_header(types) + rinex2_epoch(" 10  1  6  5 57  3.0000000", records)
    path = tmp_path / "cut.10o"
    path.write_text(text[: text.rstrip("\n").rfind("\n") + 1])
    obs = read_obs(path)
    assert obs.value[obs.satellites() == "G04"].tolist() == [2.0e7 + 4 + j for j in range(5)]
    assert _assert_equal_to_georinex(path) == 3 * 7 + 5


@pytest.mark.shared_data
def test_real_rinex2_file_cut_inside_a_line_equals_georinex(tmp_path):
    """The yamatogawa file cut 32 characters into its last line (after two whole fields)."""
    source = require_shared("yamatogawa_ublox_walk/yamatogawa_rover.obs").read_bytes()
    cut = source.rstrip(b"\n")
    cut = cut[: cut.rfind(b"\n") + 1 + 32]
    path = tmp_path / "cut.10o"
    path.write_bytes(cut)
    full = read_obs(require_shared("yamatogawa_ublox_walk/yamatogawa_rover.obs"))
    obs = read_obs(path)
    assert len(obs) == len(full) - 2
    assert _assert_equal_to_georinex(path) == len(obs)
