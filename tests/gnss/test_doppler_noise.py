"""Doppler σ fitted from the residuals: redundancy numbers that sum to the epoch's redundancy,
the normalised MAD of a satellite's recent residuals (scaled back by √r), its window, the rows
needed before it replaces the prior, and its floor."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from vo_doppler.gnss.doppler_noise import FLOOR_MPS, fitted_sigma, redundancy_numbers
from vo_doppler.model.doppler import DopplerRows

N_SAT = 6
LOS = np.array(
    [
        [0.6, 0.0, 0.8],
        [0.0, 0.6, 0.8],
        [-0.6, 0.0, 0.8],
        [0.0, -0.6, 0.8],
        [0.8, 0.6, 0.0],
        [0.48, -0.64, 0.6],
    ]
)
VELOCITY, DRIFT = np.array([3.0, -1.0, 0.2]), 50.0


def _rows(n_epochs: int, error: np.ndarray, sigma=0.1, los=LOS) -> DopplerRows:
    """``n_epochs`` epochs 1 s apart, the same six lines of sight each, range rates of the
    velocity and clock drift above plus ``error`` (n_epochs × 6)."""
    n = len(los)
    epoch = np.repeat(np.arange(n_epochs), n)
    los_rows = np.tile(los, (n_epochs, 1))
    range_rate = -los_rows @ VELOCITY + DRIFT + np.asarray(error).reshape(-1)
    return DopplerRows(
        t=100.0 + epoch.astype(float),
        los=los_rows,
        sat_velocity=np.zeros((epoch.size, 3)),
        sat_clock_drift=0.0,
        range_rate=range_rate,
        weight=np.broadcast_to(np.asarray(sigma, dtype=float) ** -2.0, epoch.size),
        sat_id=np.tile([f"G{k:02d}" for k in range(1, n + 1)], n_epochs),
        epoch=epoch,
        system=np.full(epoch.size, "G"),
        prn=np.tile(np.arange(1, n + 1), n_epochs),
        code=np.full(epoch.size, "D1C"),
    )


def _truth(n_epochs: int) -> SimpleNamespace:
    return SimpleNamespace(
        velocity_ecef=np.tile(VELOCITY, (n_epochs, 1)), clock_drift_mps=np.full(n_epochs, DRIFT)
    )


def _pattern(n: int) -> np.ndarray:
    """+1, −1, 0, +1, −1, 0, …: over any six or more in a row the median is 0 and the median
    absolute value 1."""
    return np.array([1.0, -1.0, 0.0])[np.arange(n) % 3]


def _hat_diagonal(los: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    design = np.hstack([-los, np.ones((len(los), 1))]) / sigma[:, None]
    return np.diag(design @ np.linalg.solve(design.T @ design, design.T))


def test_redundancy_numbers_are_one_minus_the_hat_diagonal_and_sum_to_n_minus_4():
    sigma = np.array([0.1, 0.2, 0.1, 0.5, 0.1, 0.3])
    rows = _rows(2, np.zeros((2, N_SAT)), sigma=np.tile(sigma, 2))
    r = redundancy_numbers(rows, rows.sigma())
    np.testing.assert_allclose(r, np.tile(1.0 - _hat_diagonal(LOS, sigma), 2), atol=1e-12)
    assert r[:N_SAT].sum() == pytest.approx(N_SAT - 4, abs=1e-12)
    assert np.all((r > 0) & (r < 1))
    # a common scale of the σ changes no redundancy number
    np.testing.assert_allclose(redundancy_numbers(rows, 7.0 * rows.sigma()), r, atol=1e-12)


def test_an_epoch_without_redundancy_has_none():
    rows = _rows(1, np.zeros((1, 4)), los=LOS[:4])
    assert np.isnan(redundancy_numbers(rows, rows.sigma())).all()


def test_the_sigma_is_the_nmad_of_the_recent_residuals_scaled_back_by_sqrt_r():
    # every satellite's errors run +e_s, −e_s, 0, +e_s, …; the solution is the truth, so the
    # residuals are the errors themselves: over any 20 or more rows their median is 0 and
    # their median absolute value e_s, so the NMAD is 1.4826 · e_s / √r_s
    n_epochs, e = 30, np.array([0.05, 0.1, 0.02, 0.3, 0.08, 0.04])
    rows = _rows(n_epochs, _pattern(n_epochs)[:, None] * e)
    prior = np.full(len(rows), 9.0)
    sigma = fitted_sigma(rows, _truth(n_epochs), prior, min_rows=20).reshape(n_epochs, N_SAT)
    r = 1.0 - _hat_diagonal(LOS, np.full(N_SAT, 0.1))
    np.testing.assert_array_equal(sigma[:19], 9.0)  # fewer than 20 rows: the prior
    np.testing.assert_allclose(sigma[19:], np.tile(1.4826 * e / np.sqrt(r), (11, 1)), rtol=1e-9)


def test_the_reference_sigma_scales_the_residuals_and_the_result():
    n_epochs = 24
    rows = _rows(n_epochs, _pattern(n_epochs)[:, None] * np.full(N_SAT, 0.1))
    reference = np.tile([1.0, 2.0, 0.5, 1.0, 1.0, 1.0], n_epochs)
    plain = fitted_sigma(rows, _truth(n_epochs), np.ones(len(rows)), min_rows=4)
    scaled = fitted_sigma(rows, _truth(n_epochs), np.ones(len(rows)), reference, min_rows=4)
    np.testing.assert_allclose(scaled, plain, rtol=1e-12)  # k·reference: the same σ


def test_only_the_rows_within_the_window_count_and_a_burst_is_forgotten():
    # satellite 1's errors 0.5 in size for the first 10 s, then 0.01: a 5-s window (six rows)
    # holds a majority of small errors from 12 s on, a 60-s window from 14 s on; the NMAD
    # follows the majority
    n_epochs = 30
    errors = np.zeros((n_epochs, N_SAT))
    errors[:, 0] = _pattern(n_epochs) * np.where(np.arange(n_epochs) < 10, 0.5, 0.01)
    rows = _rows(n_epochs, errors)
    first = np.arange(n_epochs) * N_SAT
    scale = 1.4826 / np.sqrt(1.0 - _hat_diagonal(LOS, np.full(N_SAT, 0.1))[0])
    short = fitted_sigma(rows, _truth(n_epochs), np.ones(len(rows)), window_s=5.0, min_rows=4)
    np.testing.assert_allclose(short[first[4:10]], scale * 0.5, rtol=1e-9)
    np.testing.assert_allclose(short[first[12:]], scale * 0.01, rtol=1e-9)
    long = fitted_sigma(rows, _truth(n_epochs), np.ones(len(rows)), window_s=60.0, min_rows=4)
    np.testing.assert_allclose(long[first[4:13]], scale * 0.5, rtol=1e-9)
    np.testing.assert_allclose(long[first[14:]], scale * 0.01, rtol=1e-9)


def test_a_quiet_satellite_gets_the_floor():
    rows = _rows(25, np.zeros((25, N_SAT)))
    sigma = fitted_sigma(rows, _truth(25), np.full(len(rows), 0.3), min_rows=20)
    np.testing.assert_array_equal(sigma[: 19 * N_SAT], 0.3)
    np.testing.assert_array_equal(sigma[19 * N_SAT :], FLOOR_MPS)
