"""Simulator visibility: exact ray-box cases, facade reflections, and a narrow street that
leaves fewer than four satellites."""

from __future__ import annotations

import numpy as np
import pytest

from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.sim.gnss_observations import Boxes, facade_reflections, ray_hits
from vo_doppler.sim.scene import Building
from vo_doppler.sim.urban_canyon import CityConfig, UrbanCanyonConfig, simulate_urban_canyon

ANTENNA = np.array([0.0, 0.0, 1.6])


def direction(azimuth_deg: float, elevation_deg: float) -> np.ndarray:
    az, el = np.radians(azimuth_deg), np.radians(elevation_deg)
    return np.array([np.cos(el) * np.sin(az), np.cos(el) * np.cos(az), np.sin(el)])


def east_building() -> Boxes:
    """One 30-m building from x = 10 to 20 m, long in y."""
    return Boxes.from_buildings([Building(10.0, -50.0, 20.0, 50.0, 30.0)])


def test_satellite_behind_building_is_blocked_and_above_roofline_is_seen():
    boxes = east_building()
    roofline = np.degrees(np.arctan((30.0 - 1.6) / 10.0))
    cases = {
        (90.0, 30.0): True,
        (90.0, roofline - 0.01): True,
        (90.0, roofline + 0.01): False,
        (90.0, 80.0): False,
        (270.0, 10.0): False,  # other side of the street: open
        (0.0, 5.0): False,  # along the street
    }
    rays = np.array([direction(*key) for key in cases])
    hits = ray_hits(np.tile(ANTENNA, (len(rays), 1)), rays, boxes)
    np.testing.assert_array_equal(hits.hit, list(cases.values()))
    blocked = hits.hit
    assert np.all(hits.axis[blocked] == 0)  # the west facade (x = 10) is hit first
    expected = 10.0 / rays[blocked, 0]
    np.testing.assert_allclose(hits.distance[blocked], expected, rtol=1e-12)


def test_ray_test_is_vectorised_over_many_boxes():
    rng = np.random.default_rng(1)
    lo = rng.uniform(-100, 100, (50, 3)) * [1, 1, 0]
    boxes = Boxes(lo, lo + rng.uniform(5, 30, (50, 3)))
    origins = rng.uniform(-100, 100, (300, 3)) * [1, 1, 0] + [0, 0, 1.0]
    rays = np.array([direction(a, e) for a, e in rng.uniform([0, 1], [360, 89], (300, 2))])
    together = ray_hits(origins, rays, boxes)
    for k in range(0, 300, 37):
        single = [
            ray_hits(
                origins[k : k + 1], rays[k : k + 1], Boxes(boxes.lo[m : m + 1], boxes.hi[m : m + 1])
            )
            for m in range(50)
        ]
        distances = [s.distance[0] for s in single]
        assert together.hit[k] == any(s.hit[0] for s in single)
        assert together.distance[k] == pytest.approx(min(distances))


def test_facade_reflection_extra_path_and_rate():
    """Street between facades at x = ±5 m (40 m high): a satellite in the west at 70° is
    blocked, its reflection on the east facade arrives; extra path 2·d·|u_x|."""
    boxes = Boxes.from_buildings(
        [Building(5.0, -100.0, 15.0, 100.0, 40.0), Building(-15.0, -100.0, -5.0, 100.0, 40.0)]
    )
    u = direction(270.0, 70.0)
    velocity = np.array([[2.0, 0.0, 0.0]])
    assert ray_hits(ANTENNA[None], u[None], boxes).hit[0]
    bounce = facade_reflections(ANTENNA[None], u[None], velocity, boxes)
    assert bounce.found[0]
    u_x = np.cos(np.radians(70.0))
    assert bounce.excess_m[0] == pytest.approx(2 * 5.0 * u_x, rel=1e-9)
    assert bounce.excess_rate_mps[0] == pytest.approx(-2 * 2.0 * u_x, rel=1e-9)
    moved = facade_reflections(ANTENNA[None] + velocity * 0.1, u[None], velocity, boxes)
    assert (moved.excess_m[0] - bounce.excess_m[0]) / 0.1 == pytest.approx(
        bounce.excess_rate_mps[0], rel=1e-6
    )
    matte = np.zeros((2, 2), dtype=bool)
    assert not facade_reflections(ANTENNA[None], u[None], velocity, boxes, matte).found[0]
    glass_east = matte.copy()
    glass_east[0, 0] = True  # only the east building's x-facing facades reflect
    assert facade_reflections(ANTENNA[None], u[None], velocity, boxes, glass_east).found[0]
    low = direction(270.0, 30.0)  # reflected path blocked again by the west building
    assert not facade_reflections(ANTENNA[None], low[None], velocity, boxes).found[0]


@pytest.mark.slow
def test_narrow_street_leaves_fewer_than_four_satellites(tmp_path):
    config = UrbanCanyonConfig(
        duration_s=20.0,
        seed=1,
        render=False,
        city=CityConfig(street_width_m=14.0, height_range_m=(25.0, 60.0)),
    )
    sim = simulate_urban_canyon(tmp_path, config)
    obs = read_obs(tmp_path / "gnss" / "rover.obs")
    doppler = obs.select(code="D1C")
    per_epoch = np.bincount(
        np.searchsorted(obs.epoch_time, doppler.time), minlength=obs.epoch_time.size
    )
    np.testing.assert_array_equal(per_epoch, sim.gnss.n_visible)
    low = per_epoch < 4
    assert low.sum() >= 40  # at least 2 s of epochs
    assert sim.stats.longest_lt4_s >= 2.0
    assert np.all(sim.gnss.n_above_mask >= 8)  # open sky would give plenty
