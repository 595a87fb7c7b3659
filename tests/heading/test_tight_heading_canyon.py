"""The tight heading in a street canyon that starts before the calibration: two GPS satellites
per epoch after 20 s of the sample drive (``heading.from_gnss.emulated_canyon``), with
reflected satellites among them and the wheel scale and gyro bias still at their priors."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from vo_doppler.geo import wrap_angle
from vo_doppler.heading.from_gnss import emulated_canyon
from vo_doppler.io.sequence import read_sequence
from vo_doppler.run_stages import RunConfig, sequence_heading

pytestmark = pytest.mark.slow

SAMPLE = Path(__file__).resolve().parents[2] / "sample_sequences" / "urban_canyon_small"


def test_no_reliable_heading_is_far_outside_its_sigma():
    """A one-satellite window's heading (σ 16°) once confirmed two-satellite headings 88° off
    at σ 0.6° (one of the two satellites reflected, 16 m/s): those were reliable and locked the
    right headings out for 10 s. And the drive's first window (three GPS satellites, one
    reflected) gave a heading 64° off at σ 0.2° that nothing checked, which started every
    trajectory. Gross faults are what this guards against: no reliable
    heading 5σ off, and 95 % within 3σ."""
    sequence = read_sequence(SAMPLE)
    config = RunConfig()
    obs = sequence.observations
    after = obs.epoch_time[0] + 20.0
    rows, velocity = emulated_canyon(
        obs, sequence.navigation, 2, after, "G", config.elevation_mask_rad
    )
    table = sequence_heading(sequence, rows, velocity, config.heading)
    assert table.wheel_scale[-1] == 1.0  # no conventional heading calibrated anything
    error = np.abs(wrap_angle(table.yaw_tc - sequence.truth.yaw_at(table.t)))
    reliable = table.tc_reliable
    assert np.count_nonzero(reliable & (table.t >= after)) > 100
    normalised = error[reliable] / table.sigma_tc[reliable]
    assert np.max(normalised) < 5.0
    assert np.mean(normalised <= 3.0) > 0.95
    assert np.median(np.degrees(error[reliable])) < 1.0
