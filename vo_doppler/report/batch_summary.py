"""The aggregate of a batch: one row per recording and one overall row, as a typed table (for
CSV and Parquet) and a self-contained HTML page.

Per recording: its status, the exit category and error message of a failure, the wall time,
the run's warnings (how many, and their texts), heading availability (conventional and tightly
coupled, [TK18] sec. 3.2 and 3.5), the calibration at the end of the drive (wheel scale and
gyro bias, [TK18] sec. 3.3–3.4) and, with ground truth, each pipeline's horizontal error per
100 m. Overall: availability weighted by GNSS epochs, error per 100 m weighted by the driven
length (the error of the fleet's kilometres), the median calibration over recordings, the
warnings of all recordings counted.
"""

from __future__ import annotations

import html
from pathlib import Path
from urllib.parse import quote

import numpy as np

from vo_doppler.errors import shown
from vo_doppler.eval.pipelines import PIPELINE_LABELS
from vo_doppler.run import Pipeline

OVERALL = "all recordings"
ERROR_COLUMNS = {p: f"{p}_error_per_100m_m" for p in Pipeline}
AVAILABILITY = ("conventional_heading_availability", "tight_heading_availability")
CALIBRATION = ("final_wheel_scale", "final_gyro_bias_dps")
COLUMNS: dict[str, type] = {
    "recording": str,
    "status": str,
    "exit_category": str,
    "error": str,
    "seconds": float,
    "warnings": int,
    "warning_texts": str,
    "gnss_epochs": int,
    "vo_frames": int,
    **dict.fromkeys(AVAILABILITY, float),
    "tight_heading_used": float,
    **dict.fromkeys(CALIBRATION, float),
    "path_length_m": float,
    **dict.fromkeys(ERROR_COLUMNS.values(), float),
}
"""Column → type of the aggregate table (the CSV and Parquet schema)."""

WARNING_SEPARATOR = " | "
"""Between a recording's warnings in ``warning_texts`` (one CSV cell, no line breaks)."""


def summary_warnings(summary: dict | None) -> list[str]:
    """The warnings of a run's summary (none for a recording without one)."""
    return list((summary or {}).get("warnings") or [])


def warnings_status(status: str, count: int) -> str:
    """A status with its warnings for people: ``done, 2 warnings``; as it is without any."""
    if not count:
        return status
    return f"{status}, {count} warning{'s' if count > 1 else ''}"


def recording_row(
    name: str, status: str, category: str | None, error: str | None, seconds: float, summary
) -> dict:
    """One recording's row from its run summary (``None`` for a failed recording). Besides the
    table's :data:`COLUMNS` it keeps the warnings as a list under ``warning_list`` (for the HTML
    page; the tables join them in ``warning_texts``)."""
    row = {
        "recording": name,
        "status": status,
        "exit_category": category,
        "error": error,
        "seconds": seconds,
    }
    if summary is None:
        return row
    warnings = summary_warnings(summary)
    row["warnings"] = len(warnings)
    row["warning_texts"] = WARNING_SEPARATOR.join(warnings) if warnings else None
    row["warning_list"] = warnings
    for key in ("gnss_epochs", "vo_frames", *AVAILABILITY, "tight_heading_used", *CALIBRATION):
        row[key] = summary.get(key)
    evaluation = summary.get("evaluation") or {}
    for pipeline, column in ERROR_COLUMNS.items():
        if pipeline in evaluation:
            row[column] = evaluation[pipeline]["error_per_100m_m"]
    if evaluation:
        row["path_length_m"] = max(e["path_length_m"] for e in evaluation.values())
    return row


def _weighted_mean(rows: list[dict], column: str, weight: str) -> float | None:
    pairs = [
        (r[column], r[weight])
        for r in rows
        if r.get(column) is not None and np.isfinite(r[column]) and r.get(weight)
    ]
    if not pairs:
        return None
    values, weights = np.array(pairs, dtype=float).T
    return float(np.sum(values * weights) / np.sum(weights))


def _median(rows: list[dict], column: str) -> float | None:
    values = [r[column] for r in rows if r.get(column) is not None]
    return float(np.median(values)) if values else None


