"""Speed of the tightly coupled heading solver against a plain scipy.optimize.least_squares.

Both solve the same sec. 3.5 problem in this script: a synthetic drive at 20 Hz, 2 s windows,
3 satellites per epoch, Doppler noise 5 cm/s, unknowns (θ₀, ρ₀, α) per window with a Huber
loss. The baseline calls least_squares once per window (analytic Jacobian, started from the
truth-free gyro-propagated previous estimate); ours solves every window at once.
Usage: python benchmarks/heading_speed.py [--epochs N] [--repeat N] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from vo_doppler.geo import wrap_angle
from vo_doppler.heading.tight_heading import TightHeadingConfig, tight_heading_series
from vo_doppler.sim.doppler_rows import simulate_doppler

ROOT = Path(__file__).resolve().parents[1]
AZIMUTH = [30.0, 110.0, 200.0, 280.0, 330.0, 160.0, 75.0, 250.0]
ELEVATION = [60.0, 30.0, 45.0, 20.0, 70.0, 15.0, 40.0, 55.0]


def _scenario(n_epochs: int, rate_hz: float, seed: int):
    t = np.arange(n_epochs) / rate_hz
    return simulate_doppler(
        t,
        lambda t: 0.5 + 0.3 * np.sin(0.2 * t),
        lambda t: 12.0 + 3.0 * np.sin(0.1 * t),
        AZIMUTH,
        ELEVATION,
        sats_per_epoch=3,
        noise_mps=0.05,
        seed=seed,
    )


def scipy_baseline(scenario, config: TightHeadingConfig) -> np.ndarray:
    """One ``least_squares(loss="huber")`` call per window, same model and weights."""
    rows, t_epoch = scenario.rows, scenario.t_epoch
    y_all = rows.reduced()
    epoch_of_row = np.searchsorted(t_epoch, rows.t - 1e-9)
    sqrt_w = np.sqrt(rows.weight)
    estimates = np.full(len(t_epoch), np.nan)
    previous = 0.0
    for k in range(len(t_epoch)):
        lo = np.searchsorted(rows.t, t_epoch[k] - config.window_s, side="right")
        hi = np.searchsorted(rows.t, t_epoch[k], side="right")
        e = epoch_of_row[lo:hi]
        delta = scenario.yaw_angle[e] - scenario.yaw_angle[k]
        tau = t_epoch[e] - t_epoch[k]
        s = scenario.speed[e]
        ge, gn = rows.los[lo:hi, 0], rows.los[lo:hi, 1]
        y, sw = y_all[lo:hi], sqrt_w[lo:hi]

        def residual(x, delta=delta, tau=tau, s=s, ge=ge, gn=gn, y=y, sw=sw):
            heading = x[0] + delta
            model = -s * (ge * np.cos(heading) + gn * np.sin(heading)) + x[1] - x[2] * tau
            return sw * (y - model)

        def jacobian(x, delta=delta, tau=tau, s=s, ge=ge, gn=gn, sw=sw):
            heading = x[0] + delta
            d_theta = -s * (-ge * np.sin(heading) + gn * np.cos(heading))
            return -sw[:, None] * np.column_stack([d_theta, np.ones_like(tau), -tau])

        start = previous + (scenario.yaw_angle[k] - scenario.yaw_angle[k - 1] if k else 0.0)
        x0 = np.array([start, float(np.median(y)), 0.0])
        fit = least_squares(residual, x0, jac=jacobian, loss="huber", f_scale=config.huber_k)
        estimates[k] = previous = float(wrap_angle(fit.x[0]))
    return estimates


def _best_time(function, repeat: int):
    best, value = float("inf"), None
    for _ in range(repeat):
        start = time.perf_counter()
        value = function()
        best = min(best, time.perf_counter() - start)
    return best, value


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--epochs", type=int, default=2000)
    parser.add_argument("--rate-hz", type=float, default=20.0)
    parser.add_argument("--repeat", type=int, default=2, help="runs of each solver (best kept)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--json", default=ROOT / "benchmarks" / "results" / "heading_speed.json")
    args = parser.parse_args()
    config = TightHeadingConfig(window_s=2.0)
    scenario = _scenario(args.epochs, args.rate_hz, args.seed)

    def ours_run():
        return tight_heading_series(
            scenario.rows, scenario.t_epoch, scenario.speed, scenario.yaw_angle, config
        )

    ours_s, result = _best_time(ours_run, args.repeat)
    scipy_s, baseline = _best_time(lambda: scipy_baseline(scenario, config), args.repeat)
    skip = int(config.window_s * args.rate_hz)  # compare full windows only
    ours_err = np.degrees(np.abs(wrap_angle(result.yaw - scenario.yaw)))[skip:]
    base_err = np.degrees(np.abs(wrap_angle(baseline - scenario.yaw)))[skip:]
    n = len(scenario.t_epoch)
    rows_per_window = float(np.median(result.n_obs[skip:]))
    summary = {
        "epochs": n,
        "rate_hz": args.rate_hz,
        "window_s": config.window_s,
        "sats_per_epoch": 3,
        "rows_per_window": rows_per_window,
        "vo_doppler_s": ours_s,
        "scipy_least_squares_s": scipy_s,
        "vo_doppler_epochs_per_s": n / ours_s,
        "scipy_epochs_per_s": n / scipy_s,
        "speedup": scipy_s / ours_s,
        "vo_doppler_median_error_deg": float(np.nanmedian(ours_err)),
        "scipy_median_error_deg": float(np.nanmedian(base_err)),
        "max_difference_deg": float(
            np.nanmax(np.degrees(np.abs(wrap_angle(result.yaw - baseline)))[skip:])
        ),
        "vo_doppler_available_fraction": float(result.available[skip:].mean()),
    }
    print(f"{'solver':<24}{'seconds':>10}{'epochs/s':>12}{'median err °':>14}")
    print(
        f"{'vo_doppler (batched GN)':<24}{ours_s:>10.3f}{n / ours_s:>12.0f}"
        f"{summary['vo_doppler_median_error_deg']:>14.4f}"
    )
    print(
        f"{'scipy least_squares':<24}{scipy_s:>10.3f}{n / scipy_s:>12.0f}"
        f"{summary['scipy_median_error_deg']:>14.4f}"
    )
    print(
        f"speed-up: {scipy_s / ours_s:.1f}x  ({n} epochs, {rows_per_window:.0f} rows/window); "
        f"max |ours − scipy| = {summary['max_difference_deg']:.4f}°"
    )
    out = Path(args.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(summary, indent=2))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
