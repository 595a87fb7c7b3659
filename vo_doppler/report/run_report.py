"""The run report: one self-contained HTML page (figures embedded as data URIs, the map as
inline SVG; readable offline) and the figures as PNG files beside it.

The page says what the data is, how it was run (command, version, configuration), the result
in one sentence, the pipelines' errors with units and definitions, a zoomable map, the error
over distance, the heading error over time, the GNSS heading figure and the largest errors of
the tightly coupled heading on epochs the correction used.
"""

from __future__ import annotations

import base64
import html
import io
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from vo_doppler.errors import shown
from vo_doppler.eval.per_distance import MIN_PATH_M, ErrorPerDistance
from vo_doppler.eval.pipelines import (
    PIPELINE_LABELS,
    UNCORRECTED,
    AbsolutePositionErrors,
    PipelineErrors,
)
from vo_doppler.geo import EnuFrame, wrap_angle
from vo_doppler.gnss.doppler_velocity import MIN_SATELLITES
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report.decimation import drawn_line, drawn_rows
from vo_doppler.report.figure import new_figure, tight_layout
from vo_doppler.report.provenance import DataDescription
from vo_doppler.report.trajectory_map import COLOURS, TRUTH, map_html

if TYPE_CHECKING:
    from matplotlib.figure import Figure

TABLE_COLUMNS = (
    ("error_per_100m_m", "error per 100 m, mean [m]", "{:.2f}"),
    ("error_per_100m_max_m", "error per 100 m, max [m]", "{:.2f}"),
    ("error_per_100m_3d_m", "3-D error per 100 m, mean [m]", "{:.2f}"),
    ("kitti_translation_pct", "KITTI translation error [%]", "{:.2f}"),
    ("heading_rmse_deg", "heading RMSE [deg]", "{:.2f}"),
    ("heading_availability", "absolute heading used [% of the GNSS epochs it could use]", "{:.0%}"),
    ("final_position_error_m", "final horizontal error [m]", "{:.2f}"),
)
"""(key of :class:`PipelineErrors`, column title with unit, format): the report's table and
the terminal's share it (see :func:`table_cell`)."""

ABSOLUTE_COLUMNS = (
    ("start_horizontal_m", "start, horizontal [m]"),
    ("start_vertical_m", "start, vertical [m]"),
    ("median_horizontal_m", "median, horizontal [m]"),
    ("median_vertical_m", "median, vertical [m]"),
    ("end_horizontal_m", "end, horizontal [m]"),
    ("end_vertical_m", "end, vertical [m]"),
)
"""(key of :class:`AbsolutePositionErrors`, column title with unit) of the report's table of
the trajectories' positions as written against the ground truth."""