def overall_row(rows: list[dict]) -> dict:
    """The fleet's row: counts by status, total time and warnings, epoch-weighted availability,
    the median calibration and the length-weighted error per 100 m of every pipeline."""
    statuses = [r["status"] for r in rows]
    counts = ", ".join(f"{statuses.count(s)} {s}" for s in dict.fromkeys(statuses))
    row = {
        "recording": OVERALL,
        "status": counts,
        "seconds": float(sum(r["seconds"] for r in rows)),
        "warnings": sum(r.get("warnings") or 0 for r in rows),
        "gnss_epochs": sum(r.get("gnss_epochs") or 0 for r in rows),
        "vo_frames": sum(r.get("vo_frames") or 0 for r in rows),
        "path_length_m": sum(r.get("path_length_m") or 0.0 for r in rows),
    }
    for column in (*AVAILABILITY, "tight_heading_used"):
        row[column] = _weighted_mean(rows, column, "gnss_epochs")
    for column in CALIBRATION:
        row[column] = _median(rows, column)
    for column in ERROR_COLUMNS.values():
        row[column] = _weighted_mean(rows, column, "path_length_m")
    return row


HTML_COLUMNS = (
    ("status", "status", "{}"),
    ("seconds", "time [s]", "{:.1f}"),
    ("warnings", "warnings", "{:d}"),
    ("conventional_heading_availability", "conventional heading", "{:.0%}"),
    ("tight_heading_availability", "tightly coupled heading", "{:.0%}"),
    ("final_wheel_scale", "wheel scale", "{:.4f}"),
    ("final_gyro_bias_dps", "gyro bias [deg/s]", "{:+.3f}"),
    ("path_length_m", "driven [m]", "{:.0f}"),
    *(
        (column, f"{PIPELINE_LABELS[p]} [m / 100 m]", "{:.2f}")
        for p, column in ERROR_COLUMNS.items()
    ),
)


def _cell(row: dict, key: str, fmt: str) -> str:
    value = row.get(key)
    return "" if value is None else html.escape(fmt.format(value))


def write_batch_html(path: Path, rows: list[dict], title: str = "vo-doppler batch") -> None:
    """One page: the table (each recording linked to its own report), then the failures with
    their exit category and message. ``rows`` ends with the overall row."""
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'>",
        f"<title>{html.escape(title)}</title>",
        "<style>body{font-family:sans-serif;margin:2em}table{border-collapse:collapse}"
        "td,th{border:1px solid #bbb;padding:4px 8px;text-align:right}"
        "th:first-child,td:first-child{text-align:left}tr.overall{font-weight:bold}</style>",
        f"</head><body><h1>{html.escape(title)}</h1>",
        "<p>Error per 100 m: horizontal, against ground truth (recordings that have one); the "
        "overall row weights it by the driven length and the heading availability by the GNSS "
        "epochs, and gives the median calibration. The warnings of each recording are listed "
        "below the table (and in its report).</p><table><tr><th>recording</th>",
    ]
    parts += [f"<th>{html.escape(label)}</th>" for _, label, _ in HTML_COLUMNS]
    parts.append("</tr>")
    for row in rows:
        name = html.escape(row["recording"])
        overall = row["recording"] == OVERALL
        linked = not overall and row["status"] != "failed"
        href = html.escape(quote(row["recording"]))
        link = f"<a href='{href}/report.html'>{name}</a>" if linked else name
        cells = "".join(f"<td>{_cell(row, key, fmt)}</td>" for key, _, fmt in HTML_COLUMNS)
        parts.append(f"<tr{' class=overall' if overall else ''}><td>{link}</td>{cells}</tr>")
    parts.append("</table>")
    warned = [r for r in rows if r.get("warning_list")]
    if warned:
        parts.append("<h2>Warnings</h2>")
        for r in warned:
            href = html.escape(quote(r["recording"]))
            parts.append(
                f"<p><a href='{href}/report.html'>{html.escape(r['recording'])}</a>:</p><ul>"
            )
            parts += [f"<li>{html.escape(text)}</li>" for text in r["warning_list"]]
            parts.append("</ul>")
    failures = [r for r in rows if r["status"] == "failed"]
    if failures:
        parts.append("<h2>Failed recordings</h2><ul>")
        parts += [
            f"<li><b>{html.escape(r['recording'])}</b> ({html.escape(r['exit_category'])}): "
            f"{html.escape(r['error'])}</li>"
            for r in failures
        ]
        parts.append("</ul>")
    parts.append("</body></html>")
    path.write_text(shown("\n".join(parts)), encoding="utf-8")
