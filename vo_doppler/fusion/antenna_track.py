"""Where the trajectories are placed: the GNSS antenna's positions at the valid SPP fixes,
smoothed along the Doppler velocities, and which of them may give a height (docs/design.md,
"Heading correction of VO")."""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from vo_doppler.geo import EnuFrame
from vo_doppler.gnss.receiver_track import smoothed_track
from vo_doppler.gnss.spp import EARTH_SURFACE_M
from vo_doppler.model.gnss_solutions import SppSolution, VelocitySolution

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class AntennaTrack:
    """Where the trajectories are placed: the GNSS antenna's ENU positions ``position`` (N, 3, m)
    at the GPS times ``t`` (N,) of the valid SPP fixes; ``t`` empty with one untimed position
    (no fix: the RINEX approximate position or the origin). Heights come only from the positions
    whose ``height_sigma`` (N,, m; None: all) is at most ``PLACEMENT_VERTICAL_SIGMA_M``; without
    any, from the sequence origin (the first pose at up 0). ``height_source`` says which, in
    words, for the report."""

    t: np.ndarray
    position: np.ndarray
    height_sigma: np.ndarray | None = None
    height_source: str = "the antenna positions"

    @property
    def height_rows(self) -> np.ndarray:
        """Indices of the positions whose heights may place a trajectory."""
        if self.height_sigma is None:
            return np.arange(len(self.position))
        return np.flatnonzero(
            np.nan_to_num(self.height_sigma, nan=np.inf) <= PLACEMENT_VERTICAL_SIGMA_M
        )


PLACEMENT_VERTICAL_SIGMA_M = 5.0
"""Largest vertical σ (m) of a valid fix whose height may place the trajectories. A street
canyon's fixes are worst in height (the satellites left are high, their reflections all
delays): the sample's valid fixes lay 46 m above the road, the Hong Kong drive's 14 m at the
median with σ_u 14 m; a fix this good is a better height than the origin's guess, a worse one
is not."""
ORIGIN_HEIGHT = (
    "the sequence origin (no valid fix with a vertical σ of at most {limit:g} m): the first "
    "pose at its height"
)


def _height_sigma(spp: SppSolution, rows: np.ndarray) -> tuple[np.ndarray, str]:
    """σ_u (m) of the fixes ``rows`` (inf where unknown) and what places the heights."""
    sigma = np.full(rows.size, np.inf)
    if spp.vertical_sigma_m is not None:
        sigma = np.nan_to_num(spp.vertical_sigma_m[rows], nan=np.inf)
    good = sigma <= PLACEMENT_VERTICAL_SIGMA_M
    if not good.any():
        return sigma, ORIGIN_HEIGHT.format(limit=PLACEMENT_VERTICAL_SIGMA_M)
    return sigma, (
        f"the valid fixes with a vertical σ of at most {PLACEMENT_VERTICAL_SIGMA_M:g} m "
        f"({good.sum()} of {rows.size}; median σ_u {np.median(sigma[good]):.1f} m), their "
        "inverse-variance weighted median"
    )


def antenna_track(
    spp: SppSolution,
    velocity: VelocitySolution,
    approx_position: np.ndarray | None,
    enu: EnuFrame,
) -> AntennaTrack:
    """The antenna's positions that place every trajectory (:func:`level_with_yaw`).

    At the epochs of the valid SPP fixes, the fixes smoothed along the final Doppler velocities
    (:func:`vo_doppler.gnss.receiver_track.smoothed_track`, robust: Huber, then Cauchy
    weights, so that one bad fix among its neighbours barely moves the track). Only there: an
    epoch without a fix would be the fixes carried to it by the Doppler velocities, which in a
    street canyon (few satellites, reflections) drift by tens of metres over seconds; the
    trajectory itself carries the fixes back to its start. With one valid fix, that fix;
    without any, ``approx_position`` (ECEF, the RINEX header's), else the ENU origin (untimed,
    with a warning).
    """
    valid = np.flatnonzero(spp.valid)
    if valid.size >= 2:
        fixes = np.where(spp.valid[:, None], spp.position_ecef, np.nan)
        known = velocity.valid
        if velocity.untestable is not None:
            known = known | velocity.untestable
        track = smoothed_track(
            spp.t, fixes, spp.horizontal_sigma_m, velocity.velocity_ecef, velocity.covariance, known
        )
        if track is not None:
            sigma, source = _height_sigma(spp, valid)
            return AntennaTrack(spp.t[valid], enu.ecef_to_enu(track[valid]), sigma, source)
    if valid.size:
        sigma, source = _height_sigma(spp, valid)
        return AntennaTrack(spp.t[valid], enu.ecef_to_enu(spp.position_ecef[valid]), sigma, source)
    origin = ORIGIN_HEIGHT.format(limit=PLACEMENT_VERTICAL_SIGMA_M)
    approx = np.asarray(approx_position if approx_position is not None else np.nan, dtype=float)
    if np.all(np.isfinite(approx)) and np.linalg.norm(approx) > EARTH_SURFACE_M:
        log.warning("no SPP fix: the trajectories start at the RINEX approximate position")
        return AntennaTrack(
            np.zeros(0), enu.ecef_to_enu(approx.reshape(1, 3)), np.full(1, np.inf), origin
        )
    log.warning("no SPP fix and no approximate position: the trajectories start at the origin")
    return AntennaTrack(np.zeros(0), np.zeros((1, 3)), np.full(1, np.inf), origin)
