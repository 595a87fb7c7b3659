"""SPP integrity on real recordings (issue 30): the Hong Kong canyon drive, whose fixes were all
valid up to 190 m off (47 % beyond 3σ horizontally), and two static receivers (the F9P in the
same street, the Septentrio in the open)."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from tests.conftest import require_shared
from vo_doppler.geo import EnuFrame, geodetic_to_ecef
from vo_doppler.gnss.pipeline import gnss_position
from vo_doppler.io.rinex_nav import read_nav
from vo_doppler.io.rinex_obs import read_obs
from vo_doppler.model.gnss_solutions import SppSolution

pytestmark = [pytest.mark.shared_data, pytest.mark.slow]

HK = "hk_tst_canyon_drive/"
STATIC = "hk_tst_static_f9p/"


def _position(obs_path: str, nav_paths: list[str], systems: str = "GREJC") -> SppSolution:
    obs = read_obs(require_shared(obs_path))
    nav = read_nav([require_shared(p) for p in nav_paths])
    logging.disable(logging.WARNING)
    try:
        return gnss_position(obs, nav, systems)
    finally:
        logging.disable(logging.NOTSET)


def _errors(solution: SppSolution, t_truth: np.ndarray, truth_ecef: np.ndarray):
    """ENU errors (N, 3) of the epochs within 0.1 s of a truth row, and those epochs."""
    index = np.clip(np.searchsorted(t_truth, solution.t - 0.1), 0, t_truth.size - 1)
    scored = np.abs(t_truth[index] - solution.t) <= 0.1
    frame = EnuFrame.from_ecef(truth_ecef[0])
    error = frame.ecef_to_enu(solution.position_ecef) - frame.ecef_to_enu(truth_ecef[index])
    return error, scored


def _figures(solution: SppSolution, error: np.ndarray, scored: np.ndarray) -> dict:
    valid = scored & solution.valid
    horizontal = np.hypot(error[:, 0], error[:, 1])[valid]
    vertical = np.abs(error[valid, 2])
    return {
        "valid_share": valid.sum() / scored.sum(),
        "median_m": float(np.median(horizontal)),
        "max_m": float(np.max(horizontal)),
        "beyond_3sigma_h": float(np.mean(horizontal > 3.0 * solution.horizontal_sigma_m[valid])),
        "beyond_3sigma_v": float(np.mean(vertical > 3.0 * solution.vertical_sigma_m[valid])),
        "beyond_hpl": float(np.mean(horizontal > solution.horizontal_protection_m[valid])),
    }


@pytest.mark.xdist_group("hk_canyon")
def test_canyon_fixes_valid_only_when_consistent_and_their_sigma_honest(hk_canyon):
    """The fixes of the GNSS stage as ``run`` makes them (``gnss_position`` on the drive's
    files returns this very solution: the recording carries no receiver σ)."""
    solution = hk_canyon[1].spp
    table = np.loadtxt(require_shared(HK + "groundTruth_TST_first_half.csv"), delimiter=",")
    t_truth = table[:, 0] * 604800.0 + table[:, 1]
    truth = geodetic_to_ecef(np.radians(table[:, 2]), np.radians(table[:, 3]), table[:, 4])
    error, scored = _errors(solution, t_truth, truth)
    figures = _figures(solution, error, scored)
    # measured: 54 % of the 242 scored fixes valid (was 100 %), horizontal error median 6.2 m
    # (12.9), max 31.8 m (189.5); beyond 3σ 2.3 % horizontally (47 %), 7.7 % vertically;
    # none beyond the horizontal protection level
    assert 0.4 <= figures["valid_share"] <= 0.8
    assert figures["median_m"] <= 8.0 and figures["max_m"] <= 45.0
    assert figures["beyond_3sigma_h"] <= 0.05 and figures["beyond_3sigma_v"] <= 0.12
    assert figures["beyond_hpl"] <= 0.01
    invalid = scored & ~solution.valid & np.isfinite(error[:, 0])
    assert np.median(np.hypot(error[invalid, 0], error[invalid, 1])) > 2 * figures["median_m"]
    assert solution.noise_models  # fitted from the drive's own residuals
    for model in solution.noise_models.values():
        assert model.cn0_fitted and model.law[1] > 0


@pytest.mark.parametrize(
    ("obs_path", "nav_paths", "truth_path"),
    [
        (
            STATIC + "2020_06_03_TST_03.obs",
            [STATIC + f"hksc155{hour}.20{kind}" for hour in "cd" for kind in "ngbl"],
            STATIC + "groundTruth_TST.csv",
        ),
        ("septentrio_static/rover.obs", ["septentrio_static/base.nav"], None),
    ],
    ids=["hk_static_f9p", "septentrio_static"],
)
def test_static_fixes_stay_valid_within_their_sigma(obs_path, nav_paths, truth_path):
    solution = _position(obs_path, nav_paths)
    if truth_path:
        lat, lon, height = np.loadtxt(require_shared(truth_path), delimiter=",")[0, 2:5]
    else:
        lat, lon, height = np.loadtxt(require_shared("septentrio_static/rover_position.txt"))
    truth = geodetic_to_ecef(np.radians(lat), np.radians(lon), height).reshape(1, 3)
    error, scored = _errors(solution, solution.t, np.repeat(truth, solution.t.size, axis=0))
    figures = _figures(solution, error, scored)
    # measured: F9P in the canyon 100 % valid, median 2.3 m, none beyond 3σ (0.1 % vertically);
    # Septentrio 100 %, 3.0 m (its σ_h 2.5 m: the broadcast orbit, clock and ionosphere budget;
    # the residuals alone said 0.4 m and put every fix beyond 3σ)
    assert figures["valid_share"] >= 0.98
    assert figures["beyond_3sigma_h"] <= 0.01 and figures["beyond_3sigma_v"] <= 0.01
