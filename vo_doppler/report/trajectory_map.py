"""The run report's map: the trajectories as inline SVG over the local ENU plane (metres) with
pan and zoom, an opt-in OpenStreetMap background, an opt-in layer of the trajectories as
evaluated (moved to the ground truth at their start), and the same tracks as GeoJSON (lon/lat).

Nothing is fetched unless the reader ticks the background box, so the page works offline and
raises no console errors there.
"""

from __future__ import annotations

import html
from pathlib import Path

import numpy as np

from vo_doppler.geo import EnuFrame, ecef_to_geodetic
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report.json_text import json_text

TRUTH = "truth"
COLOURS = {
    TRUTH: "#555555",
    "vo": "#ff7f0e",
    "vo_gps_conv": "#1f77b4",
    "vo_gps_tc": "#d62728",
    "dr": "#8c564b",
    "dr_gps_conv": "#17becf",
    "dr_gps_tc": "#2ca02c",
}
"""One colour per track, shared by every figure of the report."""

MAX_POINTS = 1500
"""Tracks longer than this are thinned (every k-th pose, the last kept) to keep pages small."""


def thinned(positions: np.ndarray, max_points: int = MAX_POINTS) -> np.ndarray:
    """Every k-th row of ``positions`` so that at most ``max_points`` remain, the last kept."""
    step = max(1, int(np.ceil(len(positions) / max_points)))
    rows = np.arange(0, len(positions), step)
    if len(positions) and rows[-1] != len(positions) - 1:
        rows = np.append(rows, len(positions) - 1)
    return positions[rows]


def lon_lat(enu: EnuFrame, positions: np.ndarray) -> np.ndarray:
    """ENU positions (m) as (longitude, latitude) in degrees."""
    lat, lon, _ = ecef_to_geodetic(enu.enu_to_ecef(positions))
    return np.column_stack([np.degrees(lon), np.degrees(lat)])


def write_geojson(
    path: Path, tracks: dict[str, Trajectory], labels: dict[str, str], enu: EnuFrame
) -> None:
    """One LineString feature per track, coordinates [lon, lat] in degrees (RFC 7946)."""
    features = []
    for name, trajectory in tracks.items():
        if len(trajectory) < 2:
            continue
        coordinates = np.round(lon_lat(enu, thinned(trajectory.positions)), 8)
        features.append(
            {
                "type": "Feature",
                "properties": {"name": name, "label": labels.get(name, name)},
                "geometry": {"type": "LineString", "coordinates": coordinates.tolist()},
            }
        )
    path.write_text(json_text({"type": "FeatureCollection", "features": features}))


def _bounds(trajectory: Trajectory) -> tuple[np.ndarray, np.ndarray] | None:
    """(east, north) minima and maxima of the finite positions of one track (None: none is),
    taken track by track rather than of all tracks stacked (a 30-min drive's ground truth and
    twelve tracks stacked were 8.5 MiB, twice)."""
    plane = trajectory.positions[:, :2]
    finite = plane[np.isfinite(plane).all(axis=1)]
    return (finite.min(axis=0), finite.max(axis=0)) if len(finite) else None


def _points(positions: np.ndarray) -> str:
    return " ".join(f"{e:.2f},{-n:.2f}" for e, n in thinned(positions)[:, :2])


