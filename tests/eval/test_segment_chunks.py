"""The KITTI segment errors computed a chunk of start frames at a time: the same figures as
one pass, in memory bounded by the chunk (issue 30: 35 MiB for 40,000 poses
at once)."""

from __future__ import annotations

import tracemalloc

import numpy as np
from scipy.spatial.transform import Rotation

import vo_doppler.eval.metrics as metrics
from vo_doppler.model.trajectory import Trajectory


def wandering(n: int, seed: int) -> Trajectory:
    rng = np.random.default_rng(seed)
    yaw = np.cumsum(rng.normal(0.0, 0.02, n))
    steps = np.column_stack([np.cos(yaw), np.sin(yaw), rng.normal(0.0, 0.01, n)])
    return Trajectory(
        np.arange(n) * 0.1, np.cumsum(steps, axis=0), Rotation.from_euler("z", yaw[:, None])
    )


def test_chunks_give_the_figures_of_one_pass(monkeypatch):
    truth, estimate = wandering(3001, 1), wandering(3001, 2)
    lengths = (100.0, 400.0, 2900.0, 5000.0)
    monkeypatch.setattr(metrics, "SEGMENT_CHUNK", 10**6)
    whole = metrics.segment_errors(estimate, truth, lengths)
    monkeypatch.setattr(metrics, "SEGMENT_CHUNK", 7)
    chunked = metrics.segment_errors(estimate, truth, lengths)
    assert [s.length_m for s in whole] == [100.0, 400.0, 2900.0]  # 5000 m does not fit
    assert chunked == whole  # bit for bit
    assert whole[0].count == 3001 - 100 and whole[0].translation_pct > 0.0


def test_the_memory_is_that_of_a_chunk_not_of_the_path():
    truth, estimate = wandering(40_000, 3), wandering(40_000, 4)
    tracemalloc.start()
    try:
        metrics.segment_errors(estimate, truth, (100.0,))
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak < 8 * 2**20  # 34.6 MiB when every start frame was done at once
