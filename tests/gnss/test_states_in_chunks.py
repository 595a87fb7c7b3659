"""Satellite states computed a chunk of rows at a time (issue 30: the GNSS stage's peak memory
grew with the drive's duration) are the states of one call, row for row."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vo_doppler.gnss import satellite_source
from vo_doppler.gnss.ephemeris import satellite_states
from vo_doppler.gnss.satellite_source import BroadcastSource
from vo_doppler.io.rinex_nav import read_nav

NAV = Path(__file__).resolve().parents[2] / "sample_sequences/urban_canyon_small/gnss/brdc.nav"


def test_chunked_states_are_those_of_one_call(monkeypatch):
    nav = read_nav(NAV)
    rng = np.random.default_rng(3)
    n = 1000
    system = rng.choice(np.array(["G", "E", "R"]), n)
    prn = rng.integers(1, 33, n)
    t = nav.kepler["toe"].min() + rng.uniform(0.0, 4 * 3600.0, n)
    whole = satellite_states(nav, system, prn, t)
    monkeypatch.setattr(satellite_source, "STATES_CHUNK", 97)
    chunked = BroadcastSource(nav).states(system, prn, t)
    assert whole.valid.any() and not whole.valid.all()
    for name in ("position", "velocity", "clock_bias_s", "clock_drift", "valid", "record"):
        np.testing.assert_array_equal(getattr(chunked, name), getattr(whole, name))
