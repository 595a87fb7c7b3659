"""``heading_from_gnss`` checks its vehicle signals as ``run`` does, on a simulated drive."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.errors import InputError
from vo_doppler.gnss.pipeline import gnss_velocity
from vo_doppler.heading.from_gnss import heading_from_gnss
from vo_doppler.heading.pipeline import HeadingPipelineConfig
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.vehicle_signals import VehicleSignals

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def drive(turning_drive_folder):
    """The 20-s simulated canyon drive with one left turn of 90°, its GNSS stage run."""
    sequence = read_sequence(turning_drive_folder)
    return sequence, gnss_velocity(sequence.observations, sequence.navigation, "GE")


def _heading(drive, yaw_rate: SensorSeries, **config):
    sequence, gnss = drive
    return heading_from_gnss(
        sequence.observations.epoch_time,
        gnss.rows,
        gnss.velocity,
        VehicleSignals(sequence.wheel_speed, yaw_rate),
        sequence.enu,
        HeadingPipelineConfig(**config),
    )


def test_a_yaw_rate_of_the_wrong_sign_is_refused_in_generic_words_without_a_source(drive):
    sequence, _ = drive
    assert _heading(drive, sequence.yaw_rate).warnings == []
    negated = SensorSeries(sequence.yaw_rate.t, -sequence.yaw_rate.value)
    with pytest.raises(InputError, match=r"^the yaw rate: wrong sign: .*; negate it: it must be"):
        _heading(drive, negated)


def test_a_calibrated_gyro_bias_beyond_a_car_sensor_is_in_the_table_warnings(drive, caplog):
    sequence, _ = drive
    off = SensorSeries(sequence.yaw_rate.t, sequence.yaw_rate.value + np.radians(5.0))
    table = _heading(drive, off)
    (warning,) = [w for w in table.warnings if w.startswith("gyro bias")]
    assert warning.startswith("gyro bias: the calibration gives +5.3") and warning in caplog.text
    # A gyro 5 °/s off turns by other amounts than the course: no turn confirms its sign,
    # and the table says so.
    assert any("its sign could not be checked" in w for w in table.warnings)
    fixed = _heading(drive, off, fixed_gyro_bias_rad_s=np.radians(5.0)).warnings
    assert not any(w.startswith("gyro bias") for w in fixed)  # chosen: no check
