"""Tightly coupled heading on real Doppler noise: how often data snooping flags clean windows
(against its nominal false-alarm rate α), how often the robust fallback gives the heading, and
the heading against ground truth.

    python benchmarks/heading_real_noise.py SEQUENCE_DIR [SEQUENCE_DIR ...] [--json FILE]

Each folder is a sequence with ground truth, e.g. the comma2k19 minute imported as in
``benchmarks/real_heading.py``. The tight heading runs on the GNSS stage's Doppler rows (the
receiver's σ as weights, or the σ fitted from the data) with the wheel speed and yaw rate
calibrated from the truth (``calibration_truth``), so that only the Doppler differs between the
cases:

* ``recorded``: every row;
* ``clean``: only the rows within ``CLEAN_SIGMAS`` a-priori σ of the truth (range rate predicted
  from the truth's velocity, vertical included, about the epoch's median clock drift): no
  spikes or blunders, so every window flagged (rows rejected or a fault it could not name) is a
  false alarm, to compare with α;
* ``clean, level``: the same rows with the truth's vertical velocity taken out of the Doppler
  (the model assumes a level road).

Each with NLOS data snooping off and on; figures over the moving epochs (truth speed above
``MOVING_MPS``), errors |heading − truth yaw| in degrees.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from benchmarks.real_heading import MOVING_MPS, calibration_truth, truth_velocity
from benchmarks.sequence_runs import read_with_truth, run_sequences
from vo_doppler.geo import wrap_angle
from vo_doppler.heading.tight_heading import antenna_offset_velocity, tight_heading_series
from vo_doppler.model.doppler import DopplerRows
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.timeseries import integral_at, sample
from vo_doppler.run_stages import RunConfig, sequence_gnss

ROOT = Path(__file__).resolve().parents[1]
CLEAN_SIGMAS = 4.0


def truth_residuals(sequence: Sequence, rows: DopplerRows) -> tuple[np.ndarray, np.ndarray]:
    """Per row (ENU rows): the reduced observation minus the truth's −G·v and the epoch's median
    clock drift, in units of the row's a-priori σ; and the truth's vertical velocity."""
    velocity = truth_velocity(sequence, rows.t)
    error = rows.reduced() + np.einsum("ij,ij->i", rows.los, velocity)
    epoch = np.unique(rows.t, return_inverse=True)[1].reshape(-1)
    drift = np.array([np.median(error[epoch == k]) for k in range(epoch.max() + 1)])
    return (error - drift[epoch]) / rows.sigma(), velocity[:, 2]


def row_cases(sequence: Sequence, rows: DopplerRows) -> dict[str, DopplerRows]:
    z, vertical = truth_residuals(sequence, rows)
    clean = np.abs(z) <= CLEAN_SIGMAS
    level = dataclasses.replace(rows, range_rate=rows.range_rate + rows.los[:, 2] * vertical)
    return {"recorded": rows, "clean": rows.select(clean), "clean, level": level.select(clean)}


def evaluate(folder: Path) -> dict:
    """The figures with the receiver's Doppler σ and with the σ fitted from the data."""
    sequence = read_with_truth(folder)
    return {noise: _variant(sequence, noise == "fitted") for noise in ("receiver", "fitted")}


def _variant(sequence: Sequence, fit_noise: bool) -> dict:
    config = RunConfig()
    rows = sequence_gnss(sequence, config, fit_noise).rows.in_enu()
    t = sequence.observations.epoch_time
    scale, bias = calibration_truth(sequence)
    rate = sample(sequence.yaw_rate.t, sequence.yaw_rate.value, t)
    speed = scale * sample(sequence.wheel_speed.t, sequence.wheel_speed.value, t)
    yaw_angle = integral_at(sequence.yaw_rate.t, sequence.yaw_rate.value, t) - bias * (t - t[0])
    lever = np.nan_to_num(antenna_offset_velocity(rate - bias, sequence.antenna_lever_arm_m))
    moving = np.linalg.norm(truth_velocity(sequence, t)[:, :2], axis=1) > MOVING_MPS
    truth_yaw = sequence.truth.yaw_at(t)
    tight = config.heading.tight
    figures = {"epochs": int(t.size), "moving": int(moving.sum()), "alpha": tight.outlier_alpha}
    cases = {}
    for name, case_rows in row_cases(sequence, rows).items():
        for snooping in ("off", "on"):
            passes = tight.outlier_passes if snooping == "on" else 0
            solver = dataclasses.replace(tight, outlier_passes=passes)
            result = tight_heading_series(
                case_rows, t, speed, yaw_angle, solver, lever_velocity=lever
            )
            cases[f"{name}|{snooping}"] = _figures(result, moving, truth_yaw, len(case_rows))
    figures["cases"] = cases
    return figures


def _figures(result, moving, truth_yaw, n_rows) -> dict:
    available = result.available & moving
    error = np.degrees(np.abs(wrap_angle(result.yaw - truth_yaw)))[available]
    fallback = getattr(result, "fallback", np.zeros_like(result.available))
    flagged = (result.n_rejected > 0) | result.inconsistent
    return {
        "rows": n_rows,
        "available": float(available.sum() / max(moving.sum(), 1)),
        "median_deg": float(np.median(error)) if error.size else None,
        "p95_deg": float(np.percentile(error, 95)) if error.size else None,
        "flagged": float(np.mean(flagged[moving])),
        "rejected": float(np.mean(result.n_rejected[moving] > 0)),
        "unnamed": float(np.mean(result.inconsistent[moving])),
        "fallback_epochs": int(np.count_nonzero(fallback & moving)),
    }


def _degrees(value: float | None) -> str:
    return "—" if value is None else f"{value:.2f}"


def print_sequence(console: Console, name: str, variants: dict) -> None:
    first = next(iter(variants.values()))
    table = Table(title=f"{name}: {first['moving']} moving epochs, α = {first['alpha']} per window")
    for column in (
        "Doppler σ",
        "rows",
        "snooping",
        "available",
        "median [°]",
        "p95 [°]",
        "windows flagged",
        "with rejection",
        "unnamed fault",
        "fallback epochs",
    ):
        table.add_column(column, justify="right")
    for noise, figures in variants.items():
        for key, f in figures["cases"].items():
            rows, snooping = key.split("|")
            table.add_row(
                noise,
                f"{rows} ({f['rows']})",
                snooping,
                f"{f['available']:.1%}",
                _degrees(f["median_deg"]),
                _degrees(f["p95_deg"]),
                f"{f['flagged']:.1%}",
                f"{f['rejected']:.1%}",
                f"{f['unnamed']:.1%}",
                str(f["fallback_epochs"]),
            )
    console.print(table)


def main(argv: list[str] | None = None) -> int:
    return run_sequences(
        __doc__.splitlines()[0],
        ROOT / "benchmarks" / "results" / "heading_real_noise.json",
        lambda folder, _, console: evaluate(folder),
        print_sequence,
        argv,
    )


if __name__ == "__main__":
    raise SystemExit(main())
