"""The run report: figures (PNG) and one self-contained HTML page with the summary table."""

from __future__ import annotations

import html
from pathlib import Path

from matplotlib.figure import Figure

from vo_doppler.eval.per_distance import ErrorPerDistance
from vo_doppler.eval.pipelines import PIPELINE_LABELS, PipelineErrors
from vo_doppler.model.trajectory import Trajectory

TABLE_COLUMNS = (
    ("error_per_100m_m", "horizontal error per 100 m, mean [m]", "{:.2f}"),
    ("error_per_100m_max_m", "max [m]", "{:.2f}"),
    ("error_per_100m_3d_m", "3-D error per 100 m [m]", "{:.2f}"),
    ("kitti_translation_pct", "KITTI translation [%]", "{:.2f}"),
    ("heading_rmse_deg", "heading RMSE [deg]", "{:.2f}"),
    ("heading_availability", "heading availability", "{:.0%}"),
    ("final_position_error_m", "final horizontal error [m]", "{:.2f}"),
)


def trajectories_figure(
    path: Path, trajectories: dict[str, Trajectory], truth: Trajectory | None, title: str
) -> None:
    fig = Figure(figsize=(8, 7))
    ax = fig.subplots()
    if truth is not None:
        ax.plot(
            truth.positions[:, 0],
            truth.positions[:, 1],
            "k-",
            lw=2.5,
            alpha=0.35,
            label="ground truth",
        )
    for name, trajectory in trajectories.items():
        ax.plot(
            trajectory.positions[:, 0],
            trajectory.positions[:, 1],
            lw=1.2,
            label=PIPELINE_LABELS.get(name, name),
        )
    first = next(iter(trajectories.values()), None)
    if first is not None and len(first):
        ax.plot(*first.positions[0, :2], "ko", ms=5, label="start")
    ax.set_xlabel("east [m]")
    ax.set_ylabel("north [m]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def error_per_100m_figure(path: Path, per_100m: dict[str, ErrorPerDistance], title: str) -> None:
    fig = Figure(figsize=(9, 4))
    ax = fig.subplots()
    for name, result in per_100m.items():
        ax.plot(
            result.start_distance_m,
            result.errors_m,
            lw=1.2,
            label=f"{PIPELINE_LABELS.get(name, name)} (mean {result.mean_m_per_100m:.2f} m)",
        )
    window = next(iter(per_100m.values())).window_m if per_100m else 100.0
    ax.set_xlabel("start of the window along the path [m]")
    ax.set_ylabel(f"horizontal error after {window:.0f} m [m per 100 m]")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def write_html_report(
    path: Path,
    title: str,
    facts: dict[str, str],
    errors: dict[str, PipelineErrors],
    figures: list[Path],
) -> None:
    """One HTML page: the facts list, the pipelines table (when evaluated) and the figures."""
    parts = [
        "<!doctype html><html><head><meta charset='utf-8'>",
        f"<title>{html.escape(title)}</title>",
        "<style>body{font-family:sans-serif;margin:2em;max-width:70em}"
        "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:4px 8px;"
        "text-align:right}th:first-child,td:first-child{text-align:left}img{max-width:100%}"
        "</style></head><body>",
        f"<h1>{html.escape(title)}</h1><ul>",
    ]
    parts += [f"<li><b>{html.escape(k)}</b>: {html.escape(v)}</li>" for k, v in facts.items()]
    parts.append("</ul>")
    if errors:
        parts.append("<h2>Pipelines against ground truth</h2><table><tr><th>pipeline</th>")
        parts += [f"<th>{html.escape(label)}</th>" for _, label, _ in TABLE_COLUMNS]
        parts.append("</tr>")
        for name, row in errors.items():
            values = row.to_dict()
            cells = "".join(f"<td>{fmt.format(values[key])}</td>" for key, _, fmt in TABLE_COLUMNS)
            parts.append(f"<tr><td>{html.escape(PIPELINE_LABELS.get(name, name))}</td>{cells}</tr>")
        parts.append("</table>")
    parts.append("<h2>Figures</h2>")
    parts += [
        f"<p><img src='{html.escape(f.name)}' alt='{html.escape(f.stem)}'></p>" for f in figures
    ]
    parts.append("</body></html>")
    path.write_text("\n".join(parts))