MAP_SCRIPT = """
(function () {
  const svg = document.getElementById('map');
  const home = svg.getAttribute('viewBox').split(' ').map(Number);
  let view = home.slice();
  const lat0 = Number(svg.dataset.lat), lon0 = Number(svg.dataset.lon);
  const tiles = document.getElementById('tiles');
  const osm = document.getElementById('osm');
  const scale = document.getElementById('scale');
  const R = 6378137, D = Math.PI / 180;
  function toSvg(evt) {
    const p = svg.createSVGPoint(); p.x = evt.clientX; p.y = evt.clientY;
    return p.matrixTransform(svg.getScreenCTM().inverse());
  }
  function lonOf(x, z) { return x / 2 ** z * 360 - 180; }
  function latOf(y, z) {
    const n = Math.PI - 2 * Math.PI * y / 2 ** z;
    return Math.atan(Math.sinh(n)) / D;
  }
  function east(lon) { return (lon - lon0) * D * R * Math.cos(lat0 * D); }
  function south(lat) { return -(lat - lat0) * D * R; }
  function drawTiles() {
    tiles.replaceChildren();
    if (!osm.checked) return;
    const px = svg.clientWidth || 800;
    const metresPerPx = view[2] / px;
    const z = Math.max(1, Math.min(19, Math.round(Math.log2(
      156543.03 * Math.cos(lat0 * D) / metresPerPx))));
    const n = 2 ** z;
    const lonLeft = lon0 + view[0] / (D * R * Math.cos(lat0 * D));
    const lonRight = lon0 + (view[0] + view[2]) / (D * R * Math.cos(lat0 * D));
    const latTop = lat0 - view[1] / (D * R), latBottom = lat0 - (view[1] + view[3]) / (D * R);
    const tx = l => Math.floor((l + 180) / 360 * n);
    const ty = l => Math.floor((1 - Math.log(Math.tan(l * D) + 1 / Math.cos(l * D)) / Math.PI)
      / 2 * n);
    for (let x = tx(lonLeft); x <= tx(lonRight); x++) {
      for (let y = ty(latTop); y <= ty(latBottom); y++) {
        const img = document.createElementNS('http://www.w3.org/2000/svg', 'image');
        const x0 = east(lonOf(x, z)), y0 = south(latOf(y, z));
        img.setAttribute('x', x0); img.setAttribute('y', y0);
        img.setAttribute('width', east(lonOf(x + 1, z)) - x0);
        img.setAttribute('height', south(latOf(y + 1, z)) - y0);
        img.setAttribute('preserveAspectRatio', 'none');
        img.setAttribute('opacity', '0.6');
        img.setAttribute('href', `https://tile.openstreetmap.org/${z}/${x}/${y}.png`);
        tiles.appendChild(img);
      }
    }
  }
  function nice(m) {
    const p = 10 ** Math.floor(Math.log10(m));
    return [1, 2, 5, 10].map(k => k * p).filter(v => v <= m).pop();
  }
  function update() {
    svg.setAttribute('viewBox', view.join(' '));
    const px = svg.clientWidth || 800;
    const metres = nice(view[2] / 4);
    scale.style.width = (metres / view[2] * px) + 'px';
    scale.textContent = metres >= 1000 ? `${metres / 1000} km` : `${metres} m`;
    drawTiles();
  }
  svg.addEventListener('wheel', evt => {
    evt.preventDefault();
    const p = toSvg(evt), k = evt.deltaY > 0 ? 1.25 : 0.8;
    view = [p.x - (p.x - view[0]) * k, p.y - (p.y - view[1]) * k, view[2] * k, view[3] * k];
    update();
  }, {passive: false});
  let drag = null;
  svg.addEventListener('pointerdown', evt => {
    drag = toSvg(evt); svg.setPointerCapture(evt.pointerId);
  });
  svg.addEventListener('pointermove', evt => {
    if (!drag) return;
    const p = toSvg(evt);
    view[0] -= p.x - drag.x; view[1] -= p.y - drag.y;
    svg.setAttribute('viewBox', view.join(' '));
  });
  svg.addEventListener('pointerup', () => { drag = null; update(); });
  document.getElementById('zoom-in').onclick = () => {
    view = [view[0] + view[2] / 4, view[1] + view[3] / 4, view[2] / 2, view[3] / 2]; update();
  };
  document.getElementById('zoom-out').onclick = () => {
    view = [view[0] - view[2] / 2, view[1] - view[3] / 2, view[2] * 2, view[3] * 2]; update();
  };
  document.getElementById('reset').onclick = () => { view = home.slice(); update(); };
  osm.onchange = drawTiles;
  const evaluated = document.getElementById('evaluated');
  if (evaluated) {
    evaluated.onchange = () => document.getElementById('evaluated-tracks')
      .setAttribute('display', evaluated.checked ? 'inline' : 'none');
  }
  update();
})();
"""


def _polyline(positions: np.ndarray, colour: str, width: int, dash: str, title: str) -> str:
    dashes = f" stroke-dasharray='{dash}'" if dash else ""
    return (
        f"<polyline points='{_points(positions)}' fill='none' stroke='{colour}' "
        f"stroke-width='{width}' vector-effect='non-scaling-stroke'{dashes}>"
        f"<title>{html.escape(title)}</title></polyline>"
    )


