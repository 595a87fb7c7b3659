"""Tightly coupled and conventional heading on a drive whose GNSS antenna is off the vehicle
origin: the lever arm ignored (zero) and applied, against ground truth, side by side.

    python benchmarks/heading_lever_arm.py SEQUENCE_DIR [SEQUENCE_DIR ...] [--json FILE]

Each folder is a sequence with ground truth and ``gnss.antenna_lever_arm_m`` (images are not
read), e.g.

    vo-doppler simulate --scenario urban-canyon --duration 60 --seed 5 --size 320,180 \\
        --antenna-lever-arm 1.5,0,1.6 -o /tmp/lever

The heading stage runs as in ``vo-doppler run`` (systems, elevation mask, calibration); "used"
epochs are those the heading correction would use (available, reliable, σ < 2°); "turning"
epochs those where the true yaw rate exceeds ``TURN_RATE_DPS``. Errors are
|heading − ground-truth yaw| in degrees.
"""

from __future__ import annotations

import numpy as np
from rich.console import Console
from rich.table import Table

from benchmarks.heading_nlos import ROOT, _errors, _fmt, sequence_with_truth
from benchmarks.sequence_runs import run_sequences
from vo_doppler.fusion.correction import usable_tight_heading
from vo_doppler.geo import wrap_angle
from vo_doppler.heading.from_gnss import heading_from_gnss
from vo_doppler.model.timeseries import sample
from vo_doppler.model.vehicle_signals import VehicleSignals
from vo_doppler.run import RunConfig

TURN_RATE_DPS = 3.0


def evaluate(folder, _results_dir=None, _console=None) -> dict:
    inputs, gnss, truth_yaw = sequence_with_truth(folder)
    config = RunConfig()
    obs, truth = inputs.observations, inputs.truth
    rate = np.gradient(truth.yaw(), truth.t)
    turning = np.abs(np.degrees(np.nan_to_num(sample(truth.t, rate, obs.epoch_time))))
    turning = turning > TURN_RATE_DPS
    figures = {
        "epochs": len(obs.epoch_time),
        "turning": float(turning.mean()),
        "lever_arm_m": list(inputs.antenna_lever_arm_m),
        "variants": {},
    }
    for name, lever in (("ignored", (0.0, 0.0, 0.0)), ("applied", inputs.antenna_lever_arm_m)):
        table = heading_from_gnss(
            obs.epoch_time,
            gnss.rows,
            gnss.velocity,
            VehicleSignals(inputs.wheel_speed, inputs.yaw_rate),
            inputs.enu,
            config.heading,
            lever,
        )
        tc = np.degrees(np.abs(wrap_angle(table.yaw_tc - truth_yaw)))
        conv = np.degrees(np.abs(wrap_angle(table.yaw_conv - truth_yaw)))
        used = usable_tight_heading(table, config.correction.tc_max_sigma_rad)
        figures["variants"][name] = {
            "tc_used": _errors(tc, used),
            "tc_used_turning": _errors(tc, used & turning),
            "tc_used_straight": _errors(tc, used & ~turning),
            "conv_turning": _errors(conv, table.conv_valid & turning),
            "gyro_bias_dps": float(np.degrees(table.gyro_bias[-1])),
            "wheel_scale": float(table.wheel_scale[-1]),
        }
    return figures


def print_sequence(console: Console, name: str, figures: dict) -> None:
    lever = ", ".join(f"{v:g}" for v in figures["lever_arm_m"])
    table = Table(
        title=f"{name}: antenna at ({lever}) m, {figures['epochs']} epochs, "
        f"{figures['turning']:.0%} turning (> {TURN_RATE_DPS:g}°/s)"
    )
    for column in ("lever arm", "heading", "epochs", "rms [°]", "p95 [°]", "max [°]"):
        table.add_column(column, justify="right")
    labels = {
        "tc_used": "tight, used",
        "tc_used_turning": "tight, used, turning",
        "tc_used_straight": "tight, used, straight",
        "conv_turning": "conventional, turning",
    }
    for variant, f in figures["variants"].items():
        for key, label in labels.items():
            e = f[key]
            table.add_row(
                variant,
                label,
                f"{e['fraction']:.1%}",
                _fmt(e["rms_deg"], ".3f"),
                _fmt(e["p95_deg"], ".3f"),
                _fmt(e["max_deg"], ".3f"),
            )
    console.print(table)


def main(argv: list[str] | None = None) -> int:
    return run_sequences(
        __doc__.splitlines()[0],
        ROOT / "benchmarks/results/heading_lever_arm.json",
        evaluate,
        print_sequence,
        argv,
    )


if __name__ == "__main__":
    raise SystemExit(main())
