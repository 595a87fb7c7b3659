"""The map's view spans every finite position of the tracks drawn and evaluated, found track
by track (issue 30: 34 MiB for a 30-min drive's tracks stacked)."""

from __future__ import annotations

import re
import tracemalloc

import numpy as np
from scipy.spatial.transform import Rotation

from vo_doppler.geo import EnuFrame, geodetic_to_ecef
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report.trajectory_map import map_html

ENU = EnuFrame.from_ecef(geodetic_to_ecef(np.radians(35.0), np.radians(139.0), 10.0))


def track(positions) -> Trajectory:
    positions = np.asarray(positions, dtype=float)
    return Trajectory(np.arange(len(positions)), positions, Rotation.identity(len(positions)))


def view_box(page: str) -> list[float]:
    return [float(v) for v in re.search(r"viewBox='([^']+)'", page).group(1).split()]


def test_the_view_spans_the_finite_positions_of_every_track():
    truth = track([[0, 0, 0], [100, 50, 0], [np.nan, 900, 0]])  # a NaN row is left out
    vo = track([[-20, 10, 0], [40, -30, 0]])
    lost = track([[np.nan, np.nan, 0], [np.inf, 1, 0]])  # no finite position at all
    moved = track([[0, 0, 0], [130, 20, 0]])
    page = map_html({"truth": truth, "vo": vo, "dr": lost}, {}, ENU, {"vo": moved})
    margin = 0.05 * 150.0  # 5 % of the larger side, east -20..130
    expected = [-20 - margin, -50 - margin, 150 + 2 * margin, 80 + 2 * margin]
    np.testing.assert_allclose(view_box(page), expected, atol=0.006)
    none = map_html({"dr": lost}, {}, ENU)
    assert none == "<p>No trajectory to draw (no finite position).</p>"


def test_the_memory_does_not_hold_every_track_stacked():
    rng = np.random.default_rng(0)
    tracks = {"truth": track(np.cumsum(rng.normal(size=(200_000, 3)), axis=0))}
    tracks |= {f"p{k}": track(np.cumsum(rng.normal(size=(40_000, 3)), axis=0)) for k in range(6)}
    tracemalloc.start()
    try:
        map_html(tracks, {}, ENU, tracks)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 8 * 2**20  # 34.4 MiB with the tracks stacked
