"""The blend's noise fit filters its grid in chunks by a byte budget: the likelihood of every
grid point does not depend on the budget (bit for bit), and the budget bounds the memory."""

from __future__ import annotations

import tracemalloc
from dataclasses import replace

import numpy as np
import pytest

from vo_doppler.fusion.heading_blend import (
    FIT_FLOATS_PER_MEASUREMENT,
    OUTLIER_GRID,
    SCALE_GRID,
    SIGMA_GRID,
    BlendConfig,
    DriftClock,
    OffsetMeasurements,
    fit_process_noise,
    grid_log_likelihood,
)

MIB = 2**20
N = 1000


@pytest.fixture(scope="module")
def walk():
    """A random walk in distance and turning seen through noisy headings (N measurements, all
    kept: no correlation time), on the fit's 2,560-point grid of σ_d, σ_ψ and s."""
    rng = np.random.default_rng(11)
    distance = np.arange(N, dtype=float)
    turn = np.cumsum(np.abs(rng.normal(0.0, 0.01, N)))
    t = distance / 10.0
    offset = np.cumsum(0.002 * rng.standard_normal(N) + 0.01 * np.sqrt(np.diff(turn, prepend=0)))
    measurements = OffsetMeasurements(
        t, offset + 0.02 * rng.standard_normal(N), np.full(N, 0.02), np.zeros(N)
    )
    clock = DriftClock(t, distance, turn)
    axes = (SIGMA_GRID, SIGMA_GRID, SCALE_GRID)
    grid = tuple(g.ravel() for g in np.meshgrid(*axes, indexing="ij"))
    return measurements, clock, grid


@pytest.mark.slow
def test_the_likelihood_of_every_grid_point_does_not_depend_on_the_chunks(walk):
    """Chunks of one point (on the first 100 measurements: a Python step per measurement and
    chunk), of a few points and of many give the side-by-side values bit for bit."""
    measurements, clock, grid = walk
    for keep, budgets in ((np.arange(100), (1,)), (np.arange(N), (8 * MIB, 32 * MIB))):
        whole = grid_log_likelihood(
            measurements, keep, clock, grid, OUTLIER_GRID, BlendConfig(fit_chunk_bytes=1 << 40)
        )
        assert whole.shape == (grid[0].size, OUTLIER_GRID.size)
        assert np.isfinite(whole).all() and np.ptp(whole) > 0
        for budget in budgets:
            chunked = grid_log_likelihood(
                measurements, keep, clock, grid, OUTLIER_GRID, BlendConfig(fit_chunk_bytes=budget)
            )
            assert np.array_equal(chunked, whole), budget


@pytest.mark.slow
def test_the_fit_is_the_same_and_its_memory_follows_the_budget(walk):
    """1,000 measurements × 2,560 points side by side hold about 117 MiB; in chunks of 8 MiB
    the fit's traced peak stays near the budget, and the chosen noise is the same."""
    measurements, clock, _ = walk
    config = BlendConfig(fit_chunk_bytes=8 * MIB, outlier_fraction=float(OUTLIER_GRID[1]))
    tracemalloc.start()
    try:
        chunked = fit_process_noise(measurements, clock, config)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    whole = fit_process_noise(measurements, clock, replace(config, fit_chunk_bytes=1 << 40))
    assert chunked == whole
    assert chunked.fitted
    assert peak < 8 * MIB + 8 * FIT_FLOATS_PER_MEASUREMENT * N + MIB


def test_one_filter_per_point_gives_the_likelihood_of_every_outlier_fraction(walk):
    """Each column (one ε) is, bit for bit, the grid filtered with that ε alone."""
    measurements, clock, grid = walk
    keep = np.arange(150)
    config = BlendConfig()
    every = grid_log_likelihood(measurements, keep, clock, grid, OUTLIER_GRID, config)
    for column, epsilon in enumerate(OUTLIER_GRID):
        alone = grid_log_likelihood(measurements, keep, clock, grid, np.array([epsilon]), config)
        assert np.array_equal(every[:, column], alone[:, 0])
    assert not np.array_equal(every[:, 0], every[:, 2])