GLOSSARY = (
    (
        "error per 100 m",
        "For every 100 m stretch of the ground-truth path (one starting every metre), the "
        "horizontal distance between where the estimate moved and where the vehicle moved over "
        "that stretch; the mean and the largest over all stretches, in metres. 1 m per 100 m "
        "is a 1 % drift. On a path shorter than 100 m the whole path is scaled to 100 m; on one "
        f"shorter than {MIN_PATH_M:.0f} m it is not available (—).",
    ),
    ("3-D error per 100 m", "The same with the height difference included."),
    (
        "KITTI translation error",
        "The KITTI odometry benchmark's relative error: over segments of 100, 200, … 800 m "
        "(those that fit the path) from every pose, the translation error of the relative pose "
        "in % of the segment length, averaged.",
    ),
    (
        "heading RMSE",
        "Root mean square of the yaw difference between the pipeline's vehicle poses and the "
        "ground truth at every pose, in degrees.",
    ),
    (
        "absolute heading used",
        "Share of the GNSS epochs where the pipeline could use an absolute (GNSS) heading whose "
        "heading corrected it: the epochs inside its trajectory's time span that the vehicle "
        "signals (wheel speed and yaw rate) cover; the epochs without them count in no share. "
        "“—”: the pipeline uses no absolute heading (VO or dead reckoning alone).",
    ),
    (
        "available",
        "The estimator produced a heading at the epoch. Conventional: a Doppler velocity "
        f"solution that passed its tests ({MIN_SATELLITES + 1} or more satellites after fault "
        "exclusion, one more than the unknowns so that the χ² test can check them) while "
        "moving. Tightly coupled: the [TK18] window "
        "solver (Doppler of any number of satellites + gyro + wheel speed over a 2 s window) "
        "returned a heading.",
    ),
    (
        "reliable",
        "The tightly coupled heading agrees with its neighbours propagated by the gyro.",
    ),
    (
        "used by the correction",
        "Available, reliable and with a standard deviation σ below the configured limit: only "
        "these headings correct the VO. The terminal summary and the table use this same word.",
    ),
    (
        "σ (sigma)",
        "The standard deviation the estimator states for its heading; the heading figure "
        "shades ±2σ.",
    ),
    (
        "final horizontal error",
        "Horizontal distance between the last pose and the ground truth at that time, the "
        "trajectory moved to the truth at its start as for every figure of that table (the "
        "positions as written are in the next table).",
    ),
    (
        "VO alone / + GPS",
        "VO alone: monocular visual odometry, metric scale from the calibrated wheel speed, "
        "turned to the absolute headings of its first seconds and never corrected again. VO + GPS "
        "(conventional): VO heading corrected by the heading of the Doppler velocity. VO + GPS "
        "(tightly coupled): corrected by the [TK18] tightly coupled Doppler heading.",
    ),
    (
        "wheel + gyro DR alone / + GPS",
        "Dead reckoning of the wheel speed and the yaw-rate gyro (calibrated by the GNSS Doppler "
        "where the recording has GNSS), turned to the absolute headings of its first seconds "
        "(without GNSS: started facing east); + GPS: corrected by the conventional or the "
        "tightly coupled heading as the VO is.",
    ),
)

GLOSSARY_NEEDS = {
    "absolute heading used": "gnss",
    "available": "gnss",
    "reliable": "gnss",
    "used by the correction": "gnss",
    "σ (sigma)": "gnss",
    "VO alone / + GPS": "camera",
}
"""The definitions of what runs only with a sensor: left out of the report of a recording
without it (:func:`glossary`)."""


def glossary(camera: bool = True, gnss: bool = True) -> list[tuple[str, str]]:
    """The definitions the report of a recording with (or without) a ``camera`` and ``gnss``
    needs: those of :data:`GLOSSARY` whose pipelines or figures it shows."""
    present = {"camera": camera, "gnss": gnss}
    return [(k, v) for k, v in GLOSSARY if present.get(GLOSSARY_NEEDS.get(k, ""), True)]


WORST_EPOCHS = 8
WORST_SEPARATION_S = 1.0
"""The worst-errors list keeps one epoch per second: neighbours of a listed epoch are skipped."""


def label(name: str) -> str:
    return PIPELINE_LABELS.get(name, name)


def table_cell(name: str, key: str, value: float, fmt: str) -> str:
    """A table cell: "—" where the quantity does not apply (an uncorrected pipeline's heading
    use) or is unknown (NaN), else ``fmt``."""
    if key == "heading_availability" and name in UNCORRECTED:
        return "—"
    return number_or_dash(value, fmt)


def number_or_dash(value: float | None, fmt: str) -> str:
    """``fmt.format(value)``, or "—" for a figure that is not available (None or NaN)."""
    if value is None or not np.isfinite(value):
        return "—"
    return fmt.format(value)


