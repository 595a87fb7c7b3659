"""Synthetic city scenes made of textured planar rectangles, and their procedural textures.

World frame ENU (x east, y north, z up), ground at z = 0. A city is a grid of building blocks
separated by streets; each block is split into a few buildings (boxes) of random height. Only
faces that can be seen are kept: outer walls down to the ground, the part of a shared wall that
rises above the lower neighbour, and roofs. Everything is deterministic per seed.

Textures are seamless square tiles (wrap addressing), built from multi-scale posterised pink
noise (blobs with sharp, curved edges) overlaid with random axis-aligned rectangles of random
grey levels at scales from a few texels to an eighth of the tile. That gives strong corners at
every distance without the periodic structure (window grids, checkerboards) that lets KLT lock
onto the wrong copy of a pattern. A plane shows a window of its tile from a per-plane offset,
so neighbouring planes look different; the tile period (tens of metres) is far beyond any
tracking search radius.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np

WINDOW_STREAM = 0x3D0C
"""Second seed word of the window-facade random stream."""
SUN_DIRECTION = np.array([0.45, -0.55, 0.70]) / np.linalg.norm([0.45, -0.55, 0.70])
"""Unit vector towards the sun (ENU), used for per-face brightness."""


@dataclass(frozen=True, eq=False)
class Plane:
    """A textured rectangle ``origin + a·u_axis + b·v_axis``, 0 ≤ a ≤ width, 0 ≤ b ≤ height.

    The texture coordinate (in texels) of the point (a, b) is ``(a / texel_size + offset[0],
    b / texel_size + offset[1])``, wrapped into the tile ``texture`` (an index into
    ``Scene.textures``); texel i is centred at coordinate i. The front side faces
    ``normal = u_axis × v_axis``; a one-sided plane is invisible from behind. Rendered grey value
    is ``gain · texture + bias``.
    """

    origin: np.ndarray
    u_axis: np.ndarray
    v_axis: np.ndarray
    width: float
    height: float
    texture: int
    texel_size: float
    offset: tuple[float, float] = (0.0, 0.0)
    gain: float = 1.0
    bias: float = 0.0
    two_sided: bool = False

    @property
    def normal(self) -> np.ndarray:
        return np.cross(self.u_axis, self.v_axis)

    @property
    def corners(self) -> np.ndarray:
        """The four corners (4, 3) in order (0,0), (w,0), (w,h), (0,h)."""
        u = np.asarray(self.u_axis) * self.width
        v = np.asarray(self.v_axis) * self.height
        o = np.asarray(self.origin, dtype=float)
        return np.array([o, o + u, o + u + v, o + v])

    def point(self, a: float, b: float) -> np.ndarray:
        """World point at in-plane coordinates (a, b) metres."""
        return np.asarray(self.origin) + a * np.asarray(self.u_axis) + b * np.asarray(self.v_axis)

    def texel_to_point(self, s: float, t: float) -> np.ndarray:
        """World point whose (unwrapped) texture coordinate is (s, t) texels."""
        return self.point(
            (s - self.offset[0]) * self.texel_size, (t - self.offset[1]) * self.texel_size
        )


@dataclass(frozen=True)
class Building:
    """An axis-aligned box on the ground: footprint [x0, x1] × [y0, y1], roof at ``height``."""

    x0: float
    y0: float
    x1: float
    y1: float
    height: float


@dataclass(frozen=True)
class CityLayout:
    """Street grid: street centre lines at x = i·pitch_x (i = 0..blocks_x), y = j·pitch_y."""

    blocks_x: int
    blocks_y: int
    block_size: tuple[float, float]
    street_width: float

    @property
    def pitch(self) -> tuple[float, float]:
        return (
            self.block_size[0] + self.street_width,
            self.block_size[1] + self.street_width,
        )


@dataclass
class Scene:
    """Planes to render, their texture tiles (uint8, square or rectangular) and the sky grey."""

    planes: list[Plane]
    textures: list[np.ndarray]
    sky: float = 215.0
    buildings: list[Building] = field(default_factory=list)
    layout: CityLayout | None = None


def _white(size: int, rng: np.random.Generator) -> np.ndarray:
    """Square white noise (float32) of the standard normal law."""
    return rng.standard_normal((size, size)).astype(np.float32)


def _pink_filter(white: np.ndarray, f_low: float, f_high: float) -> np.ndarray:
    """Periodic noise with a 1/f amplitude spectrum between f_low and f_high cycles/texel,
    normalised, from the square white noise ``white``."""
    size = white.shape[0]
    fy = np.fft.fftfreq(size)[:, None]
    fx = np.fft.rfftfreq(size)[None, :]
    radius = np.hypot(fy, fx)
    band = (radius >= f_low) & (radius <= f_high)
    amplitude = np.where(band, 1.0 / np.maximum(radius, 1e-9), 0.0)
    noise = np.fft.irfft2(np.fft.rfft2(white) * amplitude, s=(size, size))
    return ((noise - noise.mean()) / (noise.std() + 1e-12)).astype(np.float32)


def _draw_wrapped_rect(canvas: np.ndarray, x: int, y: int, w: int, h: int, value: float) -> None:
    """Fill a rectangle with corner (x, y) ∈ [0, size)² on a torus (copies cover the wrap)."""
    size = canvas.shape[0]
    shifts_x = (0, -size) if x + w > size else (0,)
    shifts_y = (0, -size) if y + h > size else (0,)
    for dx in shifts_x:
        for dy in shifts_y:
            corner = (x + dx, y + dy)
            cv2.rectangle(canvas, corner, (corner[0] + w - 1, corner[1] + h - 1), value, -1)


def texture_draws(
    size: int, rng: np.random.Generator, rect_coverage: float = 0.12, max_rect: float = 1 / 8
) -> tuple[np.ndarray, list[tuple[np.ndarray, np.ndarray, np.ndarray]], np.ndarray]:
    """The random numbers of one :func:`procedural_texture`, in the order it draws them: the
    white noise of its blobs, each octave's rectangles (corners, sizes, grey levels) and the
    white noise of its fine texture. An untextured city draws them without painting, so that
    its buildings are those of the textured city of the same seed."""
    blobs = _white(size, rng)
    octaves = []
    side = 4.0
    while side <= max_rect * size:
        count = int(rect_coverage * size * size / side**2)
        xy = rng.integers(0, size, size=(count, 2))
        wh = np.maximum((side * rng.uniform(0.5, 1.5, size=(count, 2))).astype(int), 2)
        octaves.append((xy, wh, rng.uniform(0.0, 1.0, size=count)))
        side *= 2.0
    return blobs, octaves, _white(size, rng)


def procedural_texture(
    size: int, rng: np.random.Generator, rect_coverage: float = 0.12, max_rect: float = 1 / 8
) -> np.ndarray:
    """A seamless, corner-rich, non-periodic grey tile (size × size uint8, size a power of two).

    Posterised pink noise (periods from 12 texels to half the tile) gives blobs of every scale
    with sharp curved edges; random rectangles at octave scales from 4 texels to ``max_rect``
    of the side (each scale covering about ``rect_coverage`` of the tile, random aspect and grey
    level) add straight-edged corners; a little fine noise adds texture inside flat areas.
    Levels are stretched to 12..243.
    """
    blobs, octaves, fine = texture_draws(size, rng, rect_coverage, max_rect)
    noise = _pink_filter(blobs, 2.0 / size, 1.0 / 12.0)
    levels = np.quantile(noise, [0.2, 0.4, 0.6, 0.8])
    tile = (np.digitize(noise, levels).astype(np.float32) / 4.0) * 0.8 + 0.1
    for xy, wh, values in octaves:
        for (x, y), (w, h), value in zip(xy.tolist(), wh.tolist(), values.tolist(), strict=True):
            _draw_wrapped_rect(tile, x, y, w, h, value)
    tile += 0.05 * _pink_filter(fine, 0.1, 0.5)
    lo, hi = np.quantile(tile, [0.01, 0.99])
    return np.clip(12.0 + 231.0 * (tile - lo) / (hi - lo), 0, 255).round().astype(np.uint8)


@dataclass(frozen=True)
class WindowFacadeDraws:
    """The random numbers of one :func:`window_facade_texture`, drawn in its order: wall,
    glass and frame levels, window size, each window's blind (the fraction drawn and its grey
    level, or None) in column-major order, and the white noises of the plaster's pink noise and
    of its fine texture."""

    wall: float
    glass: float
    frame_step: float
    width_fraction: float
    height_fraction: float
    blinds: list[tuple[float, float] | None]
    plaster: np.ndarray
    fine: np.ndarray


def window_facade_draws(
    size: int, rng: np.random.Generator, columns: int = 16, storeys: int = 12
) -> WindowFacadeDraws:
    """The draws of :func:`window_facade_texture`; an untextured city makes them without
    painting, so that its walls are those of the textured city of the same seed."""
    wall = float(rng.uniform(0.45, 0.8))
    plaster = _white(size, rng)
    glass, frame_step = float(rng.uniform(0.08, 0.3)), float(rng.uniform(0.08, 0.2))
    width_fraction, height_fraction = float(rng.uniform(0.45, 0.65)), float(rng.uniform(0.4, 0.6))
    blinds = [
        (float(rng.uniform(0.2, 0.9)), float(rng.uniform(0.5, 0.9)))
        if rng.uniform() < 0.2
        else None
        for _ in range(columns * storeys)
    ]
    fine = _white(size, rng)
    return WindowFacadeDraws(
        wall, glass, frame_step, width_fraction, height_fraction, blinds, plaster, fine
    )


def window_facade_texture(
    size: int, rng: np.random.Generator, columns: int = 16, storeys: int = 12
) -> np.ndarray:
    """A seamless facade tile with a regular grid of windows (size × size uint8).

    ``columns`` × ``storeys`` identical bays (window spacing size/columns texels across,
    size/storeys up: 2.56 m × 3.41 m at the default 0.04 m texel and 1024-texel tile), each a
    dark glazed window with a lighter frame and sill on a plaster wall of faint pink noise; a
    few windows have a blind drawn to a random height, as on real buildings. The repetition is
    what makes real facades hard for feature tracking: a patch matches its neighbours a bay away.
    """
    draws = window_facade_draws(size, rng, columns, storeys)
    tile = draws.wall + 0.04 * _pink_filter(draws.plaster, 4.0 / size, 0.25)
    frame = min(draws.wall + draws.frame_step, 1.0)
    bay_w, bay_h = size / columns, size / storeys
    win_w = int(bay_w * draws.width_fraction)
    win_h = int(bay_h * draws.height_fraction)
    border = max(2, int(0.08 * win_w))
    blinds = iter(draws.blinds)
    for i in range(columns):
        for j in range(storeys):
            x = round(i * bay_w + (bay_w - win_w) / 2)
            y = round(j * bay_h + (bay_h - win_h) / 2)
            cv2.rectangle(
                tile,
                (x - border, y - border),
                (x + win_w + border, y + win_h + 2 * border),
                frame,
                -1,
            )
            cv2.rectangle(tile, (x, y), (x + win_w, y + win_h), draws.glass, -1)
            blind = next(blinds)
            if blind is not None:
                drawn = int(win_h * blind[0])
                cv2.rectangle(tile, (x, y), (x + win_w, y + drawn), blind[1], -1)
    tile += 0.02 * _pink_filter(draws.fine, 0.1, 0.5)
    return np.clip(12.0 + 231.0 * tile, 0, 255).round().astype(np.uint8)


def _wall_texture(
    rng: np.random.Generator, window_rng: np.random.Generator, corner_rich: int, windows: int
) -> int:
    """Texture index of a wall: one of the corner-rich tiles drawn from ``rng`` (as without
    window facades), replaced with probability windows / (corner_rich + windows) by a window
    tile drawn from ``window_rng``."""
    texture = 1 + int(rng.integers(corner_rich))
    if windows and window_rng.uniform() < windows / (corner_rich + windows):
        texture = 1 + corner_rich + int(window_rng.integers(windows))
    return texture


def _split(length: float, parts: int, rng: np.random.Generator) -> np.ndarray:
    """Random split points 0 = c0 < c1 < … < c_parts = length, each part ≥ length / (3·parts)."""
    weights = rng.uniform(0.5, 1.5, size=parts)
    return np.concatenate([[0.0], np.cumsum(weights) / weights.sum() * length])


def _wall(
    p0: np.ndarray,
    p1: np.ndarray,
    z0: float,
    z1: float,
    texture: int,
    texel: float,
    rng: np.random.Generator,
    tile_size: int,
) -> Plane:
    """Vertical wall over the ground segment p0 → p1 from height z0 to z1.

    Its front (normal u × z) is on the right of p0 → p1 seen from above.
    """
    direction = p1 - p0
    length = float(np.linalg.norm(direction))
    u_axis = np.array([direction[0], direction[1], 0.0]) / length
    v_axis = np.array([0.0, 0.0, 1.0])
    normal = np.cross(u_axis, v_axis)
    light = max(float(normal @ SUN_DIRECTION), 0.0)
    return Plane(
        origin=np.array([p0[0], p0[1], z0]),
        u_axis=u_axis,
        v_axis=v_axis,
        width=length,
        height=z1 - z0,
        texture=texture,
        texel_size=texel,
        offset=(float(rng.uniform(0, tile_size)), float(rng.uniform(0, tile_size))),
        gain=(0.55 + 0.45 * light) * rng.uniform(0.9, 1.1),
        bias=rng.uniform(-8.0, 8.0),
    )


def _block_buildings(
    x0: float,
    y0: float,
    x1: float,
    y1: float,
    rng: np.random.Generator,
    buildings_per_side: tuple[int, int],
    height_range: tuple[float, float],
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Lot boundaries along x and y and the heights (nx, ny) of the buildings of one block."""
    nx = int(rng.integers(buildings_per_side[0], buildings_per_side[1] + 1))
    ny = int(rng.integers(buildings_per_side[0], buildings_per_side[1] + 1))
    xs = x0 + _split(x1 - x0, nx, rng)
    ys = y0 + _split(y1 - y0, ny, rng)
    heights = rng.uniform(height_range[0], height_range[1], size=(nx, ny))
    return xs, ys, heights


