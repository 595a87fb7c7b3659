"""Speed of the heading smoother's RTS pass (heading/smoother.py, design (S1)–(S2)) against
filterpy's KalmanFilter.batch_filter + rts_smoother on the same model and data.

A 10-minute drive at 20 Hz (12,000 epochs) with a window heading at every epoch; both sides
compute the smoothed offset and its variance (equal to 1e-9, checked), in alternating runs;
the table gives the median wall time of each and their ratio.
Usage: python benchmarks/smoother_speed.py [--epochs N] [--repeat N] [--json FILE]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from filterpy.kalman import KalmanFilter

from vo_doppler.heading.smoother import HeadingSmootherConfig, _Model, _rts

ROOT = Path(__file__).resolve().parents[1]


def _case(n: int):
    rng = np.random.default_rng(0)
    t = np.arange(n) / 20.0
    phi = np.cumsum(rng.normal(0.0, 0.002, n))
    z = 0.3 + rng.normal(0.0, 0.01, n)
    variance = np.full(n, 0.01**2 * 40.0)
    config = HeadingSmootherConfig(bias_walk_rad_per_s_sqrt_s=1e-5)
    return _Model(t, phi, 1e-4, 0.005, 1e-4, config), z, variance


def ours(model, z, variance):
    return _rts(model, np.arange(len(z)), z, variance)


def filterpy_rts(model, z, variance):
    kf = KalmanFilter(dim_x=2, dim_z=1)
    kf.x = np.array([z[0], 0.0])
    kf.P = np.diag([variance[0], model.bias_sigma**2])
    kf.H = np.array([[1.0, 0.0]])
    dt = np.diff(model.t)
    turn = (model.scale_sigma * np.abs(np.diff(model.yaw_angle))) ** 2
    q_b = model.config.bias_walk_rad_per_s_sqrt_s**2
    fs = [np.eye(2)] + [np.array([[1.0, -d], [0.0, 1.0]]) for d in dt]
    qs = [np.zeros((2, 2))] + [
        np.diag([model.q_a**2 * d + q, q_b * d]) for d, q in zip(dt, turn, strict=True)
    ]
    rs = [np.array([[r]]) for r in variance]
    zs = [None] + [np.array([v]) for v in z[1:]]
    means, covariances, _, _ = kf.batch_filter(zs, Fs=fs, Qs=qs, Rs=rs)
    smoothed, smoothed_cov, _, _ = kf.rts_smoother(means, covariances, Fs=fs, Qs=qs)
    return smoothed[:, 0], smoothed_cov[:, 0, 0]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--epochs", type=int, default=12000)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument(
        "--json", type=Path, default=ROOT / "benchmarks" / "results" / "smoother_speed.json"
    )
    args = parser.parse_args()
    model, z, variance = _case(args.epochs)
    a, b = ours(model, z, variance), filterpy_rts(model, z, variance)
    np.testing.assert_allclose(a[0], b[0], atol=1e-9)
    np.testing.assert_allclose(a[1], b[1], rtol=1e-6)
    times = {"ours": [], "filterpy": []}
    for _ in range(args.repeat):
        for name, fn in (("ours", ours), ("filterpy", filterpy_rts)):
            start = time.perf_counter()
            fn(model, z, variance)
            times[name].append(time.perf_counter() - start)
    median = {k: float(np.median(v)) for k, v in times.items()}
    ratio = median["filterpy"] / median["ours"]
    print(f"{'implementation':<16}{'median wall [s]':>16}{'epochs/s':>12}")
    for name in ("ours", "filterpy"):
        print(f"{name:<16}{median[name]:>16.3f}{args.epochs / median[name]:>12.0f}")
    print(f"speed-up (filterpy / ours, median of {args.repeat}): {ratio:.1f}x")
    result = {"epochs": args.epochs, "repeat": args.repeat, "times_s": times, "ratio": ratio}
    args.json.parent.mkdir(parents=True, exist_ok=True)
    args.json.write_text(json.dumps(result, indent=2) + "\n")
    print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
