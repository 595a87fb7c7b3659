"""Figures for people: top views of trajectories (degrees and metres, never radians)."""

from __future__ import annotations

from pathlib import Path

from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report.figure import new_figure, tight_layout

AXIS_INDEX = {"x": 0, "y": 1, "z": 2}


def plot_top_view(
    trajectories: dict[str, Trajectory],
    path: str | Path,
    plane: tuple[str, str] = ("x", "y"),
    title: str = "",
    unit: str = "m",
) -> None:
    """Plot each trajectory's positions on ``plane`` (horizontal, vertical axis names)."""
    h, v = AXIS_INDEX[plane[0]], AXIS_INDEX[plane[1]]
    fig = new_figure(figsize=(7, 6), dpi=110)
    ax = fig.subplots()
    for label, trajectory in trajectories.items():
        if not len(trajectory):
            continue
        ax.plot(trajectory.positions[:, h], trajectory.positions[:, v], label=label, lw=1.5)
        ax.plot(trajectory.positions[0, h], trajectory.positions[0, v], "ko", ms=4)
        ax.plot(trajectory.positions[-1, h], trajectory.positions[-1, v], "k^", ms=5)
    ax.set_xlabel(f"{plane[0]} [{unit}]")
    ax.set_ylabel(f"{plane[1]} [{unit}]")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(alpha=0.3)
    ax.legend()
    if title:
        ax.set_title(title)
    tight_layout(fig)
    fig.savefig(path)
