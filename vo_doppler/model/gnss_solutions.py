"""Per-epoch GNSS solutions: single-point positions and Doppler velocities."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class SppSolution:
    """Per-epoch positions (ECEF m), receiver clock bias per system (m), quality figures."""

    t: np.ndarray
    position_ecef: np.ndarray
    clock_bias_m: dict[str, np.ndarray]
    n_sat: np.ndarray
    residual_rms_m: np.ndarray
    pdop: np.ndarray
    valid: np.ndarray
    n_no_ephemeris: int
    verified: np.ndarray | None = None
    """Redundant and passing the chi-square test with the fitted pseudorange σ (a solved epoch
    without redundancy, or still failing the test after the allowed exclusions, keeps its
    position but is not verified); ``valid`` is the same unless the fixes were also checked
    against their Doppler-carried neighbours (``consistency_tested``)."""
    hdop: np.ndarray | None = None
    horizontal_sigma_m: np.ndarray | None = None
    """√(σ_e² + σ_n²) of the position from the weighted covariance (m)."""
    vertical_sigma_m: np.ndarray | None = None
    """σ_u of the position from the weighted covariance (m)."""
    horizontal_protection_m: np.ndarray | None = None
    """The largest horizontal position error (m) that a bias on one satellite's pseudorange
    could cause while the chi-square test would catch it less than four times in five
    (Baarda's minimal detectable bias, :func:`vo_doppler.gnss.lsq.minimal_detectable_shift`):
    what the σ does not cover when one satellite is reflected. Infinite without redundancy,
    NaN where unsolved."""
    vertical_protection_m: np.ndarray | None = None
    """The same for the vertical (m)."""
    consistency_scale: tuple[float, float] | None = None
    """(λ_h, λ_u): how much the fixes' scatter about their Doppler-carried neighbours exceeds
    their formal σ, by which the σ and protection levels were multiplied
    (:mod:`vo_doppler.gnss.position_check`); None: not checked."""
    consistency_tested: np.ndarray | None = None
    """Fixes the neighbour check could judge (None: not run); ``verified`` is each epoch's own
    test, ``valid`` adds the check."""
    noise_models: dict = field(default_factory=dict)
    """(system, pseudorange code) → the σ(C/N0, elevation) law fitted to the residuals
    (:class:`vo_doppler.gnss.pseudorange_noise.PseudorangeNoiseModel`); empty: the a-priori σ."""


@dataclass(frozen=True)
class VelocitySolution:
    """Per-epoch receiver velocity (ECEF and ENU at the receiver, m/s) and clock drift (m/s).

    ``covariance`` 4×4 of (v_x, v_y, v_z, b) in ECEF; ``dop`` columns (GDOP, PDOP, HDOP, VDOP,
    TDOP) of the velocity geometry (unweighted). Integrity: ``verified`` epochs have redundancy
    (≥ 5 satellites after exclusion), pass the chi-square test and have a plausible vertical
    velocity; ``valid`` epochs are the verified ones whose course and speed are also continuous
    with their neighbours' (a solved four-satellite epoch, whose fault cannot be detected, an
    epoch whose residuals still fail the test after the allowed exclusions and one that jumps off
    its neighbours keep their values for inspection but are not valid). Unsolved epochs: NaN.
    """

    t: np.ndarray
    velocity_ecef: np.ndarray
    velocity_enu: np.ndarray
    clock_drift_mps: np.ndarray
    covariance: np.ndarray
    dop: np.ndarray
    n_sat: np.ndarray
    n_obs: np.ndarray
    n_excluded: np.ndarray
    residual_rms_mps: np.ndarray
    valid: np.ndarray
    n_no_ephemeris: int = 0
    verified: np.ndarray | None = None
    speed_sigma_mps: np.ndarray | None = None
    """σ of the horizontal speed from the covariance (m/s)."""
    course_sigma_rad: np.ndarray | None = None
    """σ of the course from the covariance (rad; large when slow)."""
    vertical_sigma_mps: np.ndarray | None = None
    """σ of the up velocity from the covariance (m/s)."""
    horizontal_protection_mps: np.ndarray | None = None
    """The largest horizontal velocity error (m/s) that a bias on one satellite's Doppler could
    cause while the chi-square test would catch it less than four times in five (the effect of
    Baarda's minimal detectable bias, :func:`vo_doppler.gnss.lsq.minimal_detectable_shift`):
    what the σ does not cover when one satellite is reflected. Infinite without redundancy,
    NaN where unsolved; a street canyon's five or six satellites along the street leave it at
    metres per second even where the σ is centimetres."""
    untestable: np.ndarray | None = None
    """Solved from exactly four satellites (no redundancy, so a fault cannot be detected in the
    epoch) with a plausible vertical velocity: not valid, but a candidate wherever redundancy
    from elsewhere tests it (the heading stage's robust calibration against the wheels and the
    gyro); None: no such epoch flagged."""

    continuity_tested: np.ndarray | None = None
    """Valid epochs whose course the continuity test (2b) could judge: it needs neighbours
    within ±0.5 s, which a 1-Hz receiver never has (None: not run)."""

    @property
    def speed_mps(self) -> np.ndarray:
        """Horizontal speed (m/s): a car's speed; the vertical of a canyon fix is noise."""
        return np.hypot(self.velocity_enu[:, 0], self.velocity_enu[:, 1])

    @property
    def sigma_mps(self) -> np.ndarray:
        """√trace of the velocity covariance (m/s): one figure of each fix's precision."""
        return np.sqrt(np.trace(self.covariance[:, :3, :3], axis1=1, axis2=2))

    @property
    def course_deg(self) -> np.ndarray:
        """Course over ground, degrees clockwise from north in [0, 360)."""
        e, n = self.velocity_enu[:, 0], self.velocity_enu[:, 1]
        return np.mod(np.rad2deg(np.arctan2(e, n)), 360.0)