def png_data_uri(fig: Figure, path: Path | None = None) -> str:
    """The figure as a PNG data URI (also written to ``path`` when given)."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    data = buffer.getvalue()
    if path is not None:
        path.write_bytes(data)
    return "data:image/png;base64," + base64.b64encode(data).decode("ascii")


def trajectories_figure(
    path: Path, trajectories: dict[str, Trajectory], truth: Trajectory | None, title: str
) -> None:
    """Top view (east, north in metres) of every pipeline's trajectory and the ground truth."""
    fig = new_figure(figsize=(8, 7))
    ax = fig.subplots()
    if truth is not None:
        ax.plot(*_drawn_plane(truth), "k-", lw=2.5, alpha=0.35, label="ground truth")
    for name, trajectory in trajectories.items():
        ax.plot(*_drawn_plane(trajectory), lw=1.2, c=COLOURS.get(name), label=label(name))
    first = next(iter(trajectories.values()), None)
    if first is not None and len(first):
        ax.plot(*first.positions[0, :2], "ko", ms=5, label="start")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    tight_layout(fig)
    fig.savefig(path, dpi=110)


def _drawn_plane(trajectory: Trajectory) -> np.ndarray:
    """East and north (2, N) of the poses the top view draws (:func:`drawn_rows`)."""
    plane = trajectory.positions[:, :2]
    return plane[drawn_rows(plane)].T


def _mean_text(mean_m: float | None) -> str:
    return "path too short: not available" if mean_m is None else f"mean {mean_m:.2f} m"


def build_error_per_100m_figure(per_100m: dict[str, ErrorPerDistance], title: str) -> Figure:
    """Per pipeline, the error of each 100 m stretch against where the stretch starts."""
    fig = new_figure(figsize=(9, 3.8))
    ax = fig.subplots()
    for name, result in per_100m.items():
        ax.plot(
            *drawn_line(result.start_distance_m, result.errors_m),
            lw=1.4,
            c=COLOURS.get(name),
            label=f"{label(name)} ({_mean_text(result.mean_m_per_100m)})",
        )
    window = next(iter(per_100m.values())).window_m if per_100m else 100.0
    ax.set_xlabel("distance along the ground-truth path where the stretch starts [m]")
    ax.set_ylabel(f"error after {window:.0f} m\n[m per 100 m]")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    tight_layout(fig)
    return fig


def error_per_100m_figure(path: Path, per_100m: dict[str, ErrorPerDistance], title: str) -> None:
    build_error_per_100m_figure(per_100m, title).savefig(path, dpi=110)


SYMLOG_LINEAR_DEG = 1.0


def heading_error_over_time(trajectory: Trajectory, truth: Trajectory) -> np.ndarray:
    """Yaw of each pose minus the ground truth's at its time (rad, wrapped; NaN outside)."""
    return wrap_angle(trajectory.yaw() - truth.yaw_at(trajectory.t))


