"""Heading on real recordings: conventional Doppler velocity and tight heading against ground
truth, the calibration against truth, and an emulated street canyon.

    python benchmarks/real_heading.py SEQUENCE_DIR [SEQUENCE_DIR ...] [--json FILE]
        [--calibration ls|kalman]

Each folder is a sequence with ground truth, e.g. the comma2k19 minute imported by

    vo-doppler import comma2k19 ../shared/data/comma2k19_example1 \\
        --orbits ../shared/data/comma2k19_example1/Sta20124_1400_1845.sp3 -o /tmp/comma

The GNSS and heading stages run as in ``vo-doppler run`` (``RunConfig``), twice: with the
receiver-reported Doppler σ where the folder has one (else the a-priori C/N0 model), and with
σ fitted from the data for every row (``gnss.doppler_velocity.solve_with_fitted_noise``; the
fitted σ(C/N0, elevation) models are printed). Figures:

* conventional velocity (epochs flagged valid): |speed error| and |course error| against the
  ground truth's velocity (differences of its positions, central, at the GNSS epochs; on
  comma2k19 they differ from global_pose's own velocities by 0.002 m/s median), median and p95,
  how many valid epochs fall beyond 1.5° and beyond 3σ of their own speed or course σ; twice:
  as the GNSS stage flags them with its σ (vel.csv of ``vo-doppler gnss``), and as ``run`` and
  ``heading`` flag them in heading.csv after the gyro and wheel test, with that table's σ
  (``heading.integrity``, docs/design.md (I1));
* calibration: the heading stage's final wheel scale and gyro bias against the values that fit
  the ground truth with the same models (scale = Σ w·v / Σ w², bias = slope of ∫ω − ψ_truth);
* tight heading: availability and |error| against the truth yaw, open sky and with an
  emulated canyon (the ``CANYON_SATS`` highest GPS satellites per epoch after ``CANYON_AFTER_S``
  of open sky, ``heading.from_gnss.emulated_canyon``), and with that canyon from the first
  epoch (no conventional velocity ever calibrates: the gyro bias comes from the tight heading,
  ``heading.pipeline.tight_gyro_bias``).
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from benchmarks.sequence_runs import read_with_truth, run_sequences
from vo_doppler.eval.pipelines import evaluate_pipelines
from vo_doppler.fusion.correction import usable_tight_heading
from vo_doppler.geo import wrap_angle
from vo_doppler.heading.from_gnss import emulated_canyon
from vo_doppler.heading.pipeline import CALIBRATION_METHODS
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.timeseries import integral_at, sample
from vo_doppler.run import (
    AntennaTrack,
    Pipeline,
    RunConfig,
    correct_all,
    sequence_gnss,
    sequence_heading,
)

ROOT = Path(__file__).resolve().parents[1]
CANYON_SATS = 2
CANYON_AFTER_S = 20.0
COURSE_BOUND_DEG = 1.5
MOVING_MPS = 2.0
DEAD_RECKONING = (Pipeline.DR, Pipeline.DR_GPS_CONV, Pipeline.DR_GPS_TC)


def truth_velocity(sequence: Sequence, t: np.ndarray) -> np.ndarray:
    """ENU velocity of the ground truth at ``t`` (central differences of its positions)."""
    truth = sequence.truth
    velocity = np.gradient(truth.positions, truth.t, axis=0)
    return np.column_stack([sample(truth.t, velocity[:, i], t) for i in range(3)])


def calibration_truth(sequence: Sequence) -> tuple[float, float]:
    """(wheel scale, gyro bias rad/s) fitted to the ground truth with the calibration's models:
    the bias is the slope of the integrated yaw rate minus the truth's yaw (its orientation,
    unwrapped over the whole drive: a course from the velocity turns at random while stopped)."""
    truth = sequence.truth
    t = truth.t
    velocity = truth_velocity(sequence, t)
    speed = np.linalg.norm(velocity, axis=1)
    wheel = sample(sequence.wheel_speed.t, sequence.wheel_speed.value, t)
    ok = np.isfinite(wheel) & (speed > MOVING_MPS)
    scale = float(np.sum(wheel[ok] * speed[ok]) / np.sum(wheel[ok] ** 2))
    phi = integral_at(sequence.yaw_rate.t, sequence.yaw_rate.value, t)
    yaw = np.unwrap(truth.yaw())
    ok &= np.isfinite(phi)
    design = np.column_stack([np.ones(ok.sum()), t[ok] - t[ok].mean()])
    bias = float(np.linalg.lstsq(design, phi[ok] - yaw[ok], rcond=None)[0][1])
    return scale, bias


def _stats(values: np.ndarray) -> dict:
    if not values.size:
        return {"median": None, "p95": None, "max": None}
    return {
        "median": float(np.median(values)),
        "p95": float(np.percentile(values, 95)),
        "max": float(np.max(values)),
    }


def conventional_figures(sequence: Sequence, velocity, table: HeadingTable | None = None) -> dict:
    """Figures of the conventional velocity's valid epochs against the truth: as the GNSS
    stage flags them with its σ (``vo-doppler gnss``, vel.csv), or, given the heading stage's
    ``table``, as ``run`` and ``heading`` flag them after the gyro and wheel test with the
    table's σ (heading.csv)."""
    truth = truth_velocity(sequence, velocity.t)
    moving = np.linalg.norm(truth[:, :2], axis=1) > MOVING_MPS
    valid = velocity.valid & moving
    speed_sigma, course_sigma = velocity.speed_sigma_mps, velocity.course_sigma_rad
    if table is not None:
        valid &= table.conv_valid
        speed_sigma, course_sigma = table.speed_sigma_conv, table.sigma_conv
    speed_error = np.abs(
        np.linalg.norm(velocity.velocity_enu[:, :2], axis=1) - np.linalg.norm(truth[:, :2], axis=1)
    )
    course = np.arctan2(velocity.velocity_enu[:, 1], velocity.velocity_enu[:, 0])
    course_error = np.degrees(np.abs(wrap_angle(course - np.arctan2(truth[:, 1], truth[:, 0]))))
    beyond = valid & (
        (speed_error > 3.0 * speed_sigma) | (course_error > 3.0 * np.degrees(course_sigma))
    )
    return {
        "moving_epochs": int(moving.sum()),
        "valid": float(valid.sum() / max(moving.sum(), 1)),
        "verified": float((velocity.verified & moving).sum() / max(moving.sum(), 1)),
        "speed_error_mps": _stats(speed_error[valid]),
        "course_error_deg": _stats(course_error[valid]),
        "valid_course_beyond_bound": int((valid & (course_error > COURSE_BOUND_DEG)).sum()),
        "valid_beyond_3_sigma": int(beyond.sum()),
    }