def city_scene(
    seed: int = 0,
    blocks_x: int = 4,
    blocks_y: int = 3,
    block_size: tuple[float, float] = (60.0, 60.0),
    street_width: float = 16.0,
    height_range: tuple[float, float] = (8.0, 35.0),
    buildings_per_side: tuple[int, int] = (1, 3),
    facade_texel_m: float = 0.04,
    ground_texel_m: float = 0.02,
    tile_size: int = 1024,
    n_facade_textures: int = 6,
    ground_margin_m: float = 2000.0,
    window_facades: int = 0,
    ground_contrast: float = 1.0,
    textured: bool = True,
) -> Scene:
    """A city of ``blocks_x × blocks_y`` building blocks on a street grid (deterministic per seed).

    Street centre lines run along x = i·pitch_x and y = j·pitch_y (pitch = block + street width),
    so block (i, j) covers [i·pitch_x + w/2, (i+1)·pitch_x − w/2] × (same in y). Each block holds
    a random grid of 1–3 × 1–3 buildings with heights drawn from ``height_range``. The ground
    (one plane, z = 0) extends ``ground_margin_m`` beyond the city so the horizon is ground.
    ``window_facades`` adds that many repetitive window-grid tiles
    (:func:`window_facade_texture`) to the ``n_facade_textures`` corner-rich ones; walls pick
    among all of them, roofs among the former (0, the default, gives the scene of earlier versions).
    ``ground_contrast`` scales the ground texture's grey levels about their mean (1: as drawn;
    worn asphalt is a low-contrast surface, about a third of the facades' contrast).
    ``textured`` False leaves ``Scene.textures`` empty: the geometry alone (the same planes and
    buildings), for a simulation that renders no image.
    """
    rng = np.random.default_rng(seed)
    ground_tile = 2 * tile_size
    textures = []
    if textured:
        textures = [procedural_texture(ground_tile, rng, rect_coverage=0.1, max_rect=1 / 32)]
        if ground_contrast != 1.0:
            mean = float(textures[0].mean())
            textures[0] = np.clip(mean + ground_contrast * (textures[0] - mean), 0, 255).round()
            textures[0] = textures[0].astype(np.uint8)
        textures += [procedural_texture(tile_size, rng) for _ in range(n_facade_textures)]
    else:  # the same draws unpainted (85 % of a simulation without images): the same buildings
        texture_draws(ground_tile, rng, rect_coverage=0.1, max_rect=1 / 32)
        for _ in range(n_facade_textures):
            texture_draws(tile_size, rng)
    # Window facades draw from their own stream, so the city is the same with or without them.
    window_rng = np.random.default_rng([seed, WINDOW_STREAM])
    for _ in range(window_facades):
        if textured:
            textures.append(window_facade_texture(tile_size, window_rng))
        else:
            window_facade_draws(tile_size, window_rng)
    layout = CityLayout(blocks_x, blocks_y, block_size, street_width)
    px, py = layout.pitch
    extent = np.array([blocks_x * px, blocks_y * py])
    lo = -np.full(2, ground_margin_m)
    planes = [
        Plane(
            origin=np.array([lo[0], lo[1], 0.0]),
            u_axis=np.array([1.0, 0.0, 0.0]),
            v_axis=np.array([0.0, 1.0, 0.0]),
            width=float(extent[0] - 2 * lo[0]),
            height=float(extent[1] - 2 * lo[1]),
            texture=0,
            texel_size=ground_texel_m,
            offset=(float(rng.uniform(0, ground_tile)), float(rng.uniform(0, ground_tile))),
            gain=0.85,
            bias=0.0,
        )
    ]
    buildings: list[Building] = []
    half = street_width / 2.0
    for i in range(blocks_x):
        for j in range(blocks_y):
            xs, ys, heights = _block_buildings(
                i * px + half,
                j * py + half,
                (i + 1) * px - half,
                (j + 1) * py - half,
                rng,
                buildings_per_side,
                height_range,
            )
            nx, ny = heights.shape
            padded = np.zeros((nx + 2, ny + 2))
            padded[1:-1, 1:-1] = heights
            for a in range(nx):
                for b in range(ny):
                    h = float(heights[a, b])
                    buildings.append(Building(xs[a], ys[b], xs[a + 1], ys[b + 1], h))
                    # Faces listed counter-clockwise seen from above so u × z points outward.
                    corners = np.array(
                        [
                            [xs[a], ys[b]],
                            [xs[a + 1], ys[b]],
                            [xs[a + 1], ys[b + 1]],
                            [xs[a], ys[b + 1]],
                        ]
                    )
                    neighbours = (
                        padded[a + 1, b],
                        padded[a + 2, b + 1],
                        padded[a + 1, b + 2],
                        padded[a, b + 1],
                    )
                    for side, below in enumerate(neighbours):
                        if h > below:
                            planes.append(
                                _wall(
                                    corners[side],
                                    corners[(side + 1) % 4],
                                    float(below),
                                    h,
                                    _wall_texture(
                                        rng, window_rng, n_facade_textures, window_facades
                                    ),
                                    facade_texel_m,
                                    rng,
                                    tile_size,
                                )
                            )
                    planes.append(
                        Plane(
                            origin=np.array([xs[a], ys[b], h]),
                            u_axis=np.array([1.0, 0.0, 0.0]),
                            v_axis=np.array([0.0, 1.0, 0.0]),
                            width=float(xs[a + 1] - xs[a]),
                            height=float(ys[b + 1] - ys[b]),
                            texture=1 + int(rng.integers(n_facade_textures)),
                            texel_size=facade_texel_m,
                            offset=(float(rng.uniform(0, tile_size)), 0.0),
                            gain=0.9,
                        )
                    )
    return Scene(planes=planes, textures=textures, buildings=buildings, layout=layout)
