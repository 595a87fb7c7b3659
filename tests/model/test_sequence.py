"""A recording's sensors: whether it has GNSS and a camera, and the span both vehicle signals
cover, and its vehicle signals as the heading stage takes them."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vo_doppler.geo import EnuFrame
from vo_doppler.model.camera import Camera
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.vehicle_source import VehicleSignalSource


def _sequence(yaw_t, wheel_t, **fields) -> Sequence:
    values = {
        "name": "s",
        "image_paths": [],
        "image_times": np.zeros(0),
        "camera": None,
        "observations": None,
        "navigation": None,
        "yaw_rate": SensorSeries(np.asarray(yaw_t, float), np.zeros(len(yaw_t))),
        "wheel_speed": SensorSeries(np.asarray(wheel_t, float), np.zeros(len(wheel_t))),
        "enu": EnuFrame(0.6, 2.4, 10.0),
    }
    return Sequence(**(values | fields))


def test_the_vehicle_span_is_where_both_signals_overlap():
    assert _sequence([0.0, 5.0, 10.0], [2.0, 12.0]).vehicle_span == (2.0, 10.0)
    assert _sequence([3.0, 4.0], [0.0, 9.0]).vehicle_span == (3.0, 4.0)
    assert _sequence([0.0, 1.0], [2.0, 3.0]).vehicle_span is None  # apart
    assert _sequence([0.0, 1.0], [1.0, 3.0]).vehicle_span == (1.0, 1.0)  # touching
    assert _sequence([], [0.0, 1.0]).vehicle_span is None


def test_gnss_needs_observations_and_navigation_and_a_camera_needs_images():
    bare = _sequence([0.0], [0.0])
    assert not bare.has_gnss and not bare.has_camera
    assert not _sequence([0.0], [0.0], observations=object()).has_gnss
    assert _sequence([0.0], [0.0], observations=object(), navigation=object()).has_gnss
    camera = Camera(500.0, 500.0, 320.0, 240.0)
    assert not _sequence([0.0], [0.0], camera=camera).has_camera  # no image
    assert _sequence([0.0], [0.0], camera=camera, image_paths=[Path("0.png")]).has_camera
    assert not _sequence([0.0], [0.0], image_paths=[Path("0.png")]).has_camera  # no calibration


def test_the_vehicle_signals_are_the_sequences_own_with_their_source():
    accelerometer = SensorSeries(np.array([0.0, 1.0]), np.array([0.1, -0.2]))
    source = VehicleSignalSource(sensor="CAN", yaw_rate="VEHICLE.YAW (vehicle.dbc)")
    sequence = _sequence(
        [0.0, 5.0], [2.0, 12.0], forward_acceleration=accelerometer, vehicle_source=source
    )
    signals = sequence.vehicle_signals
    assert signals.wheel_speed is sequence.wheel_speed and signals.yaw_rate is sequence.yaw_rate
    assert signals.forward_acceleration is accelerometer and signals.source is source
    assert _sequence([0.0], [0.0]).vehicle_signals.forward_acceleration is None
