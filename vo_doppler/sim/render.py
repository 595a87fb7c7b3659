"""Ray-cast rendering of a planar scene into a grey pinhole image, with anti-aliased texturing.

Poses are camera → world 4×4 matrices (``p_world = T[:3, :3] @ p_camera + T[:3, 3]``), camera
frame OpenCV (x right, y down, z forward); pixel (u, v) is centred at integer coordinates and
projects from ``u = fx·x/z + cx``.

Per frame, for every plane that survives back-face and frustum culling:
1. its rectangle is clipped in 3-D against the view frustum (near plane and the four sides) and
   the clipped polygon is filled in the image (conservatively: edge pixels are resolved later);
2. the inverse depth of a plane is affine in the pixel coordinates, ``1/z = (n·K⁻¹[u, v, 1])/d``
   for the plane ``n·X = d`` in camera coordinates, so the nearest hit is a z-buffer test of an
   affine function over the polygon's bounding box.
Then every pixel's texture coordinate is the plane's homography applied to (u, v). The texture
footprint of a pixel along each texture axis is the norm of the corresponding row of that
homography's Jacobian (texels per pixel); its log2 (plus a bias) selects a level of a rip map
(textures pre-filtered and halved separately along s and t), and bilinear ``cv2.remap`` reads of
the four neighbouring level pairs are blended. Distant and grazing surfaces are thus low-pass
filtered before sampling and do not alias, while staying sharp across the direction of view
(ground and facades of a street grid are foreshortened along a texture axis). Pixels on
boundaries between planes or against the sky are ray-cast again exactly, at the centre (index
and depth) and at four sub-samples (grey value), so silhouettes are anti-aliased as well.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, replace

import cv2
import numpy as np

from vo_doppler.model.camera import Camera
from vo_doppler.sim.scene import Plane, Scene

NEAR_M = 0.05
"""Near clipping distance along the optical axis."""

_PAD = 2
"""Wrapped border (texels) around every texture in every atlas level, for bilinear reads."""

_SUBSAMPLES = np.array([[-0.375, -0.125], [0.125, -0.375], [0.375, 0.125], [-0.125, 0.375]])
"""Rotated-grid 2×2 sub-pixel offsets (u, v) for anti-aliasing geometric edges."""


@dataclass
class RenderResult:
    """An image with, per pixel, the depth z along the optical axis (inf for sky) and the index of
    the plane seen (−1 for sky)."""

    image: np.ndarray
    depth: np.ndarray
    plane_index: np.ndarray


_TAPS = np.array([1.0, 4.0, 6.0, 4.0, 1.0], dtype=np.float32) / 16.0


def _halve(texture: np.ndarray, axis: int) -> np.ndarray:
    """Low-pass (binomial 1-4-6-4-1, wrapping) and keep the even texels along one axis."""
    pad = [(0, 0), (0, 0)]
    pad[axis] = (2, 2)
    wrapped = np.pad(texture, pad, mode="wrap").astype(np.float32)
    if axis == 1:
        filtered = cv2.sepFilter2D(wrapped, -1, _TAPS, np.ones(1, np.float32))[:, 2:-2:2]
    else:
        filtered = cv2.sepFilter2D(wrapped, -1, np.ones(1, np.float32), _TAPS)[2:-2:2, :]
    return np.clip(np.round(filtered), 0, 255).astype(np.uint8)


def _levels_along(length: int, min_size: int = 4) -> int:
    """How many times a side can be halved exactly while staying ≥ min_size."""
    count = 0
    while length % 2 == 0 and length // 2 >= min_size:
        length //= 2
        count += 1
    return count


def _rip_levels(texture: np.ndarray) -> list[list[np.ndarray]]:
    """Anisotropic mip map ("rip map"): level [i][j] is halved i times along s and j along t.

    Texel k of level [i][j] sits at level-0 coordinate (k·2^i, ·2^j) since the even texels are
    kept. Separate s/t levels keep a grazing ground or facade sharp across the view while it is
    filtered along it; the footprints in a street grid are mostly aligned with the texture axes.
    """
    n_s = _levels_along(texture.shape[1])
    n_t = _levels_along(texture.shape[0])
    rows = [[texture]]
    for _ in range(n_t):
        rows[0].append(_halve(rows[0][-1], axis=0))
    for i in range(1, n_s + 1):
        rows.append([_halve(level, axis=1) for level in rows[i - 1]])
    return rows


def _pack(shapes: list[tuple[int, int]], max_width: int) -> tuple[np.ndarray, int, int]:
    """Shelf-pack rectangles (h, w); returns their top-left corners (n, 2) as (x, y) and the
    atlas width and height."""
    order = sorted(range(len(shapes)), key=lambda k: (-shapes[k][0], -shapes[k][1]))
    corners = np.zeros((len(shapes), 2), dtype=np.int64)
    x = y = shelf = width = 0
    for k in order:
        h, w = shapes[k]
        if x + w > max_width and x > 0:
            x, y, shelf = 0, y + shelf, 0
        corners[k] = (x, y)
        x += w
        shelf = max(shelf, h)
        width = max(width, x)
    return corners, width, y + shelf


class _TextureAtlas:
    """Every rip-map level of every texture packed into one image, each with a wrapped border.

    ``slot_origin[base[k] + i·(n_t[k] + 1) + j]`` is the atlas position of texel (0, 0) of level
    [i][j] of texture k.
    """

    def __init__(self, textures: list[np.ndarray]):
        levels = [_rip_levels(np.asarray(t, dtype=np.uint8)) for t in textures]
        self.n_s = np.array([len(rows) - 1 for rows in levels], dtype=np.int32)
        self.n_t = np.array([len(rows[0]) - 1 for rows in levels], dtype=np.int32)
        self.size = np.array([[t.shape[1], t.shape[0]] for t in textures], dtype=np.float32)
        tiles = [tile for rows in levels for row in rows for tile in row]
        self.base = np.cumsum(
            [0] + [(n + 1) * (m + 1) for n, m in zip(self.n_s, self.n_t, strict=True)]
        )[:-1]
        shapes = [(t.shape[0] + 2 * _PAD, t.shape[1] + 2 * _PAD) for t in tiles]
        corners, width, height = _pack(shapes, max_width=16384)
        if height > 32000:
            raise ValueError("textures too large for one atlas (cv2.remap limit 32767 px)")
        self.image = np.zeros((height, width), dtype=np.uint8)
        for (x, y), tile in zip(corners, tiles, strict=True):
            padded = np.pad(tile, _PAD, mode="wrap")
            self.image[y : y + padded.shape[0], x : x + padded.shape[1]] = padded
        self.slot_origin = (corners + _PAD).astype(np.float32)


def _plane_tables(planes: list[Plane], atlas: _TextureAtlas) -> dict[str, np.ndarray]:
    """Per-plane geometry and texture tables (one row per plane, in order)."""
    texture = np.array([p.texture for p in planes], dtype=np.int64)
    extent = np.array([[p.width, p.height] for p in planes], dtype=float).reshape(-1, 2)
    u = np.array([p.u_axis for p in planes], dtype=float).reshape(-1, 3)
    v = np.array([p.v_axis for p in planes], dtype=float).reshape(-1, 3)
    texel = np.array([p.texel_size for p in planes], dtype=float)
    offset = np.array([p.offset for p in planes], dtype=float).reshape(-1, 2)
    return {
        "corners": np.array([p.corners for p in planes]).reshape(-1, 4, 3),
        "origin": np.array([p.origin for p in planes], dtype=float).reshape(-1, 3),
        "u": u,
        "v": v,
        "normal": np.cross(u, v),
        "two_sided": np.array([p.two_sided for p in planes], dtype=bool),
        "texel": texel,
        "offset": offset,
        "gain": np.array([p.gain for p in planes], dtype=np.float32),
        "bias": np.array([p.bias for p in planes], dtype=np.float32),
        "low": offset.astype(np.float32),
        "high": (offset + extent / texel[:, None]).astype(np.float32),
        "size_s": atlas.size[texture, 0],
        "size_t": atlas.size[texture, 1],
        "n_s": atlas.n_s[texture].astype(np.float32),
        "n_t": atlas.n_t[texture].astype(np.float32),
        "base": atlas.base[texture].astype(np.float32),
    }


def _clip_polygon(polygon: np.ndarray, normal: np.ndarray, offset: float) -> np.ndarray:
    """Sutherland–Hodgman: keep the part of a convex polygon (n, 3) with normal·p ≥ offset."""
    if len(polygon) == 0:
        return polygon
    side = polygon @ normal - offset
    inside = side >= 0
    if inside.all():
        return polygon
    if not inside.any():
        return polygon[:0]
    out = []
    for k in range(len(polygon)):
        j = (k + 1) % len(polygon)
        if side[k] >= 0:
            out.append(polygon[k])
        if (side[k] >= 0) != (side[j] >= 0):
            a = side[k] / (side[k] - side[j])
            out.append(polygon[k] + a * (polygon[j] - polygon[k]))
    return np.array(out).reshape(-1, 3)


class Renderer:
    """Renders one scene through one camera; build once, then call :meth:`render` per pose.

    ``lod_bias`` (in octaves) is added to the mip level: 0.5 trades a little sharpness for the
    absence of aliasing. ``noise_std`` of :meth:`render` adds Gaussian pixel noise (grey levels)
    from a generator seeded by its ``seed`` argument, so images stay reproducible.
    """

    def __init__(
        self,
        scene: Scene,
        camera: Camera,
        lod_bias: float = 0.5,
        atlas: _TextureAtlas | None = None,
    ):
        if camera.has_distortion:
            raise ValueError("the renderer models a pinhole camera; distortion must be zero")
        if camera.width <= 0 or camera.height <= 0:
            raise ValueError("camera width and height must be set to render")
        self.scene = scene
        self.camera = camera
        self.lod_bias = lod_bias
        self.atlas = _TextureAtlas(scene.textures) if atlas is None else atlas
        self._static = _plane_tables(scene.planes, self.atlas)
        self._install(len(scene.planes), self._static)
        w, h = camera.width, camera.height
        self._u_pix = np.arange(w, dtype=np.float32)
        self._v_pix = np.arange(h, dtype=np.float32)
        self._uu, self._vv = np.meshgrid(self._u_pix, self._v_pix)
        K_inv = np.linalg.inv(camera.K)
        self._K_inv = K_inv
        margin = 1.0
        x_lo, y_lo = (-margin - camera.cx) / camera.fx, (-margin - camera.cy) / camera.fy
        x_hi = (w - 1 + margin - camera.cx) / camera.fx
        y_hi = (h - 1 + margin - camera.cy) / camera.fy
        self._frustum = [
            (np.array([0.0, 0.0, 1.0]), NEAR_M),
            (np.array([1.0, 0.0, -x_lo]), 0.0),
            (np.array([-1.0, 0.0, x_hi]), 0.0),
            (np.array([0.0, 1.0, -y_lo]), 0.0),
            (np.array([0.0, -1.0, y_hi]), 0.0),
        ]

    def _install(self, count: int, tables: dict[str, np.ndarray]) -> None:
        """Use the ``count`` planes of these tables; index 0 of the shading tables is the sky."""
        self._count = count
        self._corners, self._origin = tables["corners"], tables["origin"]
        self._u, self._v, self._normal = tables["u"], tables["v"], tables["normal"]
        self._two_sided, self._texel = tables["two_sided"], tables["texel"]
        self._offset = tables["offset"]
        sky = {
            "gain": 0.0,
            "bias": self.scene.sky,
            "size_s": 1.0,
            "size_t": 1.0,
            "n_s": 0.0,
            "n_t": 0.0,
            "base": 0.0,
        }
        for name, value in sky.items():
            setattr(self, "_" + name, np.concatenate([[value], tables[name]]).astype(np.float32))
        # Texture-coordinate range of each rectangle (unwrapped); the sky's range is empty.
        self._low = np.vstack([[np.inf, np.inf], tables["low"]]).astype(np.float32)
        self._high = np.vstack([[-np.inf, -np.inf], tables["high"]]).astype(np.float32)

    def plane_tables(self, planes: list[Plane]) -> dict[str, np.ndarray]:
        """Tables of extra planes (textures indexing ``scene.textures``) for :meth:`with_moving`;
        rows may be selected and ``origin`` and ``corners`` translated before use."""
        return _plane_tables(planes, self.atlas)

    def with_moving(self, tables: dict[str, np.ndarray]) -> Renderer:
        """A renderer of this one's scene plus the planes of ``tables`` (:meth:`plane_tables`;
        moving objects at one instant), sharing the atlas and the static tables."""
        if len(tables["origin"]) == 0:
            return self
        merged = {k: np.concatenate([self._static[k], tables[k]]) for k in self._static}
        other = copy.copy(self)
        other._install(len(self.scene.planes) + len(tables["origin"]), merged)
        return other

    def window(self, row0: int, row1: int) -> Renderer:
        """A renderer of rows [row0, row1) of this camera's image (same scene and atlas)."""
        camera = replace(self.camera, cy=self.camera.cy - row0, height=row1 - row0)
        return Renderer(self.scene, camera, self.lod_bias, self.atlas)

    def _visible_planes(self, R_cw: np.ndarray, t_cw: np.ndarray, centre: np.ndarray) -> np.ndarray:
        """Indices of planes facing the camera with some corner inside every frustum half-space."""
        facing = np.einsum("ij,ij->i", centre[None, :] - self._origin, self._normal)
        keep = (facing > 0) | (self._two_sided & (np.abs(facing) > 0))
        corners_cam = self._corners @ R_cw.T + t_cw
        for normal, offset in self._frustum:
            keep &= np.any(corners_cam @ normal >= offset, axis=1)
        return np.flatnonzero(keep)

    def render_full(
        self, T_world_camera: np.ndarray, noise_std: float = 0.0, seed: int = 0
    ) -> RenderResult:
        """Image (uint8), depth (float32, inf for sky) and plane index (−1 for sky) for a pose."""
        T = np.asarray(T_world_camera, dtype=float)
        R_wc, centre = T[:3, :3], T[:3, 3]
        R_cw = R_wc.T
        t_cw = -R_cw @ centre
        cam = self.camera
        h, w = cam.height, cam.width
        inv_depth = np.zeros((h, w), dtype=np.float32)
        index = np.zeros((h, w), dtype=np.int32)
        homographies = np.zeros((self._count + 1, 9), dtype=np.float32)
        homographies[0] = (0, 0, 0, 0, 0, 0, 0, 0, 1)
        inverse_depth_planes = np.zeros((self._count + 1, 3), dtype=np.float32)
        mask = np.zeros((h, w), dtype=np.uint8)
        for k in self._visible_planes(R_cw, t_cw, centre):
            polygon = self._corners[k] @ R_cw.T + t_cw
            for normal, offset in self._frustum:
                polygon = _clip_polygon(polygon, normal, offset)
            if len(polygon) < 3:
                continue
            n_c = R_cw @ self._normal[k]
            d_c = float(n_c @ (R_cw @ self._origin[k] + t_cw))
            if abs(d_c) < 1e-9:
                continue
            pixels = polygon[:, :2] / polygon[:, 2:3] * (cam.fx, cam.fy) + (cam.cx, cam.cy)
            x0, y0 = np.floor(pixels.min(axis=0)).astype(int)
            x1, y1 = np.ceil(pixels.max(axis=0)).astype(int)
            x0, y0 = max(x0, 0), max(y0, 0)
            x1, y1 = min(x1, w - 1), min(y1, h - 1)
            if x1 < x0 or y1 < y0:
                continue
            window = mask[y0 : y1 + 1, x0 : x1 + 1]
            window[:] = 0
            shift = 8
            vertices = np.round((pixels - (x0, y0)) * (1 << shift)).astype(np.int32)
            cv2.fillConvexPoly(window, vertices, 1, lineType=cv2.LINE_8, shift=shift)
            # 1/z = (n_c · K⁻¹ [u, v, 1]) / d_c, affine in (u, v).
            a, b, c = (n_c @ self._K_inv) / d_c
            plane_inv = (a * self._u_pix[x0 : x1 + 1])[None, :] + (
                b * self._v_pix[y0 : y1 + 1] + c
            )[:, None]
            closer = (window > 0) & (plane_inv > inv_depth[y0 : y1 + 1, x0 : x1 + 1])
            np.copyto(inv_depth[y0 : y1 + 1, x0 : x1 + 1], plane_inv, where=closer)
            np.copyto(index[y0 : y1 + 1, x0 : x1 + 1], k + 1, where=closer)
            homographies[k + 1] = self._texture_homography(k, R_cw, centre, n_c, d_c).ravel()
            inverse_depth_planes[k + 1] = (a, b, c)
        image = self._shade(index, homographies, self._uu, self._vv)
        self._resolve_edges(image, index, inv_depth, homographies, inverse_depth_planes)
        if noise_std > 0:
            image += (
                np.random.default_rng(seed).normal(0.0, noise_std, image.shape).astype(np.float32)
            )
        depth = np.full((h, w), np.inf, dtype=np.float32)
        np.divide(1.0, inv_depth, out=depth, where=index > 0)
        return RenderResult(np.clip(image, 0, 255).round().astype(np.uint8), depth, index - 1)

    def backproject(
        self, T_world_camera: np.ndarray, pixels: np.ndarray, plane_index: np.ndarray
    ) -> np.ndarray:
        """World points (N, 3) where the rays through sub-pixel ``pixels`` (N, 2) meet the plane
        seen at the nearest whole pixel (``plane_index`` from :meth:`render_full`); NaN on sky."""
        T = np.asarray(T_world_camera, dtype=float)
        pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
        h, w = plane_index.shape
        cols = np.clip(np.round(pixels[:, 0]).astype(int), 0, w - 1)
        rows = np.clip(np.round(pixels[:, 1]).astype(int), 0, h - 1)
        k = plane_index[rows, cols]
        rays = np.column_stack([pixels, np.ones(len(pixels))]) @ self._K_inv.T @ T[:3, :3].T
        normal = self._normal[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            depth = np.einsum("ij,ij->i", self._origin[k] - T[:3, 3], normal) / np.einsum(
                "ij,ij->i", rays, normal
            )
        points = T[:3, 3] + depth[:, None] * rays
        points[k < 0] = np.nan
        return points

    def render(
        self, T_world_camera: np.ndarray, noise_std: float = 0.0, seed: int = 0
    ) -> np.ndarray:
        """Grey uint8 image (height × width) seen from the camera → world pose."""
        return self.render_full(T_world_camera, noise_std, seed).image

    def _texture_homography(
        self, k: int, R_cw: np.ndarray, centre: np.ndarray, n_c: np.ndarray, d_c: float
    ) -> np.ndarray:
        """3×3 map from pixel [u, v, 1] to homogeneous texture coordinates (texels, unwrapped).

        With r = K⁻¹[u, v, 1] the hit point is X_c = r·d_c/(n_c·r); its plane coordinate along
        the axis e is ((R X_c + C − O)·e)/m = (d_c (Rᵀe)·r + ((C − O)·e)(n_c·r)) / (m (n_c·r)).
        """
        rows = []
        for axis, offset in ((self._u[k], self._offset[k, 0]), (self._v[k], self._offset[k, 1])):
            along = float((centre - self._origin[k]) @ axis)
            rows.append(
                (d_c * (R_cw @ axis) + (along + offset * self._texel[k]) * n_c) / self._texel[k]
            )
        rows.append(n_c)
        return np.array(rows) @ self._K_inv

    def _resolve_edges(
        self,
        image: np.ndarray,
        index: np.ndarray,
        inv_depth: np.ndarray,
        homographies: np.ndarray,
        inverse_depth_planes: np.ndarray,
    ) -> None:
        """Exact coverage and anti-aliasing on plane/plane and plane/sky boundaries (in place).

        The polygon fill is conservative (it also takes pixels the outline only touches), so
        every pixel next to a change of plane is ray-cast again against the planes seen at it
        and its 4 neighbours (nearest hit inside its rectangle wins): at its centre, which fixes
        index and depth, and at four rotated-grid sub-samples whose mean is its grey value.
        Interior pixels keep their centre sample, which the texture pre-filter band-limits.
        """
        edge = np.zeros(index.shape, dtype=bool)
        across = index[:, 1:] != index[:, :-1]
        edge[:, 1:] |= across
        edge[:, :-1] |= across
        down = index[1:, :] != index[:-1, :]
        edge[1:, :] |= down
        edge[:-1, :] |= down
        rows, cols = np.nonzero(edge)
        if len(rows) == 0:
            return
        padded = np.pad(index, 1, mode="edge")
        neighbours = ((0, 0), (0, 1), (0, -1), (1, 0), (-1, 0))
        offsets = np.vstack([_SUBSAMPLES, [0.0, 0.0]])
        u = (cols[None, :] + offsets[:, :1]).astype(np.float32)
        v = (rows[None, :] + offsets[:, 1:]).astype(np.float32)
        nearest = np.zeros(u.shape, dtype=np.float32)
        seen = np.zeros(u.shape, dtype=np.int32)
        for dr, dc in neighbours:
            k = padded[rows + 1 + dr, cols + 1 + dc]
            a, b, c = inverse_depth_planes[k].T
            inverse = a * u + b * v + c
            H = homographies[k]
            w = H[:, 6] * u + H[:, 7] * v + H[:, 8]
            s = (H[:, 0] * u + H[:, 1] * v + H[:, 2]) / w
            t = (H[:, 3] * u + H[:, 4] * v + H[:, 5]) / w
            low, high = self._low[k], self._high[k]
            hit = (inverse > nearest) & (inverse < 1.0 / NEAR_M)
            hit &= (s >= low[:, 0]) & (s <= high[:, 0]) & (t >= low[:, 1]) & (t <= high[:, 1])
            nearest = np.where(hit, inverse, nearest)
            seen = np.where(hit, k, seen)
        image[rows, cols] = self._shade(seen[:4], homographies, u[:4], v[:4]).mean(axis=0)
        index[rows, cols] = seen[4]
        inv_depth[rows, cols] = nearest[4]

    def _shade(
        self, index: np.ndarray, homographies: np.ndarray, u: np.ndarray, v: np.ndarray
    ) -> np.ndarray:
        """Rip-mapped texture lookup and per-plane gain/bias at pixel positions (u, v) (float32).

        The footprint of a pixel along s is |∂s/∂(u, v)| texels (likewise t); its log2 plus the
        bias picks the s and t levels, and four bilinear reads (the neighbouring integer level
        pairs) are blended.
        """
        h0, h1, h2, h3, h4, h5, h6, h7, h8 = (np.take(homographies[:, m], index) for m in range(9))
        inv_w = 1.0 / (h6 * u + h7 * v + h8)
        s = (h0 * u + h1 * v + h2) * inv_w
        t = (h3 * u + h4 * v + h5) * inv_w
        extent_s = np.hypot((h0 - s * h6) * inv_w, (h1 - s * h7) * inv_w)
        extent_t = np.hypot((h3 - t * h6) * inv_w, (h4 - t * h7) * inv_w)
        n_s, n_t = np.take(self._n_s, index), np.take(self._n_t, index)
        level_s = np.clip(np.log2(np.maximum(extent_s, 1e-6)) + self.lod_bias, 0.0, n_s)
        level_t = np.clip(np.log2(np.maximum(extent_t, 1e-6)) + self.lod_bias, 0.0, n_t)
        size_s, size_t = np.take(self._size_s, index), np.take(self._size_t, index)
        s -= size_s * np.floor(s / size_s)
        t -= size_t * np.floor(t / size_t)
        i0, j0 = np.floor(level_s), np.floor(level_t)
        fi, fj = level_s - i0, level_t - j0
        row_base = np.take(self._base, index)
        stride = n_t + 1.0
        origin = self.atlas.slot_origin
        value = np.zeros(index.shape, dtype=np.float32)
        for i, weight_i in ((i0, 1.0 - fi), (np.minimum(i0 + 1.0, n_s), fi)):
            scaled_s = s * np.exp2(-i)
            slot_row = row_base + i * stride
            for j, weight_j in ((j0, 1.0 - fj), (np.minimum(j0 + 1.0, n_t), fj)):
                slot = (slot_row + j).astype(np.int32)
                map_x = np.take(origin[:, 0], slot) + scaled_s
                map_y = np.take(origin[:, 1], slot) + t * np.exp2(-j)
                sample = cv2.remap(self.atlas.image, map_x, map_y, cv2.INTER_LINEAR)
                value += (weight_i * weight_j) * sample
        return np.take(self._gain, index) * value + np.take(self._bias, index)


def render(
    scene: Scene, camera: Camera, T_world_camera: np.ndarray, lod_bias: float = 0.5
) -> np.ndarray:
    """One-off render (builds the texture atlas each call; use :class:`Renderer` for sequences)."""
    return Renderer(scene, camera, lod_bias).render(T_world_camera)


def project_points(camera: Camera, T_world_camera: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Pixels (N, 2) of world points (N, 3) seen from a camera → world pose (NaN if behind)."""
    T = np.asarray(T_world_camera, dtype=float)
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    camera_points = (points - T[:3, 3]) @ T[:3, :3]
    pixels = camera.project(camera_points)
    pixels[camera_points[:, 2] <= 0] = np.nan
    return pixels


def look_at(eye: np.ndarray, target: np.ndarray, up: np.ndarray = (0.0, 0.0, 1.0)) -> np.ndarray:
    """Camera → world pose (4×4, OpenCV axes) at ``eye`` looking at ``target``, ``up`` up."""
    eye = np.asarray(eye, dtype=float)
    forward = np.asarray(target, dtype=float) - eye
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, np.asarray(up, dtype=float))
    norm = np.linalg.norm(right)
    if norm < 1e-9:
        raise ValueError("viewing direction is parallel to the up vector")
    right /= norm
    T = np.eye(4)
    T[:3, :3] = np.column_stack([right, np.cross(forward, right), forward])
    T[:3, 3] = eye
    return T
