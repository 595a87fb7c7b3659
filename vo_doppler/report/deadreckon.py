"""Files of ``vo-doppler deadreckon``: TUM trajectory, GeoJSON, drift-table CSV, summary JSON,
and the map and Allan-deviation figures (matplotlib Figure objects, rendered by Agg)."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from vo_doppler.geo import EnuFrame, ecef_to_geodetic
from vo_doppler.io.output_folder import open_output_folder
from vo_doppler.io.trajectory import write_tum
from vo_doppler.lowcost.drift import DriftRow
from vo_doppler.lowcost.pipeline import DeadReckonResult
from vo_doppler.report.figure import new_figure
from vo_doppler.report.json_text import json_text

DRIFT_COLUMNS = (
    "variant",
    "drift_deg_per_min",
    "final_heading_error_deg",
    "loop_gap_m",
    "loop_gap_percent",
    "end_error_m",
    "end_error_percent",
    "path_length_m",
)
"""The loop gap is NaN on a route that does not close (``lowcost.drift.route_closes``); the end
error is the distance from the reconstructed GPS track's end."""


def enu_to_lonlat(frame: EnuFrame, east: np.ndarray, north: np.ndarray) -> np.ndarray:
    """(N, 2) longitude/latitude in degrees (GeoJSON order) of ENU points at height 0."""
    ecef = frame.enu_to_ecef(np.column_stack([east, north, np.zeros(len(east))]))
    lat, lon, _ = ecef_to_geodetic(ecef)
    return np.column_stack([np.degrees(lon), np.degrees(lat)])


def geojson(result: DeadReckonResult) -> dict:
    """A FeatureCollection: the dead-reckoned line, the reconstructed GPS line, start and end."""
    frame = result.prepared.frame
    dr = result.selected_trajectory
    line = enu_to_lonlat(frame, dr.east, dr.north)
    gps = enu_to_lonlat(frame, result.prepared.track_enu[:, 0], result.prepared.track_enu[:, 1])

    def feature(kind, coordinates, **properties):
        geometry = {"type": kind, "coordinates": np.round(coordinates, 9).tolist()}
        return {"type": "Feature", "geometry": geometry, "properties": properties}

    return {
        "type": "FeatureCollection",
        "features": [
            feature("LineString", line, name="dead reckoning", variant=result.selected),
            feature("LineString", gps, name="reconstructed GPS track"),
            feature("Point", line[0], name="start", t=float(dr.t[0])),
            feature("Point", line[-1], name="end", t=float(dr.t[-1])),
        ],
    }


def drift_table_rows(rows: list[DriftRow]) -> list[list]:
    return [
        [
            row.variant,
            round(row.drift_deg_per_min, 6),
            round(row.final_heading_error_deg, 6),
            round(row.gap.gap_m, 4),
            round(row.gap.percent, 4),
            round(row.gap.end_error_m, 4),
            round(row.gap.end_error_percent, 4),
            round(row.gap.length_m, 3),
        ]
        for row in rows
    ]


def summary(result: DeadReckonResult) -> dict:
    """Choices and counts of one run, in degrees and deg/s for people."""
    rates, prepared, model = result.rates, result.prepared, result.model
    return {
        "k_used": model.k,
        "k_choices": {
            c.method: {"k": c.k, "clipped": c.clipped, "note": c.note}
            for c in model.k_choices.as_list()
        },
        "tau_s": model.tau,
        "eps0_deg_per_s": {name: float(np.degrees(v)) for name, v in model.eps0.items()},
        "threshold_deg_per_s": float(np.degrees(model.h)),
        "standstill": list(prepared.standstill),
        "standstill_is_straight_driving": not result.config.window_is_standstill,
        "standstills": [list(iv) for iv in prepared.standstills],
        "reference": result.reference_source,
        "initial_heading": (
            None if result.initial_heading is None else result.initial_heading.to_dict()
        ),
        "selected_variant": result.selected,
        "route_closes": bool(result.rows[0].gap.closed) if result.rows else None,
        "origin_lat_lon_deg": [
            float(np.degrees(prepared.frame.lat_rad)),
            float(np.degrees(prepared.frame.lon_rad)),
        ],
        "gyro1": vars(rates.report1),
        "gyro2": vars(rates.report2),
        "gps": vars(prepared.report),
        "gps_kept_fixes": len(prepared.track.kept),
    }


def write_map_figure(path: Path, result: DeadReckonResult) -> None:
    prepared = result.prepared
    fig = new_figure(figsize=(7, 7))
    ax = fig.subplots()
    ax.plot(*prepared.raw_enu.T, ".", ms=2, color="0.6", label="GPS fixes")
    ax.plot(*prepared.track_enu.T, "--", lw=1, color="0.2", label="reconstructed GPS")
    for name, dr in result.trajectories.items():
        if name.startswith("combined"):
            ax.plot(
                dr.east, dr.north, lw=1.5 if name == result.selected else 0.7, label=f"DR: {name}"
            )
    dr = result.selected_trajectory
    ax.plot(dr.east[0], dr.north[0], "o", ms=9, color="tab:blue", label="start")
    ax.plot(dr.east[-1], dr.north[-1], "s", ms=9, color="tab:red", label="end")
    ax.set(xlabel="east (m)", ylabel="north (m)", aspect="equal", title="Dead reckoning")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=7)
    fig.savefig(path, dpi=120, bbox_inches="tight")


def write_allan_figure(path: Path, result: DeadReckonResult) -> None:
    fig = new_figure(figsize=(7, 5))
    ax = fig.subplots()
    for name, allan in result.model.allan.items():
        ax.loglog(allan.taus, np.degrees(allan.adev), label=name)
    ax.axvline(result.model.tau, color="k", ls="--", lw=1, label=f"τ = {result.model.tau:.3g} s")
    ax.set(
        xlabel="averaging time τ (s)",
        ylabel="Allan deviation (deg/s)",
        title="Overlapping Allan deviation over the standstill",
    )
    ax.grid(True, which="both", lw=0.3)
    ax.legend()
    fig.savefig(path, dpi=120, bbox_inches="tight")


def output_files(folder: str | Path) -> dict[str, Path]:
    """The files :func:`write_outputs` writes into ``folder``, by name."""
    folder = Path(folder)
    return {
        "trajectory": folder / "trajectory.tum",
        "geojson": folder / "trajectory.geojson",
        "drift_table": folder / "drift_table.csv",
        "summary": folder / "deadreckon_summary.json",
        "map": folder / "map.png",
        "allan": folder / "allan_deviation.png",
    }


def write_outputs(folder: str | Path, result: DeadReckonResult) -> dict[str, Path]:
    """Write every output file into ``folder`` (created) and return their paths by name."""
    paths = output_files(open_output_folder(folder, "deadreckon"))
    write_tum(paths["trajectory"], result.selected_trajectory.trajectory())
    paths["geojson"].write_text(json_text(geojson(result)))
    with paths["drift_table"].open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(DRIFT_COLUMNS)
        writer.writerows(drift_table_rows(result.rows))
    paths["summary"].write_text(json_text(summary(result), indent=2, default=str))
    write_map_figure(paths["map"], result)
    write_allan_figure(paths["allan"], result)
    return paths
