"""Figures of a heading run: satellites per epoch with heading availability (conventional vs
tightly coupled), the headings as course, and the heading error when ground truth is given."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from vo_doppler.geo import wrap_angle
from vo_doppler.model.heading import HeadingTable


def heading_figure(
    path: str | Path, table: HeadingTable, truth_yaw: np.ndarray | None = None, title: str = ""
) -> None:
    """Write the PNG; ``truth_yaw`` (rad, per epoch, NaN where unknown) adds an error panel."""
    build_heading_figure(table, truth_yaw, title).savefig(path, dpi=110)


def build_heading_figure(
    table: HeadingTable, truth_yaw: np.ndarray | None = None, title: str = ""
) -> Figure:
    """The figure of :func:`heading_figure`. The satellite curve is ``table.n_sat_epoch``, one
    step per epoch centred on it."""
    t = table.t - (table.t[0] if len(table) else 0.0)
    panels = 3 if truth_yaw is not None else 2
    fig = Figure(figsize=(10, 2.6 * panels + 1))
    axes = fig.subplots(panels, 1, sharex=True)
    ax = axes[0]
    ax.step(t, table.n_sat_epoch, where="mid", color="0.3", label="satellites")
    ax.scatter(
        t[table.conv_valid],
        np.full(table.conv_valid.sum(), -0.5),
        s=6,
        c="tab:blue",
        label="conventional available",
    )
    ax.scatter(
        t[table.tc_available],
        np.full(table.tc_available.sum(), -1.0),
        s=6,
        c="tab:red",
        label="tightly coupled available",
    )
    ax.set_ylabel("satellites / epoch")
    ax.legend(loc="upper right", fontsize=8)
    ax = axes[1]
    ax.plot(t, np.degrees(table.course_conv), ".", ms=3, c="tab:blue", label="conventional")
    ax.plot(t, np.degrees(table.course_tc), ".", ms=3, c="tab:red", label="tightly coupled")
    ax.set_ylabel("course (deg from north)")
    ax.legend(loc="upper right", fontsize=8)
    if truth_yaw is not None:
        ax = axes[2]
        for yaw, colour, label in (
            (table.yaw_conv, "tab:blue", "conventional"),
            (table.yaw_tc, "tab:red", "tightly coupled"),
        ):
            ax.plot(t, np.degrees(wrap_angle(yaw - truth_yaw)), ".", ms=3, c=colour, label=label)
        ax.set_ylabel("heading error (deg)")
        ax.legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time since first epoch (s)")
    fig.suptitle(title)
    fig.tight_layout()
    return fig
