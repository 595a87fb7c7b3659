"""Moving vehicles: boxes that drive the city's lanes independently of the camera car.

Every street line of the grid has two lanes, a quarter of the street width either side of the
centre line, driven on the right: along x the eastbound lane is south of the line, along y the
northbound lane is east of it. Each lane has its own speed, shared by all its vehicles (so they
never run into each other), and its vehicles are spread along it with random gaps. A lane runs
``margin_m`` beyond the city at both ends and its vehicles wrap around, so the traffic is
periodic with the lane's length divided by its speed.

A vehicle at lane position s (metres from the lane's start, mod its length) is centred at
``start + s·direction`` and heads along ``direction``. It is drawn as a box (four sides and a
roof) of its own size and texture. Vehicles that would come within ``clearance_m`` of the
camera car at any of the given times are left out (the simulated traffic does not react to it:
no braking, no collisions), so a drive is never rendered from inside another vehicle.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from vo_doppler.sim.scene import SUN_DIRECTION, CityLayout, Plane, Scene, procedural_texture

VEHICLE_TYPES = {
    "car": ((4.4, 1.8, 1.5), 0.75),
    "van": ((5.4, 2.0, 2.2), 0.18),
    "bus": ((11.0, 2.5, 3.1), 0.07),
}
"""Length, width, height (m) and share of each kind of vehicle."""
FACES = 5
"""Planes per vehicle (:meth:`Vehicle.planes`): four sides, then the roof."""


@dataclass(frozen=True)
class TrafficConfig:
    """Vehicles per kilometre of lane (0: no traffic), lane speeds, and the clearance kept from
    the camera car."""

    vehicles_per_km: float = 20.0
    speed_range_mps: tuple[float, float] = (5.0, 12.0)
    min_gap_m: float = 8.0
    margin_m: float = 120.0
    clearance_m: float = 4.0
    textures: int = 4
    texel_m: float = 0.02


@dataclass(frozen=True)
class Vehicle:
    """One moving box: lane start point (x, y), unit direction, lane length (wrap period),
    position at t = 0 along the lane, speed, size (length, width, height), texture, per-face
    texture offset and brightness."""

    start: tuple[float, float]
    direction: tuple[float, float]
    lane_length: float
    s0: float
    speed: float
    size: tuple[float, float, float]
    texture: int
    offset: tuple[float, float]
    gain: float

    def centre(self, t: np.ndarray) -> np.ndarray:
        """Ground centre (N, 2) of the box at times t (s)."""
        s = np.mod(self.s0 + self.speed * np.asarray(t, dtype=float), self.lane_length)
        return np.asarray(self.start) + s[:, None] * np.asarray(self.direction)

    def planes(self, t: float) -> list[Plane]:
        """Sides (outward normals) and roof of the box at time t."""
        (cx, cy), (dx, dy) = self.centre(np.array([t]))[0], self.direction
        length, width, height = self.size
        forward = np.array([dx, dy]) * length / 2.0
        left = np.array([-dy, dx]) * width / 2.0
        centre = np.array([cx, cy])
        # Counter-clockwise seen from above, so u × z points outward.
        ring = [centre - forward - left, centre + forward - left]
        ring += [centre + forward + left, centre - forward + left]
        planes = []
        for k in range(4):
            p0, p1 = ring[k], ring[(k + 1) % 4]
            along = p1 - p0
            side = float(np.linalg.norm(along))
            u_axis = np.array([along[0], along[1], 0.0]) / side
            light = max(float(np.cross(u_axis, (0.0, 0.0, 1.0)) @ SUN_DIRECTION), 0.0)
            planes.append(
                Plane(
                    origin=np.array([p0[0], p0[1], 0.0]),
                    u_axis=u_axis,
                    v_axis=np.array([0.0, 0.0, 1.0]),
                    width=side,
                    height=height,
                    texture=self.texture,
                    texel_size=TrafficConfig.texel_m,
                    offset=(self.offset[0] + 97.0 * k, self.offset[1]),
                    gain=self.gain * (0.55 + 0.45 * light),
                )
            )
        corner = ring[0]
        planes.append(
            Plane(
                origin=np.array([corner[0], corner[1], height]),
                u_axis=np.array([dx, dy, 0.0]),
                v_axis=np.array([-dy, dx, 0.0]),
                width=length,
                height=width,
                texture=self.texture,
                texel_size=TrafficConfig.texel_m,
                offset=self.offset,
                gain=self.gain * (0.55 + 0.45 * SUN_DIRECTION[2]),
            )
        )
        return planes


def _lanes(
    layout: CityLayout, margin: float
) -> list[tuple[tuple[float, float], tuple[float, float], float]]:
    """(start, direction, length) of every lane of the street grid (right-hand traffic)."""
    px, py = layout.pitch
    quarter = layout.street_width / 4.0
    length_x = layout.blocks_x * px + 2 * margin
    length_y = layout.blocks_y * py + 2 * margin
    lanes = []
    for j in range(layout.blocks_y + 1):
        y = j * py
        lanes.append(((-margin, y - quarter), (1.0, 0.0), length_x))
        lanes.append(((layout.blocks_x * px + margin, y + quarter), (-1.0, 0.0), length_x))
    for i in range(layout.blocks_x + 1):
        x = i * px
        lanes.append(((x + quarter, -margin), (0.0, 1.0), length_y))
        lanes.append(((x - quarter, layout.blocks_y * py + margin), (0.0, -1.0), length_y))
    return lanes


def add_traffic(
    scene: Scene,
    config: TrafficConfig,
    rng: np.random.Generator,
    ego_times: np.ndarray,
    ego_xy: np.ndarray,
) -> list[Vehicle]:
    """Vehicles on every lane of the scene's street grid (their textures are appended to
    ``scene.textures``), without those that come within the clearance of the camera car, whose
    ground positions (N, 2) at ``ego_times`` are given (its times in the vehicles' clock)."""
    if scene.layout is None:
        raise ValueError("the scene has no street layout for traffic")
    if config.vehicles_per_km <= 0.0:
        return []
    first_texture = len(scene.textures)
    scene.textures.extend(
        procedural_texture(256, rng, rect_coverage=0.2, max_rect=1 / 4)
        for _ in range(config.textures)
    )
    kinds = list(VEHICLE_TYPES.values())
    shares = np.array([share for _, share in kinds])
    vehicles = []
    for start, direction, length in _lanes(scene.layout, config.margin_m):
        speed = float(rng.uniform(*config.speed_range_mps))
        count = int(rng.poisson(config.vehicles_per_km * length / 1000.0))
        s = 0.0
        for _ in range(count):
            size, _ = kinds[int(rng.choice(len(kinds), p=shares / shares.sum()))]
            s += size[0] / 2.0 + config.min_gap_m + rng.exponential(1000.0 / config.vehicles_per_km)
            if s + size[0] / 2.0 > length:
                break
            vehicles.append(
                Vehicle(
                    start,
                    direction,
                    length,
                    s,
                    speed,
                    size,
                    first_texture + int(rng.integers(config.textures)),
                    (float(rng.uniform(0, 256)), float(rng.uniform(0, 256))),
                    float(rng.uniform(0.4, 1.2)),
                )
            )
            s += size[0] / 2.0
    ego_xy = np.asarray(ego_xy, dtype=float).reshape(-1, 2)
    return [
        v
        for v in vehicles
        if np.min(np.linalg.norm(v.centre(ego_times) - ego_xy, axis=1))
        > v.size[0] / 2.0 + config.clearance_m
    ]


def displacement(vehicles: list[Vehicle], t: float) -> np.ndarray:
    """Ground displacement (N, 2) of every vehicle between time 0 and time t (the boxes only
    translate: each keeps its lane's direction)."""
    if not vehicles:
        return np.zeros((0, 2))
    start = np.array([v.start for v in vehicles])
    direction = np.array([v.direction for v in vehicles])
    length = np.array([v.lane_length for v in vehicles])
    s0 = np.array([v.s0 for v in vehicles])
    speed = np.array([v.speed for v in vehicles])
    s = np.mod(s0 + speed * t, length)
    return (start + s[:, None] * direction) - (start + s0[:, None] * direction)