def map_html(
    tracks: dict[str, Trajectory],
    labels: dict[str, str],
    enu: EnuFrame,
    evaluated: dict[str, Trajectory] | None = None,
) -> str:
    """The map section: SVG tracks (east right, north up, metres), a legend, zoom buttons, a
    scale bar and the opt-in OpenStreetMap background, with its script. ``tracks`` are drawn as
    written; ``evaluated`` (the same pipelines moved to the ground truth for the evaluation),
    when given, is a hidden layer of dotted lines that a box shows, so that the two are never
    mistaken for each other."""
    shown = {name: t for name, t in tracks.items() if len(t) > 1}
    if not shown:
        return "<p>No trajectory to draw.</p>"
    moved = {name: t for name, t in (evaluated or {}).items() if len(t) > 1}
    bounds = [b for t in (*shown.values(), *moved.values()) if (b := _bounds(t)) is not None]
    if not bounds:
        return "<p>No trajectory to draw (no finite position).</p>"
    low = np.min([b[0] for b in bounds], axis=0)
    high = np.max([b[1] for b in bounds], axis=0)
    margin = 0.05 * max(float(np.max(high - low)), 10.0)
    x, y = low[0] - margin, -high[1] - margin
    width, height = high[0] - low[0] + 2 * margin, high[1] - low[1] + 2 * margin
    lat, lon, _ = np.atleast_1d(*ecef_to_geodetic(enu.origin_ecef))
    lines, legend = [], []
    for name, trajectory in shown.items():
        colour = COLOURS.get(name, "#9467bd")
        lines.append(
            _polyline(
                trajectory.positions,
                colour,
                4 if name == TRUTH else 2,
                "6 4" if name == TRUTH else "",
                labels.get(name, name),
            )
        )
        legend.append(
            f"<span class='key'><span class='swatch' style='background:{colour}'></span>"
            f"{html.escape(labels.get(name, name))}</span>"
        )
    if moved:
        lines.append("<g id='evaluated-tracks' display='none'>")
        lines += [
            _polyline(
                trajectory.positions,
                COLOURS.get(name, "#9467bd"),
                2,
                "1 3",
                f"{labels.get(name, name)}, as evaluated (moved to the ground truth at its start)",
            )
            for name, trajectory in moved.items()
        ]
        lines.append("</g>")
    start = next(iter(shown.values())).positions[0]
    lines.append(
        f"<circle cx='{start[0]:.2f}' cy='{-start[1]:.2f}' r='{0.012 * width:.2f}' "
        "fill='black'><title>start</title></circle>"
    )
    legend.append("<span class='key'>● start</span>")
    evaluated_box = (
        " <label><input type='checkbox' id='evaluated'> also the trajectories as evaluated "
        "(dotted: each moved to the ground truth at its start, VO and DR alone also turned to "
        "its heading, as the error table compares them)</label>"
        if moved
        else ""
    )
    return (
        "<div class='map-tools'><button id='zoom-in' type='button'>zoom in</button> "
        "<button id='zoom-out' type='button'>zoom out</button> "
        "<button id='reset' type='button'>reset view</button> "
        "<label><input type='checkbox' id='osm'> OpenStreetMap background "
        "(loads map tiles from tile.openstreetmap.org when ticked; © OpenStreetMap "
        f"contributors)</label>{evaluated_box}</div>"
        f"<svg id='map' viewBox='{x:.2f} {y:.2f} {width:.2f} {height:.2f}' "
        f"data-lat='{float(np.degrees(lat[0])):.8f}' data-lon='{float(np.degrees(lon[0])):.8f}' "
        "preserveAspectRatio='xMidYMid meet' role='img' "
        "aria-label='map of the trajectories'><g id='tiles'></g>" + "".join(lines) + "</svg>"
        "<div class='legend'>"
        + "".join(legend)
        + "<span class='key'>scale: <span id='scale' class='scalebar'></span></span></div>"
        "<p class='note'>East to the right, north up, in metres from the recording's local "
        "origin. Drag to pan, scroll or use the buttons to zoom. The trajectories are drawn as "
        "written (their TUM files, placed by the GNSS positions); the same tracks are in "
        "<code>trajectories.geojson</code> (longitude/latitude) and, as a static picture, in "
        "<code>trajectories.png</code>.</p>"
        f"<script>{MAP_SCRIPT}</script>"
    )
