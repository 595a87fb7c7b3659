"""Figures of a heading run: satellites per epoch, heading availability as its own strip
(conventional available, tightly coupled available, tightly coupled used by the correction),
the headings as an unwrapped course with the tightly coupled ±2σ band, and the heading error
with the same band when ground truth is given."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from vo_doppler.geo import wrap_angle, yaw_to_course
from vo_doppler.model.heading import HeadingTable
from vo_doppler.report.decimation import drawn_line, drawn_points, drawn_rows
from vo_doppler.report.figure import new_figure, tight_layout

if TYPE_CHECKING:
    from matplotlib.figure import Figure

CONVENTIONAL, TIGHT = "tab:blue", "tab:red"
BAND_SIGMAS = 2.0


def heading_figure(
    path: str | Path,
    table: HeadingTable,
    truth_yaw: np.ndarray | None = None,
    title: str = "",
    used: np.ndarray | None = None,
) -> None:
    """Write the PNG; ``truth_yaw`` (rad, per epoch, NaN where unknown) adds an error panel,
    ``used`` (per epoch) the strip of epochs whose tightly coupled heading corrected."""
    build_heading_figure(table, truth_yaw, title, used).savefig(path, dpi=110)


def continuous_course_deg(course: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """``course`` (rad) in degrees, each value moved by whole turns to lie within 180° of the
    unwrapped ``reference`` (rad, NaN gaps filled by interpolation): no 0/360° jumps."""
    finite = np.isfinite(reference)
    if not finite.any():
        return np.degrees(course)
    index = np.arange(len(reference))
    unwrapped = np.interp(index, index[finite], np.unwrap(reference[finite]))
    return np.degrees(unwrapped + wrap_angle(course - unwrapped))


def _strip(ax, t: np.ndarray, rows: list[tuple[str, np.ndarray, str]]) -> None:
    """One row of ticks per flag: a tick at every epoch where it holds (all of them: dozens
    of thin ticks per pixel make the strip's solid colour, which fewer would lighten)."""
    for k, (_, flag, colour) in enumerate(rows):
        ax.scatter(t[flag], np.full(int(flag.sum()), k), marker="|", s=60, c=colour, lw=1)
    ax.set_yticks(range(len(rows)), [label for label, _, _ in rows], fontsize=8)
    ax.set_ylim(-0.6, len(rows) - 0.4)
    ax.invert_yaxis()
    ax.set_title("heading availability (a tick per GNSS epoch)", fontsize=9, loc="left")


def build_heading_figure(
    table: HeadingTable,
    truth_yaw: np.ndarray | None = None,
    title: str = "",
    used: np.ndarray | None = None,
) -> Figure:
    """The figure of :func:`heading_figure`. The satellite curve is ``table.n_sat_epoch``, one
    step per epoch centred on it. A long drive's lines, bands and dots are drawn from the
    epochs the figure can tell apart (:mod:`vo_doppler.report.decimation`)."""
    t = table.t - (table.t[0] if len(table) else 0.0)
    panels = 4 if truth_yaw is not None else 3
    fig = new_figure(figsize=(10, 1.6 + 2.3 * panels))
    axes = fig.subplots(
        panels, 1, sharex=True, height_ratios=[1.0, 0.7, 1.6] + [1.6] * (panels - 3)
    )
    ax = axes[0]
    ax.step(*drawn_line(t, table.n_sat_epoch), where="mid", color="0.3", label="satellites")
    ax.set_ylabel("satellites\nper epoch")
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    rows = [
        ("conventional available", table.conv_valid, CONVENTIONAL),
        ("tightly coupled available", table.tc_available, TIGHT),
    ]
    if used is not None:
        rows.append(("tightly coupled used", np.asarray(used, bool), "darkred"))
    _strip(axes[1], t, rows)
    sigma = np.where(table.tc_available, table.sigma_tc, np.nan)
    reference = yaw_to_course(truth_yaw) if truth_yaw is not None else table.course_tc
    if not np.isfinite(reference).any():
        reference = table.course_conv
    ax = axes[2]
    course_tc = continuous_course_deg(table.course_tc, reference)
    course_conv = continuous_course_deg(table.course_conv, reference)
    if truth_yaw is not None:
        truth_course = continuous_course_deg(reference, reference)
        ax.plot(*drawn_line(t, truth_course), c="k", lw=1, label="ground truth")
    band = BAND_SIGMAS * np.degrees(sigma)
    _band(ax, t, course_tc - band, course_tc + band)
    _dots(ax, t, course_conv, CONVENTIONAL, "conventional")
    _dots(ax, t, course_tc, TIGHT, f"tightly coupled (band ±{BAND_SIGMAS:g}σ)")
    ax.set_ylabel("course [deg from north,\nclockwise, unwrapped]")
    ax.grid(alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    if truth_yaw is not None:
        ax = axes[3]
        _band(ax, t, -band, band, f"±{BAND_SIGMAS:g}σ (tight)")
        for yaw, colour, label in (
            (table.yaw_conv, CONVENTIONAL, "conventional"),
            (table.yaw_tc, TIGHT, "tightly coupled"),
        ):
            _dots(ax, t, np.degrees(wrap_angle(yaw - truth_yaw)), colour, label)
        ax.axhline(0.0, c="k", lw=0.8)
        ax.set_ylabel("heading error\n(estimate − truth) [deg]")
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("time since first GNSS epoch [s]")
    fig.suptitle(title)
    tight_layout(fig)
    return fig


def _band(ax, t: np.ndarray, low: np.ndarray, high: np.ndarray, label: str | None = None) -> None:
    """The tight heading's band between ``low`` and ``high`` (breaks where either is NaN)."""
    rows = drawn_rows(np.column_stack([low, high]))
    ax.fill_between(t[rows], low[rows], high[rows], color=TIGHT, alpha=0.2, lw=0, label=label)


def _dots(ax, t: np.ndarray, values: np.ndarray, colour: str, label: str) -> None:
    """A dot per epoch (those the figure can tell apart)."""
    rows = drawn_points(t, values)
    ax.plot(t[rows], values[rows], ".", ms=3, c=colour, label=label)
