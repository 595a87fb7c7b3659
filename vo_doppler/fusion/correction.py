"""Heading correction of vehicle poses by an absolute heading: which headings may correct, and
the method ([TK18] Eq. 11–13 window, or the Kalman blend (B1)–(B4)), chosen in one place."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from enum import StrEnum

import numpy as np

from vo_doppler.choices import check_fields, checked
from vo_doppler.fusion.heading_blend import BlendConfig, blend_heading
from vo_doppler.fusion.heading_correction import HeadingReference, correct_heading
from vo_doppler.fusion.result import CorrectionResult
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.timeseries import relative_times
from vo_doppler.model.trajectory import Trajectory


class CorrectionMethod(StrEnum):
    """How absolute headings correct the VO: the adaptive blend (B1)–(B4) or [TK18]'s window
    (sec. 3.6, Eq. 11–13)."""

    KALMAN = "kalman"
    WINDOW = "window"


class HeadingSource(StrEnum):
    """Which absolute headings correct: the tightly coupled ones, the conventional ones, or the
    former where usable and the latter elsewhere (:func:`absolute_heading`)."""

    TC = "tc"
    CONV = "conv"
    TC_CONV = "tc+conv"


TC_MAX_SIGMA = np.radians(2.0)


@dataclass
class CorrectionConfig:
    """How absolute headings correct the VO (angles in rad)."""

    method: CorrectionMethod = CorrectionMethod.KALMAN
    """'kalman': the adaptive blend (B1)–(B4) (smoother; ``blend.smooth=False`` is causal);
    'window': [TK18] sec. 3.6, Eq. 11–13."""
    reference: HeadingReference = HeadingReference.COURSE
    """What the absolute heading is compared with: the VO's 'course' (direction of travel, as a
    Doppler heading is) or its 'orientation' yaw ([TK18] sec. 3.6 as written). The course is
    immune to camera-calibration and extrinsic yaw errors that skew the VO's motion."""
    window_s: float = 2.0
    """The window method's W."""
    gate_rad: float = 0.0
    """Window method: if > 0, absolute headings this far from the corrected VO heading are not
    used. Off by default: a wrong first heading would then lock out the right ones."""
    tc_max_sigma_rad: float = TC_MAX_SIGMA
    """Tightly coupled headings with a larger standard deviation do not correct."""
    blend: BlendConfig = field(default_factory=BlendConfig)

    def __post_init__(self) -> None:
        check_fields(self, method=CorrectionMethod, reference=HeadingReference)


@dataclass
class AbsoluteHeading:
    """Absolute yaw per GNSS epoch with its validity, standard deviation (NaN: unknown, the
    blend's default) and error-correlation time (s; 0 for single-epoch headings)."""

    t: np.ndarray
    yaw: np.ndarray
    valid: np.ndarray
    sigma: np.ndarray | None = None
    correlation_s: np.ndarray | float = 0.0


def usable_tight_heading(table: HeadingTable, max_sigma: float = TC_MAX_SIGMA) -> np.ndarray:
    """Epochs whose tightly coupled heading may correct: available, reliable, σ < ``max_sigma``."""
    precise = np.nan_to_num(table.sigma_tc, nan=np.inf) < max_sigma
    return table.tc_available & table.tc_reliable & precise


def tight_absolute_heading(table: HeadingTable, config: CorrectionConfig) -> AbsoluteHeading:
    """The usable tightly coupled headings; their errors are correlated over the solver's
    window."""
    usable = usable_tight_heading(table, config.tc_max_sigma_rad)
    return AbsoluteHeading(table.t, table.yaw_tc, usable, table.sigma_tc, table.tc_window_s)


def conventional_absolute_heading(table: HeadingTable) -> AbsoluteHeading:
    """The conventional (single-epoch Doppler velocity) headings as the published method has
    them: valid by the GNSS tests alone, with the velocity solution's σ — the baseline the
    tightly coupled heading is compared with."""
    valid, sigma = table.published_conventional
    return AbsoluteHeading(table.t, table.yaw_conv, valid, sigma)


def absolute_heading(
    table: HeadingTable, source: HeadingSource, config: CorrectionConfig
) -> AbsoluteHeading:
    """The headings of ``source``: 'tc' usable tightly coupled ones, 'conv' conventional ones,
    'tc+conv' the former where usable, else the latter (each with its σ and correlation time)."""
    source = checked(HeadingSource, source, "source")
    tight = tight_absolute_heading(table, config)
    conventional = conventional_absolute_heading(table)
    if source is HeadingSource.TC:
        return tight
    if source is HeadingSource.CONV:
        return conventional
    use_tight = tight.valid
    return AbsoluteHeading(
        table.t,
        np.where(use_tight, tight.yaw, conventional.yaw),
        use_tight | conventional.valid,
        np.where(use_tight, tight.sigma, conventional.sigma),
        np.where(use_tight, tight.correlation_s, conventional.correlation_s),
    )


def correct(
    vehicle: Trajectory, heading: AbsoluteHeading, config: CorrectionConfig
) -> CorrectionResult:
    """Correct vehicle poses (level world) by ``config.method``, on times relative to the
    first pose (:func:`~vo_doppler.model.timeseries.relative_times`): the result does not
    depend on the time origin (GPS seconds near 10⁹ or seconds from the start of a log)."""
    origin = float(vehicle.t[0]) if len(vehicle.t) else 0.0
    relative = replace(vehicle, t=relative_times(vehicle.t, origin))
    result = _correct(relative, replace(heading, t=relative_times(heading.t, origin)), config)
    return replace(result, vehicle=replace(result.vehicle, t=vehicle.t.copy()))


def _correct(
    vehicle: Trajectory, heading: AbsoluteHeading, config: CorrectionConfig
) -> CorrectionResult:
    if config.method is CorrectionMethod.KALMAN:
        return blend_heading(
            vehicle,
            heading.t,
            heading.yaw,
            heading.sigma,
            heading.valid,
            heading.correlation_s,
            config.blend,
            config.reference,
        )
    return correct_heading(
        vehicle,
        heading.t,
        heading.yaw,
        heading.valid,
        config.window_s,
        max_gap_s=config.blend.max_gap_s,
        gate_rad=config.gate_rad if config.gate_rad > 0 else None,
        reference=config.reference,
    )