def build_heading_error_figure(
    trajectories: dict[str, Trajectory], truth: Trajectory, t0: float, title: str
) -> Figure:
    """Per pipeline, the vehicle heading error (deg) over time; when one pipeline's errors
    reach more than ten times another's, the axis is linear within ±1° and logarithmic
    beyond, so that the small errors stay readable beside the large ones."""
    fig = new_figure(figsize=(9, 3.8))
    ax = fig.subplots()
    spread = []
    for name, trajectory in trajectories.items():
        error = np.degrees(heading_error_over_time(trajectory, truth))
        ax.plot(
            *drawn_line(trajectory.t - t0, error), lw=1.2, c=COLOURS.get(name), label=label(name)
        )
        if np.isfinite(error).any():
            spread.append(np.nanpercentile(np.abs(error), 99))
    ax.axhline(0.0, c="k", lw=0.8)
    ax.set_xlabel("time since first GNSS epoch [s]")
    symlog = len(spread) > 1 and max(spread) > 10.0 * max(min(spread), 0.1)
    if symlog:
        ax.set_yscale("symlog", linthresh=SYMLOG_LINEAR_DEG)
        note = f"axis linear within ±{SYMLOG_LINEAR_DEG:g}°, logarithmic beyond"
        ax.text(0.01, 0.03, note, transform=ax.transAxes, fontsize=7, color="0.3")
    ax.set_ylabel("heading error\n(estimate − truth) [deg]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    tight_layout(fig)
    return fig


@dataclass
class WorstEpoch:
    time_s: float
    """Since the first GNSS epoch."""
    error_deg: float
    sigma_deg: float
    satellites: int
    doppler_rows: int
    """Doppler measurements in the solver's window."""
    used: bool
    """The correction used the heading (σ under the limit); every listed epoch is reliable."""


def worst_reliable_tight_errors(
    table: HeadingTable,
    used: np.ndarray,
    truth_yaw: np.ndarray,
    count: int = WORST_EPOCHS,
    separation_s: float = WORST_SEPARATION_S,
) -> list[WorstEpoch]:
    """The largest |tightly coupled heading − truth| on epochs flagged reliable, largest first,
    at most one per ``separation_s`` (the neighbours of a listed epoch are skipped), each with
    whether the correction used it."""
    error = np.abs(wrap_angle(table.yaw_tc - truth_yaw))
    candidates = np.flatnonzero(np.asarray(table.tc_reliable, bool) & np.isfinite(error))
    picked: list[int] = []
    for k in candidates[np.argsort(-error[candidates], kind="stable")]:
        if all(abs(table.t[k] - table.t[j]) >= separation_s for j in picked):
            picked.append(int(k))
        if len(picked) == count:
            break
    return [
        WorstEpoch(
            float(table.t[k] - table.t[0]),
            float(np.degrees(error[k])),
            float(np.degrees(table.sigma_tc[k])),
            int(table.n_sat_epoch[k]),
            int(table.n_obs_window[k]),
            bool(used[k]),
        )
        for k in picked
    ]


def headline(
    errors: dict[str, PipelineErrors],
    used_fraction: float | None,
    truth_unused: bool = False,
    covered_epochs: int | None = None,
) -> str:
    """The result in one sentence: the VO's error per 100 m with the tightly coupled heading
    against the best of the VO's other pipelines (alone, with the conventional heading), or the
    wheel + gyro dead reckoning's without a camera (:func:`tight_verdict`: said plainly when the
    tightly coupled heading did not help), as the run measured them (or, without ground truth
    or with one that could not be used (``truth_unused``), how often it was used: the share
    ``used_fraction`` of the ``covered_epochs`` GNSS epochs with vehicle signals (of every GNSS
    epoch when None); ``used_fraction`` None: the recording had no GNSS)."""
    epochs = (
        "GNSS epochs"
        if covered_epochs is None
        else f"{covered_epochs} GNSS epochs with vehicle signals (wheel speed and yaw rate)"
    )
    used = (
        f"The tightly coupled heading was used by the correction at {used_fraction:.0%} of the "
        f"{epochs}."
        if used_fraction is not None
        else "No GNSS: only the VO and the dead reckoning ran, the GNSS pipelines were not run."
    )
    if truth_unused:
        return (
            "The ground truth could not be used (see the warnings): this report shows the "
            f"trajectories and headings but cannot say how accurate they are. {used}"
        )
    if not errors:
        return (
            "No ground truth: this report shows the trajectories and headings but cannot say "
            f"how accurate they are. {used}"
        )
    if any(e.error_per_100m_m is None for e in errors.values()):
        return (
            "The ground-truth path is too short for errors per distance (see the warnings); "
            f"the table shows the heading errors. {used}"
        )
    base = "vo" if any(name.startswith("vo") for name in errors) else "dr"
    tight_name = f"{base}_gps_tc"
    others = [name for name in (base, f"{base}_gps_conv") if name in errors]
    if tight_name not in errors or not others:
        shown = "; ".join(f"{label(n)} {e.error_per_100m_m:.2f}" for n, e in errors.items())
        return f"Error per 100 m (m): {shown}."
    camera = "" if base == "vo" else "No camera: "
    return camera + tight_verdict(
        "the VO" if base == "vo" else "the wheel + gyro dead reckoning",
        errors[tight_name].error_per_100m_m,
        {OTHER_WORDS[name.removeprefix(base)]: errors[name].error_per_100m_m for name in others},
    )


OTHER_WORDS = {"": "alone", "_gps_conv": "with the conventional Doppler heading"}
"""How the headline names a pipeline beside the tightly coupled one, by its name's suffix."""


def tight_verdict(subject: str, tight: float, others: dict[str, float]) -> str:
    """Whether the tightly coupled heading helped ``subject`` (e.g. "the VO"), in one sentence:
    its error per 100 m (m) ``tight`` against the best of ``others`` (how the pipeline is
    named → its error), compared as shown (two decimals): lower than the best other is a help,
    equal or higher is said plainly not to be."""
    best = min(others, key=others.__getitem__)
    rest = "".join(
        f"; {subject} {words}: {value:.2f}" for words, value in others.items() if words != best
    )
    if round(tight, 2) < round(others[best], 2):
        ratio = f", {others[best] / tight:.1f}× less than" if tight > 0 else ", below"
        return (
            f"The tightly coupled Doppler heading gave {subject} its lowest error: {tight:.2f} m "
            f"per 100 m{ratio} the best other, {subject} {best} ({others[best]:.2f}){rest}."
        )
    return (
        f"The tightly coupled Doppler heading did not help on this drive: {subject} {best} did "
        f"as well or better, {others[best]:.2f} m per 100 m against {tight:.2f} with the "
        f"tightly coupled heading{rest}."
    )


@dataclass
class RunReport:
    """Everything the page shows. ``errors``/``per_100m`` are empty without ground truth."""

    title: str
    headline: str
    data: DataDescription
    command: str
    version: str
    settings: list[tuple[str, str]]
    config_rows: list[tuple[str, str]]
    facts: dict[str, str]
    tracks: dict[str, Trajectory]
    """Trajectories as written (and the ground truth under ``"truth"``), ENU metres."""
    enu: EnuFrame
    heading_figure: str
    """Data URI of the GNSS heading figure ("" without GNSS: the section is left out)."""
    errors: dict[str, PipelineErrors] = field(default_factory=dict)
    absolute: dict[str, AbsolutePositionErrors] = field(default_factory=dict)
    """Per pipeline, its position as written against the ground truth."""
    evaluated_tracks: dict[str, Trajectory] = field(default_factory=dict)
    """The trajectories as evaluated (moved to the truth at their start): the map's optional
    layer."""
    segment_note: str = ""
    error_figure: str | None = None
    heading_error_figure: str | None = None
    worst: list[WorstEpoch] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    """What the input checks found (time order, clocks, origin) and what the evaluation could
    not do (ground truth covering part of the drive), shown under the data."""
    definitions: list[tuple[str, str]] = field(default_factory=glossary)
    """The definitions shown (:func:`glossary`: only those of what ran)."""
    placement_heights: str = ""
    """What placed the trajectories' heights (``AntennaTrack.height_source``)."""


STYLE = (
    "body{font-family:system-ui,sans-serif;margin:1.5em auto;max-width:72em;padding:0 1em;"
    "color:#222;line-height:1.4}h1{margin-bottom:.2em}.badge{display:inline-block;"
    "padding:2px 8px;border-radius:4px;font-size:.8em;vertical-align:middle;margin-left:.5em}"
    ".synthetic{background:#fde68a}.recorded{background:#bbf7d0}"
    ".headline{font-size:1.2em;background:#f1f5f9;border-left:4px solid #d62728;padding:.6em 1em}"
    "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #bbb;padding:3px 8px;"
    "text-align:right}th{background:#f1f5f9}th:first-child,td:first-child{text-align:left}"
    "td.text{text-align:left}img{max-width:100%}dt{font-weight:bold}dd{margin:0 0 .5em 1.5em}"
    "code{background:#f1f5f9;padding:1px 4px;word-break:break-all}"
    "#map{width:100%;height:32em;border:1px solid #bbb;background:#fafafa;cursor:grab;"
    "touch-action:none}.legend .key{margin-right:1.2em;white-space:nowrap}"
    ".swatch{display:inline-block;width:1.6em;height:.35em;margin-right:.4em;"
    "vertical-align:middle}.scalebar{display:inline-block;border:2px solid #222;"
    "border-top:none;height:.5em;text-align:center;font-size:.8em;line-height:.4em}"
    ".note{color:#555;font-size:.9em}.map-tools{margin:.4em 0}"
)


def _definitions(rows: list[tuple[str, str]]) -> str:
    return (
        "<table>"
        + "".join(
            f"<tr><th>{html.escape(k)}</th><td class='text'>{html.escape(v)}</td></tr>"
            for k, v in rows
        )
        + "</table>"
    )


def _errors_table(report: RunReport) -> str:
    head = "".join(f"<th>{html.escape(title)}</th>" for _, title, _ in TABLE_COLUMNS)
    rows = []
    for name, row in report.errors.items():
        values = row.to_dict()
        cells = "".join(
            f"<td>{table_cell(name, key, values[key], fmt)}</td>" for key, _, fmt in TABLE_COLUMNS
        )
        rows.append(f"<tr><td>{html.escape(label(name))}</td>{cells}</tr>")
    return f"<table><tr><th>pipeline</th>{head}</tr>{''.join(rows)}</table>"


def _absolute_table(absolute: dict[str, AbsolutePositionErrors]) -> str:
    head = "".join(f"<th>{html.escape(title)}</th>" for _, title in ABSOLUTE_COLUMNS)
    rows = []
    for name, row in absolute.items():
        values = row.to_dict()
        cells = "".join(
            f"<td>{number_or_dash(values[key], '{:.2f}')}</td>" for key, _ in ABSOLUTE_COLUMNS
        )
        rows.append(f"<tr><td>{html.escape(label(name))}</td>{cells}</tr>")
    return f"<table><tr><th>pipeline</th>{head}</tr>{''.join(rows)}</table>"


def _worst_table(worst: list[WorstEpoch]) -> str:
    if not worst:
        return "<p>No epoch flagged reliable has a known error.</p>"
    rows = "".join(
        f"<tr><td>{w.time_s:.2f}</td><td>{w.error_deg:.1f}</td><td>{w.sigma_deg:.2f}</td>"
        f"<td>{w.error_deg / w.sigma_deg:.1f}</td><td>{'yes' if w.used else 'no (σ too large)'}"
        f"</td><td>{w.satellites}</td><td>{w.doppler_rows}</td></tr>"
        for w in worst
    )
    return (
        "<table><tr><th>time since first GNSS epoch [s]</th><th>|heading error| [deg]</th>"
        "<th>stated σ [deg]</th><th>error / σ</th><th>used by the correction</th>"
        "<th>satellites at the epoch</th>"
        f"<th>Doppler rows in the solver's window</th></tr>{rows}</table>"
    )


def render(report: RunReport) -> str:
    """The HTML page of ``report``."""
    data = report.data
    kind = data.kind
    distance = (
        f"{data.distance_m:.0f} m (from the {data.distance_source})"
        if data.distance_m is not None
        else "unknown"
    )
    about = [
        ("data", data.origin),
        ("sensors", "; ".join(data.sensors)),
        ("duration", f"{data.duration_s:.1f} s (span covered by every sensor)"),
        ("distance driven", distance),
    ]
    parts = [
        "<!doctype html><html lang='en'><head><meta charset='utf-8'>",
        "<meta name='viewport' content='width=device-width, initial-scale=1'>",
        f"<title>{html.escape(report.title)}</title><style>{STYLE}</style></head><body>",
        f"<h1>{html.escape(report.title)}"
        + (f"<span class='badge {kind}'>{kind} data</span>" if kind else "")
        + "</h1>",
        f"<p class='headline'>{html.escape(report.headline)}</p>",
        "<h2>The data</h2>",
        _definitions(about),
        *(
            ["<p>Warnings:</p><ul>"]
            + [f"<li>{html.escape(w)}</li>" for w in report.warnings]
            + ["</ul>"]
            if report.warnings
            else []
        ),
        "<h2>How it was run</h2>",
        f"<p>Command: <code>{html.escape(report.command)}</code><br>"
        f"Version: {html.escape(report.version)}</p>",
        _definitions(report.settings),
        "<details><summary>Full configuration (RunConfig; angles in degrees, everything else "
        "in SI units; the settings of stages that did not run left out)</summary>",
        _definitions(report.config_rows),
        "</details>",
    ]
    if report.errors:
        parts += [
            "<h2>Pipelines against ground truth</h2>",
            "<p class='note'>Every trajectory is evaluated over the time the ground truth "
            "covers and starts there at the ground truth's position; the VO and dead reckoning "
            "alone are also turned to the truth's heading there. Definitions below the "
            f"figures. {html.escape(report.segment_note)}</p>",
            _errors_table(report),
        ]
    if report.absolute:
        parts += [
            "<h2>Positions against ground truth, as written</h2>",
            "<p class='note'>Where each trajectory is, as in its TUM file and on the map (placed "
            "by the GNSS single-point positions), against the ground truth at the same time: "
            "horizontal distance and height difference (absolute) at its first and last pose "
            "inside the truth's time span, and the medians over all of them. The table above "
            "moves each trajectory to the truth first and so leaves this offset out."
            + (
                f" Heights placed by {html.escape(report.placement_heights)}."
                if report.placement_heights
                else ""
            )
            + "</p>",
            _absolute_table(report.absolute),
        ]
    parts += [
        "<h2>Map</h2>",
        map_html(report.tracks, TRACK_LABELS, report.enu, report.evaluated_tracks),
    ]
    if report.error_figure is not None:
        parts += [
            "<h2>Error over distance</h2>",
            f"<img alt='error per 100 m along the path' src='{report.error_figure}'>",
        ]
    if report.heading_error_figure is not None:
        parts += [
            "<h2>Heading error over time</h2>",
            f"<img alt='heading error of each pipeline' src='{report.heading_error_figure}'>",
        ]
    if report.heading_figure:  # empty without GNSS
        parts += [
            "<h2>GNSS headings</h2>",
            "<p class='note'>Satellites per epoch; when the conventional and the tightly coupled "
            "heading were available and when the tightly coupled one was used; the headings as "
            "course (clockwise from north, unwrapped: no jump at 0/360°) with the tightly coupled "
            "heading's ±2σ band; with ground truth, their errors.</p>",
            f"<img alt='GNSS heading figure' src='{report.heading_figure}'>",
        ]
    if report.errors and report.heading_figure:
        parts += [
            "<h2>Largest tightly coupled heading errors on epochs flagged reliable</h2>",
            "<p class='note'>Largest error against ground truth first, at most one epoch per "
            "second. An error of many σ on a used epoch misleads the correction; on an unused one "
            "the σ limit kept it out.</p>",
            _worst_table(report.worst),
        ]
    parts += [
        "<h2>Run figures</h2>",
        _definitions(list(report.facts.items())),
        "<h2>Definitions</h2><dl>",
        *(f"<dt>{html.escape(k)}</dt><dd>{html.escape(v)}</dd>" for k, v in report.definitions),
        "</dl><p class='note'>[TK18]: Takeyama &amp; Kojima (2018), the tightly coupled Doppler "
        "heading this toolkit implements (see docs/design.md).</p>",
        "</body></html>",
    ]
    return "\n".join(parts)


TRACK_LABELS = {TRUTH: "ground truth", **PIPELINE_LABELS}


def write_run_report(path: Path, report: RunReport) -> None:
    """The report as UTF-8 HTML; a path in it that is not UTF-8 (in a warning, the command
    line) with its bytes as ``\\xff`` escapes (:func:`~vo_doppler.errors.shown`)."""
    path.write_text(shown(render(report)), encoding="utf-8")