def tight_figures(sequence: Sequence, table, epochs: np.ndarray) -> dict:
    """Heading figures over the moving epochs among ``epochs`` (mask); the tight heading is
    available where it is finite and reliable (issue 11's definition)."""
    truth = truth_velocity(sequence, table.t)
    moving = (np.linalg.norm(truth[:, :2], axis=1) > MOVING_MPS) & epochs
    truth_yaw = sequence.truth.yaw_at(table.t)
    error = np.degrees(np.abs(wrap_angle(table.yaw_tc - truth_yaw)))
    available = table.tc_available & table.tc_reliable & moving
    conventional = table.conv_valid & moving
    conv_error = np.degrees(np.abs(wrap_angle(table.yaw_conv - truth_yaw)))
    return {
        "tc_available": float(available.sum() / max(moving.sum(), 1)),
        "tc_error_deg": _stats(error[available]),
        "conv_valid": float(conventional.sum() / max(moving.sum(), 1)),
        "conv_error_deg": _stats(conv_error[conventional]),
        "wheel_scale": float(table.wheel_scale[-1]),
        "gyro_bias_dps": float(np.degrees(table.gyro_bias[-1])),
    }


def canyon_inputs(sequence: Sequence, config: RunConfig, after_s: float = CANYON_AFTER_S):
    """Doppler rows and conventional velocities of the emulated canyon from ``after_s`` into
    the recording (module docstring)."""
    obs = sequence.observations
    return emulated_canyon(
        obs,
        sequence.navigation,
        CANYON_SATS,
        obs.epoch_time[0] + after_s,
        "G",
        config.elevation_mask,
        reported_sigma=sequence.doppler_sigma,
    )


def dead_reckoning_figures(sequence: Sequence, table: HeadingTable, config: RunConfig) -> dict:
    """Error per 100 m (m) of the wheel + gyro dead reckoning alone, corrected by the
    conventional and by the tightly coupled heading of ``table`` (``run``'s pipelines)."""
    speed = table.calibrated_speed(sequence.wheel_speed)
    origin = AntennaTrack(np.zeros(0), np.zeros((1, 3)))  # the figures align the starts
    trajectories = correct_all(sequence, table, None, speed, origin, config)
    usable = usable_tight_heading(table, config.correction.tc_max_sigma)
    errors, _, _ = evaluate_pipelines(trajectories, table, usable, sequence.truth)
    return {str(name): errors[name].error_per_100m_m for name in DEAD_RECKONING if name in errors}


