"""GPS thinning, interpolation and step lengths ([KZ] Eq. 10–14): exact cases."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from vo_doppler.errors import InputError
from vo_doppler.geo import EARTH_MEAN_RADIUS_M
from vo_doppler.lowcost.gps_reconstruction import (
    equirectangular_distance,
    haversine_distance,
    reconstruct_track,
    select_fixes,
    step_lengths,
)

M_PER_RAD = EARTH_MEAN_RADIUS_M


def _east_line(metres):
    """Latitudes/longitudes on the equator at the given east offsets (m)."""
    metres = np.asarray(metres, dtype=float)
    return np.zeros_like(metres), metres / M_PER_RAD


def test_distances_one_degree_of_latitude_and_agreement():
    one_degree = np.radians(1.0)
    assert equirectangular_distance(0.0, 0.0, one_degree, 0.0) == pytest.approx(
        M_PER_RAD * one_degree
    )
    assert haversine_distance(0.0, 0.0, one_degree, 0.0) == pytest.approx(M_PER_RAD * one_degree)
    lat = np.radians(35.0)
    d_eq = equirectangular_distance(lat, 0.0, lat + 1e-5, 1e-5)
    d_hv = haversine_distance(lat, 0.0, lat + 1e-5, 1e-5)
    assert d_eq == pytest.approx(d_hv, rel=1e-6)
    with pytest.raises(ValueError):
        step_lengths(np.zeros(2), np.zeros(2), "vincenty")


def test_select_fixes_every_mth_and_cluster():
    lat, lon = _east_line([0, 1, 2, 3.5, 4, 10, 11, 11.5, 12, 20])
    np.testing.assert_array_equal(select_fixes(lat, lon, 1, 3.0), [0, 3, 5, 9])
    np.testing.assert_array_equal(select_fixes(lat, lon, 2, 3.0), [0, 4, 6, 9])
    np.testing.assert_array_equal(select_fixes(lat, lon, 1, 3.0, np.array([1])), [0, 1, 4, 5, 9])
    np.testing.assert_array_equal(select_fixes(lat, lon, 1, 0.0), np.arange(10))


def test_reconstruction_interpolates_linearly_between_kept_fixes():
    t = np.arange(5.0)
    lat, lon = _east_line([0, 1, 10, 2, 20])
    track = reconstruct_track(t, lat, lon, downsample=2, cluster_m=3.0)
    np.testing.assert_array_equal(track.kept, [0, 2, 4])
    east = track.lon * M_PER_RAD
    np.testing.assert_allclose(east, [0, 5, 10, 15, 20], atol=1e-9)
    np.testing.assert_allclose(track.step_lengths(), 5.0, rtol=1e-9)
    with pytest.raises(InputError, match="strictly increasing"):
        reconstruct_track(np.array([0.0, 0.0]), lat[:2], lon[:2])


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(-50, 50), min_size=1, max_size=40),
    st.integers(1, 5),
    st.floats(0.0, 10.0),
)
def test_reconstruction_returns_one_point_per_original_time(offsets, m, cluster):
    t = np.cumsum(np.ones(len(offsets)))
    lat = np.radians(10.0) + np.asarray(offsets) / M_PER_RAD
    lon = np.radians(179.9999) + np.cumsum(offsets) / M_PER_RAD
    track = reconstruct_track(t, lat, lon, m, cluster)
    assert len(track.t) == len(t) and np.all(track.t == t)
    assert track.kept[0] == 0 and track.kept[-1] == len(t) - 1
    assert np.all(np.diff(track.kept) > 0)
    np.testing.assert_allclose(track.lat[track.kept], lat[track.kept], atol=1e-12)
    assert np.all(np.isfinite(track.lat)) and np.all(np.abs(track.lon) <= np.pi)
