"""Figures of GNSS velocity and SPP results (people-facing units: degrees)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vo_doppler.geo import EnuFrame
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution
from vo_doppler.report.figure import integer_ticks, new_figure, tight_layout


def velocity_figure(path: str | Path, solution: VelocitySolution, title: str = "") -> None:
    """Speed, course and satellite count over time (PNG)."""
    t = solution.t - solution.t[0] if solution.t.size else solution.t
    fig = new_figure(figsize=(9, 7))
    axes = fig.subplots(3, 1, sharex=True)
    axes[0].plot(t, solution.speed_mps, ".-", ms=3)
    axes[0].set_ylabel("speed (m/s)")
    course = np.where(solution.speed_mps > 0.2, solution.course_deg, np.nan)
    axes[1].plot(t, course, ".", ms=3)
    axes[1].set_ylabel("course (deg, cw from N)\nspeed > 0.2 m/s")
    axes[1].set_ylim(0, 360)
    axes[2].step(t, solution.n_sat, where="mid")
    if not solution.valid.all():
        missing = ~solution.valid
        axes[2].plot(t[missing], solution.n_sat[missing], "rx", label="unavailable")
        axes[2].legend(loc="best")
    axes[2].set_ylabel("satellites")
    integer_ticks(axes[2].yaxis)
    axes[2].set_xlabel("time since first epoch (s)")
    fig.suptitle(title or "GNSS Doppler velocity")
    _save(fig, path)


def spp_figure(path: str | Path, solution: SppSolution, title: str = "") -> None:
    """East/north/up about the median fix and satellite count over time (PNG)."""
    t = solution.t - solution.t[0] if solution.t.size else solution.t
    fig = new_figure(figsize=(9, 6))
    axes = fig.subplots(2, 1, sharex=True)
    if solution.valid.any():
        frame = EnuFrame.from_ecef(np.median(solution.position_ecef[solution.valid], axis=0))
        enu = frame.ecef_to_enu(solution.position_ecef)
        for k, name in enumerate("enu"):
            axes[0].plot(t, enu[:, k], ".", ms=3, label=name)
        axes[0].legend(loc="best")
    axes[0].set_ylabel("position about median (m)")
    axes[1].step(t, solution.n_sat, where="mid")
    axes[1].set_ylabel("satellites")
    integer_ticks(axes[1].yaxis)
    axes[1].set_xlabel("time since first epoch (s)")
    fig.suptitle(title or "GNSS single-point positions")
    _save(fig, path)


def _save(fig, path: str | Path) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tight_layout(fig)
    fig.savefig(path, dpi=120)
