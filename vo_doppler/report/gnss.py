"""Figures of GNSS velocity and SPP results (people-facing units: degrees).

Each value axis is scaled to the valid epochs (:func:`robust_limits`): an invalid epoch's
speed of thousands of m/s or a height kilometres off would otherwise squeeze every valid value
into one line. Invalid epochs are drawn as red crosses, and any value beyond the axis at its
edge (a triangle pointing out), counted in a note on the axis.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from vo_doppler.geo import EnuFrame
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
from vo_doppler.report.figure import integer_ticks, new_figure, tight_layout

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

LIMIT_PERCENTILES = (0.5, 99.5)
"""The valid values between these percentiles set an axis (a rare wild valid value, such as a
single-point fix in a street canyon, does not either)."""
LIMIT_MARGIN = 0.25
"""Share of the valid values' range added on each side of the axis."""
INVALID_STYLE = {"marker": "x", "ls": "none", "ms": 4, "c": "tab:red", "alpha": 0.7}


def robust_limits(
    values: np.ndarray, valid: np.ndarray, min_pad: float, floor: float | None = None
) -> tuple[float, float] | None:
    """Axis limits from the finite ``values`` of the ``valid`` epochs: their
    :data:`LIMIT_PERCENTILES`, widened by :data:`LIMIT_MARGIN` of their range and at least
    ``min_pad`` on each side, not below ``floor``; None without a valid finite value."""
    values = np.asarray(values, dtype=float)
    shown = values[np.asarray(valid, dtype=bool) & np.isfinite(values)]
    if shown.size == 0:
        return None
    low, high = (float(v) for v in np.percentile(shown, LIMIT_PERCENTILES))
    pad = max(LIMIT_MARGIN * (high - low), min_pad)
    low, high = low - pad, high + pad
    if floor is not None:
        low = max(low, floor)
    return low, high


def plot_marked(
    ax: Axes,
    t: np.ndarray,
    values: np.ndarray,
    valid: np.ndarray,
    limits: tuple[float, float] | None,
    label: str,
    style: str = ".",
    invalid_label: str | None = "invalid epoch",
) -> int:
    """Plot ``values`` over ``t``: the valid epochs in ``style``, the invalid ones as red
    crosses (``invalid_label`` in the legend; None: none); with ``limits``, the axis is set to
    them and every value beyond is drawn at the edge it passes (a triangle pointing out).
    Returns how many values are beyond."""
    values = np.asarray(values, dtype=float)
    valid = np.asarray(valid, dtype=bool)
    shown = values if limits is None else np.clip(values, *limits)
    line = ax.plot(t[valid], shown[valid], style, ms=3, label=label)[0]
    invalid = ~valid & np.isfinite(values)
    if invalid.any():
        ax.plot(t[invalid], shown[invalid], label=invalid_label or "_nolegend_", **INVALID_STYLE)
    if limits is None:
        return 0
    ax.set_ylim(*limits)
    beyond = 0
    for side, marker in ((values > limits[1], "^"), (values < limits[0], "v")):
        beyond += int(np.count_nonzero(side))
        for kind, colour_of in ((side & valid, line.get_color()), (side & invalid, "tab:red")):
            if kind.any():
                ax.plot(t[kind], shown[kind], marker, ls="none", ms=6, c=colour_of, clip_on=False)
    return beyond


def note_beyond(ax: Axes, beyond: int) -> None:
    """Say on ``ax`` how many values lie beyond its limits (nothing when none does)."""
    if beyond:
        ax.text(
            0.01,
            0.97,
            f"{beyond} value{'s' if beyond > 1 else ''} beyond the axis (scaled to the valid "
            "epochs), drawn at its edge",
            transform=ax.transAxes,
            fontsize=7,
            color="0.3",
            va="top",
        )


def _satellites(ax: Axes, t: np.ndarray, n_sat: np.ndarray, valid: np.ndarray) -> None:
    ax.step(t, n_sat, where="mid")
    if not valid.all():
        ax.plot(t[~valid], n_sat[~valid], label="invalid epoch", **INVALID_STYLE)
        ax.legend(loc="best", fontsize=8)
    ax.set_ylabel("satellites")
    integer_ticks(ax.yaxis)
    ax.set_xlabel("time since first epoch (s)")


def build_velocity_figure(solution: VelocitySolution, title: str = "") -> Figure:
    """Speed, course and satellite count over time, the speed axis scaled to the valid epochs
    and the invalid epochs marked (module docstring)."""
    t = solution.t - solution.t[0] if solution.t.size else solution.t
    valid = np.asarray(solution.valid, dtype=bool)
    fig = new_figure(figsize=(9, 7))
    axes = fig.subplots(3, 1, sharex=True)
    speed = solution.speed_mps
    limits = robust_limits(speed, valid, min_pad=0.5, floor=0.0)
    note_beyond(axes[0], plot_marked(axes[0], t, speed, valid, limits, "speed", ".-"))
    axes[0].legend(loc="upper right", fontsize=8)
    axes[0].set_ylabel("speed (m/s)")
    course = np.where(speed > 0.2, solution.course_deg, np.nan)
    plot_marked(axes[1], t, course, valid, (0.0, 360.0), "course", invalid_label=None)
    axes[1].set_ylabel("course (deg, cw from N)\nspeed > 0.2 m/s")
    _satellites(axes[2], t, solution.n_sat, valid)
    fig.suptitle(title or "GNSS Doppler velocity")
    tight_layout(fig)
    return fig


def build_spp_figure(solution: SppSolution, title: str = "") -> Figure:
    """East/north/up about the median valid fix and satellite count over time, the position
    axis scaled to the valid fixes and the invalid ones marked (module docstring)."""
    t = solution.t - solution.t[0] if solution.t.size else solution.t
    valid = np.asarray(solution.valid, dtype=bool)
    fig = new_figure(figsize=(9, 6))
    axes = fig.subplots(2, 1, sharex=True)
    if valid.any():
        frame = EnuFrame.from_ecef(np.median(solution.position_ecef[valid], axis=0))
        enu = frame.ecef_to_enu(solution.position_ecef)
        limits = robust_limits(enu.ravel(), np.repeat(valid, 3), min_pad=1.0)
        beyond = sum(
            plot_marked(
                axes[0], t, enu[:, k], valid, limits, name, ".", None if k else "invalid epoch"
            )
            for k, name in enumerate("enu")
        )
        note_beyond(axes[0], beyond)
        axes[0].legend(loc="best", fontsize=8)
    axes[0].set_ylabel("position about median (m)")
    _satellites(axes[1], t, solution.n_sat, valid)
    fig.suptitle(title or "GNSS single-point positions")
    tight_layout(fig)
    return fig


def velocity_figure(path: str | Path, solution: VelocitySolution, title: str = "") -> None:
    """:func:`build_velocity_figure` written to ``path`` (PNG)."""
    _save(build_velocity_figure(solution, title), path)


def spp_figure(path: str | Path, solution: SppSolution, title: str = "") -> None:
    """:func:`build_spp_figure` written to ``path`` (PNG)."""
    _save(build_spp_figure(solution, title), path)


def _save(fig: Figure, path: str | Path) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
