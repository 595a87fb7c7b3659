"""Moving vehicles: their boxes follow their lanes, are drawn where their trajectory projects,
keep their gaps and stay clear of the camera car."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from vo_doppler.model.camera import Camera
from vo_doppler.sim.camera_effects import CameraEffects, EffectsCamera
from vo_doppler.sim.render import project_points
from vo_doppler.sim.scene import CityLayout, Plane, Scene, procedural_texture
from vo_doppler.sim.traffic import FACES, TrafficConfig, Vehicle, add_traffic, displacement

LAYOUT = CityLayout(blocks_x=2, blocks_y=2, block_size=(40.0, 40.0), street_width=20.0)


def _ground_scene() -> Scene:
    texture = procedural_texture(256, np.random.default_rng(0))
    ground = Plane(
        origin=np.array([-200.0, -200.0, 0.0]),
        u_axis=np.array([1.0, 0.0, 0.0]),
        v_axis=np.array([0.0, 1.0, 0.0]),
        width=500.0,
        height=500.0,
        texture=0,
        texel_size=0.05,
    )
    return Scene([ground], [texture], layout=LAYOUT)


def test_vehicle_moves_along_its_lane_and_wraps():
    vehicle = Vehicle((-50.0, -5.0), (1.0, 0.0), 200.0, 20.0, 10.0, (4.4, 1.8, 1.5), 0, (0, 0), 1)
    t = np.array([0.0, 1.5, 17.0, 20.0])
    np.testing.assert_allclose(vehicle.centre(t)[:, 0], [-30.0, -15.0, -50.0 + 190.0, -30.0])
    np.testing.assert_allclose(vehicle.centre(t)[:, 1], -5.0)
    for time in t:
        np.testing.assert_allclose(
            displacement([vehicle], time)[0], vehicle.centre(np.array([time]))[0] - (-30.0, -5.0)
        )


def test_box_faces_point_outward_and_enclose_the_centre():
    vehicle = Vehicle((0.0, 0.0), (0.0, 1.0), 300.0, 10.0, 8.0, (4.4, 1.8, 1.5), 0, (0, 0), 1)
    planes = vehicle.planes(2.0)
    assert len(planes) == FACES
    centre = np.array([0.0, 26.0, 0.75])
    for plane in planes[:4]:
        middle = plane.point(plane.width / 2, plane.height / 2)
        assert (middle - centre) @ plane.normal > 0
    sides = sorted(round(p.width, 6) for p in planes[:4])
    assert sides == [1.8, 1.8, 4.4, 4.4]
    assert planes[4].origin[2] == pytest.approx(1.5) and planes[4].normal[2] == pytest.approx(1.0)


def test_drawn_where_its_trajectory_projects():
    """A car crossing in front of a still camera: at each time, the pixel where its side's
    centre projects shows one of its planes, and where it was 0.8 s before shows the ground."""
    scene = _ground_scene()
    car = Vehicle((-100.0, 12.0), (1.0, 0.0), 400.0, 98.0, 8.0, (4.4, 1.8, 1.5), 0, (0, 0), 1)
    camera = Camera(300.0, 300.0, 159.5, 89.5, 320, 180)
    still = CameraEffects(
        distortion=(0.0,) * 5,
        distortion_error=(0.0,) * 5,
        readout_s=0.0,
        exposure_s=0.0,
        sensor=None,
    )
    effects = EffectsCamera(scene, camera, camera, still, np.zeros(1), 0, [car])
    T = np.eye(4)
    T[:3, :3] = np.column_stack([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
    T[:3, 3] = (0.0, 0.0, 1.5)
    renderer = effects.bands[0][3]
    for t in (0.0, 0.4, 0.8):
        tables = effects.traffic_tables(t, T[:3, 3])
        result = renderer.with_moving(tables).render_full(T)
        side = car.centre(np.array([t]))[0] - (0.0, 0.9)
        pixel = project_points(renderer.camera, T, np.array([[side[0], side[1], 0.75]]))[0]
        u, v = np.round(pixel).astype(int)
        assert result.plane_index[v, u] >= len(scene.planes), t
        earlier = car.centre(np.array([t - 0.8]))[0] - (0.0, 0.9)
        pixel = project_points(renderer.camera, T, np.array([[earlier[0], earlier[1], 0.75]]))[0]
        if 0 <= pixel[0] < renderer.camera.width:
            u, v = np.round(pixel).astype(int)
            assert result.plane_index[v, u] < len(scene.planes), t


def test_lanes_keep_their_gaps_and_the_camera_car_clear():
    scene = _ground_scene()
    config = TrafficConfig(vehicles_per_km=60.0, clearance_m=4.0)
    ego_t = np.arange(0.0, 60.0, 0.1)
    ego_xy = np.column_stack([-20.0 + 8.0 * ego_t, np.full(len(ego_t), -5.0)])
    vehicles = add_traffic(scene, config, np.random.default_rng(2), ego_t, ego_xy)
    assert len(vehicles) > 20
    assert len(scene.textures) == 1 + config.textures
    for vehicle in vehicles:
        distance = np.linalg.norm(vehicle.centre(ego_t) - ego_xy, axis=1)
        assert distance.min() > vehicle.size[0] / 2 + config.clearance_m
    lanes: dict[tuple, list[Vehicle]] = {}
    for vehicle in vehicles:
        lanes.setdefault((vehicle.start, vehicle.direction), []).append(vehicle)
    for members in lanes.values():
        assert len({v.speed for v in members}) == 1
        ordered = sorted(members, key=lambda v: v.s0)
        for a, b in itertools.pairwise(ordered):
            assert b.s0 - a.s0 >= (a.size[0] + b.size[0]) / 2 + config.min_gap_m - 1e-9
    again = add_traffic(_ground_scene(), config, np.random.default_rng(2), ego_t, ego_xy)
    assert again == vehicles