def evaluate(folder: Path, fit_noise: bool, calibration: str = "ls") -> dict:
    sequence = read_with_truth(folder)
    config = RunConfig()
    config = replace(config, heading=replace(config.heading, calibration=calibration))
    obs = sequence.observations
    gnss = sequence_gnss(sequence, config, fit_noise)
    scale_truth, bias_truth = calibration_truth(sequence)
    open_sky = sequence_heading(sequence, gnss.rows, gnss.velocity, config.heading)
    canyon = sequence_heading(sequence, *canyon_inputs(sequence, config), config.heading)
    canyon_start = sequence_heading(
        sequence, *canyon_inputs(sequence, config, after_s=0.0), config.heading
    )
    after = obs.epoch_time >= obs.epoch_time[0] + CANYON_AFTER_S
    every = np.ones(after.size, dtype=bool)
    figures = {
        "epochs": int(obs.epoch_time.size),
        "conventional_gnss": conventional_figures(sequence, gnss.velocity),
        "conventional": conventional_figures(sequence, gnss.velocity, open_sky),
        "truth_wheel_scale": scale_truth,
        "truth_gyro_bias_dps": float(np.degrees(bias_truth)),
        "open_sky": tight_figures(sequence, open_sky, every),
        "canyon": tight_figures(sequence, canyon, after),
        "canyon_start": tight_figures(sequence, canyon_start, every),
        "dead_reckoning": {
            "open_sky": dead_reckoning_figures(sequence, open_sky, config),
            "canyon": dead_reckoning_figures(sequence, canyon, config),
            "canyon_start": dead_reckoning_figures(sequence, canyon_start, config),
        },
        "doppler_noise": [model.to_dict() for model in gnss.noise_models.values()],
    }
    return figures


def _fmt(value, spec: str) -> str:
    return "—" if value is None else format(value, spec)


def print_sequence(console: Console, name: str, variants: dict) -> None:
    for noise, figures in variants.items():
        print_variant(console, f"{name}, {noise} Doppler noise", figures)


def print_variant(console: Console, name: str, figures: dict) -> None:
    table = Table(title=f"{name}: conventional Doppler velocity ({figures['epochs']} epochs)")
    for column in (
        "flags, σ",
        "valid",
        "verified",
        "speed med",
        "speed p95",
        "course med [°]",
        "course p95 [°]",
        "> 1.5°",
        "> 3σ",
    ):
        table.add_column(column, justify="right")
    for label, key in (("GNSS stage", "conventional_gnss"), ("+ gyro/wheel", "conventional")):
        c = figures[key]
        table.add_row(
            label,
            f"{c['valid']:.1%}",
            f"{c['verified']:.1%}",
            _fmt(c["speed_error_mps"]["median"], ".3f"),
            _fmt(c["speed_error_mps"]["p95"], ".3f"),
            _fmt(c["course_error_deg"]["median"], ".2f"),
            _fmt(c["course_error_deg"]["p95"], ".2f"),
            str(c["valid_course_beyond_bound"]),
            str(c["valid_beyond_3_sigma"]),
        )
    console.print(table)
    heading = Table(title=f"{name}: tight heading and calibration")
    for column in (
        "case",
        "tc avail",
        "tc med [°]",
        "tc p95 [°]",
        "conv valid",
        "conv p95 [°]",
        "wheel scale (truth)",
        "gyro bias °/s (truth)",
        "DR alone / + conv / + TC [m per 100 m]",
    ):
        heading.add_column(column, justify="right")
    for case in ("open_sky", "canyon", "canyon_start"):
        f = figures[case]
        dr = figures["dead_reckoning"][case]
        heading.add_row(
            case,
            f"{f['tc_available']:.1%}",
            _fmt(f["tc_error_deg"]["median"], ".2f"),
            _fmt(f["tc_error_deg"]["p95"], ".2f"),
            f"{f['conv_valid']:.1%}",
            _fmt(f["conv_error_deg"]["p95"], ".2f"),
            f"{f['wheel_scale']:.4f} ({figures['truth_wheel_scale']:.4f})",
            f"{f['gyro_bias_dps']:.3f} ({figures['truth_gyro_bias_dps']:.3f})",
            " / ".join(_fmt(dr.get(name), ".2f") for name in DEAD_RECKONING),
        )
    console.print(heading)
    noise = Table(title=f"{name}: Doppler σ model fitted from the data (gnss.noise_model)")
    for column in ("signal", "σ at 45 dB-Hz, zenith [m/s]", "C/N0 slope", "elevation exponent"):
        noise.add_column(column, justify="right")
    for model in figures["doppler_noise"]:
        noise.add_row(
            f"{model['system']} {model['code']}",
            f"{model['sigma_ref_mps']:.3f}",
            f"{model['cn0_slope']:.2f}",
            f"{model['elevation_exponent']:.2f}",
        )
    console.print(noise)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(add_help=False)
    parser.add_argument("--calibration", choices=CALIBRATION_METHODS, default="ls")
    chosen, rest = parser.parse_known_args(argv)
    return run_sequences(
        __doc__.splitlines()[0],
        ROOT / "benchmarks" / "results" / "real_heading.json",
        lambda folder, _, console: {
            noise: evaluate(folder, noise == "fitted", chosen.calibration)
            for noise in ("receiver", "fitted")
        },
        print_sequence,
        rest,
    )


if __name__ == "__main__":
    raise SystemExit(main())
