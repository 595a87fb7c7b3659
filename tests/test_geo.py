"""Geodetic/ECEF/ENU transforms and yaw/course conversions."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.geo import (
    EnuFrame,
    course_to_yaw,
    ecef_to_geodetic,
    geodetic_to_ecef,
    yaw_to_course,
)


def test_known_ecef_point():
    np.testing.assert_allclose(geodetic_to_ecef(0.0, 0.0, 0.0), [6378137.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(
        geodetic_to_ecef(np.pi / 2, 0.0, 0.0), [0.0, 0.0, 6356752.314245], atol=1e-5
    )


@settings(max_examples=50, deadline=None)
@given(
    st.floats(-1.5, 1.5),
    st.floats(-3.1, 3.1),
    st.floats(-100, 5000),
    st.floats(-5e3, 5e3),
    st.floats(-5e3, 5e3),
    st.floats(-50, 50),
)
def test_enu_round_trip(lat, lon, h, e, n, u):
    frame = EnuFrame(lat, lon, h)
    ecef = frame.enu_to_ecef(np.array([e, n, u]))
    np.testing.assert_allclose(frame.ecef_to_enu(ecef), [e, n, u], atol=1e-6)
    lat2, lon2, h2 = ecef_to_geodetic(frame.origin_ecef)
    np.testing.assert_allclose([lat2, lon2, h2], [lat, lon, h], atol=1e-6)


def test_enu_axes_point_east_north_up():
    frame = EnuFrame(0.0, 0.0, 0.0)
    east = frame.ecef_to_enu(frame.origin_ecef + np.array([0.0, 1.0, 0.0]))
    north = frame.ecef_to_enu(frame.origin_ecef + np.array([0.0, 0.0, 1.0]))
    np.testing.assert_allclose(east, [1, 0, 0], atol=1e-9)
    np.testing.assert_allclose(north, [0, 1, 0], atol=1e-9)


@settings(max_examples=100, deadline=None)
@given(st.floats(-np.pi, np.pi - 1e-9))
def test_yaw_course_round_trip(yaw):
    np.testing.assert_allclose(np.exp(1j * course_to_yaw(yaw_to_course(yaw))), np.exp(1j * yaw))


def test_yaw_course_convention():
    assert np.isclose(yaw_to_course(0.0), np.pi / 2)  # facing east = course 90°
    assert np.isclose(yaw_to_course(np.pi / 2), 0.0)  # facing north = course 0°
    assert np.isclose(course_to_yaw(np.pi), -np.pi / 2)  # course 180° = facing south


def test_ecef_to_geodetic_gives_pymap3ds_bits():
    import pymap3d

    rng = np.random.default_rng(1)
    directions = rng.normal(size=(500, 3))
    points = directions / np.linalg.norm(directions, axis=1)[:, None]
    points *= rng.uniform(6.3e6, 6.5e6, size=(500, 1))
    edges = np.array([[0.0, 0.0, 6356752.3], [0.0, 0.0, -6356752.3], [0.0, 0.0, 0.0], [1e3, 20, 5]])
    for ecef in (points, points[0], points[:1], np.vstack([points[:5], edges]), *edges):
        expected = pymap3d.ecef2geodetic(ecef[..., 0], ecef[..., 1], ecef[..., 2], deg=False)
        for got, want in zip(ecef_to_geodetic(ecef), expected, strict=True):
            assert np.shape(got) == np.shape(want)
            assert np.array_equal(got, want)
