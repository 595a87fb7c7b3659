"""The tight heading's windows solved in chunks by a byte budget: the headings do not depend on
the budget (bit for bit), and the budget bounds the transient memory."""

from __future__ import annotations

import tracemalloc
from dataclasses import replace

import numpy as np
import pytest

from vo_doppler.gnss.pipeline import gnss_velocity
from vo_doppler.heading import pipeline as heading_pipeline
from vo_doppler.heading.from_gnss import heading_from_gnss
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.heading.tight_heading import (
    TightHeadingConfig,
    tight_heading_series,
    windows_per_chunk,
)
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.run import RunConfig
from vo_doppler.sim.gnss_observations import GnssSimConfig
from vo_doppler.sim.urban_canyon import UrbanCanyonConfig, simulate_urban_canyon

MIB = 2**20


@pytest.fixture(scope="module")
def heading_inputs(tmp_path_factory):
    """A 12 s drive, GNSS at 20 Hz with facade reflections (so that data snooping rejects rows);
    few tiny images (only the GNSS and CAN are used)."""
    folder = tmp_path_factory.mktemp("chunks") / "drive"
    gnss = GnssSimConfig(nlos=True)
    config = UrbanCanyonConfig(duration_s=12.0, seed=7, fps=1.0, image_size_px=(64, 36), gnss=gnss)
    simulate_urban_canyon(folder, config)
    sequence = read_sequence(folder)
    run = RunConfig()
    obs = sequence.observations
    gnss = gnss_velocity(obs, sequence.navigation, run.systems, run.elevation_mask_rad)
    return (
        obs.epoch_time,
        gnss.rows,
        gnss.velocity,
        VehicleSignals(sequence.wheel_speed, sequence.yaw_rate),
        sequence.enu,
    ), sequence.antenna_lever_arm_m


def heading(inputs, chunk_bytes: int):
    args, lever = inputs
    config = HeadingPipelineConfig(tight=TightHeadingConfig(chunk_bytes=chunk_bytes))
    return heading_from_gnss(*args, config, lever)


@pytest.mark.slow
def test_chunking_does_not_change_the_headings(heading_inputs):
    whole = heading(heading_inputs, 1 << 40)
    assert np.count_nonzero(whole.rejected_rows) > 0, "the drive should exercise data snooping"
    assert np.count_nonzero(whole.tc_available) > len(whole) / 2
    for budget in (4 * MIB, MIB):
        chunked = heading(heading_inputs, budget)
        for name in ("yaw_tc", "sigma_tc", "tc_reliable", "tc_verifiable", "rejected_rows"):
            np.testing.assert_array_equal(getattr(chunked, name), getattr(whole, name), name)


def test_budget_sets_the_chunk_size():
    config = TightHeadingConfig(chunk_bytes=32 * MIB)
    per_window = 32 * MIB // windows_per_chunk(174, 10, config)
    assert 80_000 < per_window < 100_000  # ≈ 8 B × (52·174 + 2·10·72 + 8·121)
    assert windows_per_chunk(174, 10, replace(config, chunk_bytes=1)) == 1
    assert windows_per_chunk(87, 10, config) > windows_per_chunk(174, 10, config)


@pytest.fixture(scope="module")
def series_inputs(heading_inputs):
    """The arguments the heading stage passes to ``tight_heading_series`` on the drive."""
    calls = []

    def spy(*args, **kwargs):
        calls.append((args, kwargs))
        return tight_heading_series(*args, **kwargs)

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(heading_pipeline, "tight_heading_series", spy)
        heading(heading_inputs, 32 * MIB)
    assert 1 <= len(calls) <= 2  # a second pass where the tight headings calibrate the gyro
    return calls[-1]


def peak_bytes(inputs, chunk_bytes: int) -> int:
    """tracemalloc's peak (numpy's arrays included) of the tight heading with a budget."""
    args, kwargs = inputs
    kwargs = {**kwargs, "config": replace(kwargs["config"], chunk_bytes=chunk_bytes)}
    tracemalloc.start()
    try:
        tight_heading_series(*args, **kwargs)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.slow
def test_budget_bounds_the_transient_memory(series_inputs):
    """The peak above the floor of small chunks stays within the budget, and all windows at
    once need several times more (so the budget is what bounds it)."""
    floor = peak_bytes(series_inputs, MIB)
    budget = 4 * MIB
    assert peak_bytes(series_inputs, budget) - floor <= budget
    assert peak_bytes(series_inputs, 1 << 40) - floor > 2 * budget
