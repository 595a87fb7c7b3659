"""Doppler rows formed a block of observations at a time (issue 30: the GNSS stage's peak
memory grew with the drive's duration) are the rows formed at once, row for row, with the same
counts and messages."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from vo_doppler.gnss import doppler_velocity
from vo_doppler.gnss.doppler_velocity import doppler_rows
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs

SAMPLE = Path(__file__).resolve().parents[2] / "sample_sequences/urban_canyon_small/gnss"


def test_rows_formed_in_blocks_are_those_formed_at_once(monkeypatch):
    obs, nav = read_obs(SAMPLE / "rover.obs"), read_nav(SAMPLE / "brdc.nav")
    receiver = np.tile(obs.header.approx_position, (obs.epoch_time.size, 1))
    receiver[::7] = np.nan  # epochs without a position: their observations form no row
    whole = doppler_rows(obs, nav, receiver, elevation_mask_rad=np.radians(25.0))
    monkeypatch.setattr(doppler_velocity, "ROWS_CHUNK", 101)
    blocks = doppler_rows(obs, nav, receiver, elevation_mask_rad=np.radians(25.0))
    assert len(whole) > 10 * 101 and whole.n_below_mask > 0
    for field in dataclasses.fields(whole):
        mine, theirs = getattr(blocks, field.name), getattr(whole, field.name)
        if isinstance(theirs, np.ndarray):
            np.testing.assert_array_equal(mine, theirs, err_msg=field.name)
            assert not mine.flags.writeable
        else:
            assert mine == theirs, field.name
