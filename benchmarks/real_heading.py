"""Heading on real recordings: conventional Doppler velocity and tight heading against ground
truth, the calibration against truth, standstill speeds, and an emulated street canyon.

    python benchmarks/real_heading.py SEQUENCE_DIR [SEQUENCE_DIR ...] [--json FILE]
        [--rate HZ] [--heading-method snooping|robust|both] [--noise receiver|fitted|both]
        [--calibration ls|kalman]

Each folder is a sequence with ground truth, e.g. the comma2k19 minute imported by

    vo-doppler import comma2k19 ../shared/data/comma2k19_example1 \\
        --orbits ../shared/data/comma2k19_example1/Sta20124_1400_1845.sp3 -o /tmp/comma

or the Hong Kong recordings built by ``python benchmarks/real_sequences.py /tmp/hk`` (vehicle
signals synthesised from the reference). ``--rate HZ`` decimates every sequence's GNSS to that
rate first (``benchmarks/decimate.py``: the epochs nearest whole seconds at 1 Hz; default: as
recorded; a recording at or below the rate is unchanged).

The GNSS and heading stages run as in ``vo-doppler run`` (``RunConfig``), with the receiver-
reported Doppler σ where the folder has one (else the a-priori C/N0 model) and with σ fitted
from the data for every row (``gnss.doppler_velocity.solve_with_fitted_noise``; the fitted
σ(C/N0, elevation) models are printed); the heading stage with each ``--heading-method``:
``snooping`` (``HeadingPipelineConfig()``, the default of ``run``) and ``robust``
(``HeadingPipelineConfig.robust()``, ``--heading-method robust``). Moving epochs: ground-truth
horizontal speed above ``MOVING_MPS`` (3 m/s); standstill: below ``STANDSTILL_MPS`` (0.2 m/s);
epochs outside the ground truth's span count as neither (the Hong Kong drive has truth for its
first half only). Figures:

* conventional velocity (epochs flagged valid): |speed error| and |course error| against the
  ground truth's velocity (differences of its positions, central, at the GNSS epochs; on
  comma2k19 they differ from global_pose's own velocities by 0.002 m/s median), median and p95,
  how many valid epochs fall beyond 1.5° and 15° and beyond 3σ of their own speed or course σ;
  as the GNSS stage flags them with its σ (vel.csv of ``vo-doppler gnss``), and as ``run`` and
  ``heading`` flag them in heading.csv after the gyro and wheel test, with that table's σ
  (``heading.integrity``, docs/design.md (I1));
* standstill: the valid epochs' horizontal speed as ``gnss velocity``'s vel.csv and as
  ``run``'s vel.csv flag them (the car's verdict, docs/design.md (I1c)): how many exceed
  0.2 m/s, p95 and max;
* calibration: the heading stage's wheel scale and gyro bias at the last epoch the vehicle
  signals cover, against the values that fit the ground truth with the same models
  (scale = Σ w·v / Σ w², bias = slope of ∫ω − ψ_truth);
* tight heading: availability (finite and reliable) over the moving epochs and |error| against
  the truth yaw, as recorded and, except on recordings that are real canyons
  (``RECORDED_CANYONS``) or stand still throughout, with an emulated canyon (the
  ``CANYON_SATS`` highest GPS satellites per epoch after ``CANYON_AFTER_S`` of open sky,
  ``heading.from_gnss.emulated_canyon``), and with that canyon from the first epoch (no
  conventional velocity ever calibrates: the gyro bias comes from the tight heading,
  ``heading.pipeline.tight_gyro_bias``); the dead reckoning's error per 100 m alone and
  corrected by either heading (``run``'s pipelines).

A folder without ground truth whose reference came from its own GNSS (``hk_klt_f9p_drive``,
built by ``benchmarks/real_sequences.py``, which writes the reference speed beside the
signals) gets self-consistency figures instead, since nothing measures its accuracy: moving
epochs are those of reference speed above ``MOVING_MPS``; the tight heading's availability over
them; its difference there from the valid conventional headings with σ below
``CONFIDENT_CONV_SIGMA_DEG`` (1°) where both exist (median, p95, how many beyond
``CONSISTENT_DEG``, 3°), with the conventional flags and σ of heading.csv (after the gyro and
wheel test, whose σ is the velocity's times that test's factor) and of the GNSS stage alone
(vel.csv); and the calibration against the synthesised gyro bias and wheel
scale (against the receiver's own speed).
"""

from __future__ import annotations

import argparse
import logging
from dataclasses import replace
from pathlib import Path

import numpy as np
from rich.console import Console
from rich.table import Table

from benchmarks.decimate import decimate, recorded_interval
from benchmarks.real_sequences import (
    GYRO_BIAS_RAD_S,
    HK_KLT_DRIVE,
    HK_TST_CANYON,
    WHEEL_SCALE,
    read_self_reference,
)
from benchmarks.sequence_runs import read_with_truth, run_sequences
from vo_doppler.choices import values
from vo_doppler.eval.pipelines import evaluate_pipelines
from vo_doppler.fusion.antenna_track import AntennaTrack
from vo_doppler.fusion.pipelines import Pipeline
from vo_doppler.geo import wrap_angle
from vo_doppler.heading.from_gnss import emulated_canyon
from vo_doppler.heading.integrity import car_checked_velocity
from vo_doppler.heading.pipeline import CalibrationMethod, HeadingPipelineConfig
from vo_doppler.io.sequence import read_sequence
from vo_doppler.model.heading import HeadingTable
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.series import SensorSeries
from vo_doppler.model.timeseries import integral_at, sample
from vo_doppler.run_stages import (
    RunConfig,
    sequence_gnss,
    sequence_heading,
    sequence_trajectories,
)

ROOT = Path(__file__).resolve().parents[1]
CANYON_SATS = 2
CANYON_AFTER_S = 20.0
COURSE_BOUND_DEG = 1.5
COURSE_GROSS_DEG = 15.0
MOVING_MPS = 3.0
STANDSTILL_MPS = 0.2
DEAD_RECKONING = (Pipeline.DR, Pipeline.DR_GPS_CONV, Pipeline.DR_GPS_TC)
HEADING_METHODS = {"snooping": HeadingPipelineConfig, "robust": HeadingPipelineConfig.robust}
NOISES = ("receiver", "fitted")
RECORDED_CANYONS = (HK_TST_CANYON.folder, HK_KLT_DRIVE.folder)
"""Recordings (by sequence name) made in real street canyons: no canyon is emulated on them."""
SELF_REFERENCED = "self-referenced"
"""The kind of a recording whose reference came from its own GNSS (module docstring)."""
CONFIDENT_CONV_SIGMA_DEG = 1.0
CONSISTENT_DEG = 3.0
CASE_LABELS = {
    "recorded": "as recorded",
    "canyon": "canyon",
    "canyon_start": "canyon from the start",
}


def truth_velocity(sequence: Sequence, t: np.ndarray) -> np.ndarray:
    """ENU velocity of the ground truth at ``t`` (central differences of its positions; NaN
    outside its span)."""
    truth = sequence.truth
    velocity = np.gradient(truth.positions, truth.t, axis=0)
    return np.column_stack([sample(truth.t, velocity[:, i], t) for i in range(3)])


def truth_speed(sequence: Sequence, t: np.ndarray) -> np.ndarray:
    """Horizontal ground-truth speed at ``t`` (NaN outside the truth's span)."""
    return np.linalg.norm(truth_velocity(sequence, t)[:, :2], axis=1)


def calibration_truth(sequence: Sequence) -> tuple[float, float]:
    """(wheel scale, gyro bias rad/s) fitted to the ground truth with the calibration's models:
    the bias is the slope of the integrated yaw rate minus the truth's yaw (its orientation,
    unwrapped over the whole drive: a course from the velocity turns at random while stopped),
    over the moving epochs. For a recording that never moves the scale is NaN and the bias
    fits every epoch the signals cover."""
    truth = sequence.truth
    t = truth.t
    speed = np.linalg.norm(truth_velocity(sequence, t), axis=1)  # the wheels roll on grades
    wheel = sample(sequence.wheel_speed.t, sequence.wheel_speed.value, t)
    moving = np.isfinite(wheel) & (truth_speed(sequence, t) > MOVING_MPS)
    scale = float("nan")
    if moving.any():
        scale = float(np.sum(wheel[moving] * speed[moving]) / np.sum(wheel[moving] ** 2))
    phi = integral_at(sequence.yaw_rate.t, sequence.yaw_rate.value, t)
    yaw = np.unwrap(truth.yaw())
    ok = np.isfinite(phi) & (moving if moving.any() else np.isfinite(wheel))
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
    """Figures of the conventional velocity's valid moving epochs against the truth: as the
    GNSS stage flags them with its σ (``vo-doppler gnss``, vel.csv), or, given the heading
    stage's ``table``, as ``run`` and ``heading`` flag them after the gyro and wheel test with
    the table's σ (heading.csv)."""
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
        "valid_course_beyond_15deg": int((valid & (course_error > COURSE_GROSS_DEG)).sum()),
        "valid_beyond_3_sigma": int(beyond.sum()),
    }


def standstill_figures(sequence: Sequence, velocity, table: HeadingTable | None = None) -> dict:
    """The horizontal speed of the conventional velocity's valid epochs while the truth stands
    (speed below ``STANDSTILL_MPS``): as ``gnss velocity``'s vel.csv flags them, or with
    ``table`` as ``run``'s vel.csv does (the car's verdict, docs/design.md (I1c)). The true
    speed is zero, so the speed is the error."""
    standing = truth_speed(sequence, velocity.t) < STANDSTILL_MPS
    valid = velocity.valid & standing
    if table is not None:
        valid = car_checked_velocity(velocity, table).valid & standing
    speed = np.linalg.norm(velocity.velocity_enu[:, :2], axis=1)
    return {
        "standstill_epochs": int(standing.sum()),
        "valid": float(valid.sum() / max(standing.sum(), 1)),
        "valid_above_standstill": int((valid & (speed > STANDSTILL_MPS)).sum()),
        "speed_mps": _stats(speed[valid]),
    }


def _last_signal_epoch(sequence: Sequence, t: np.ndarray) -> int:
    """Index of the last epoch the wheel speed covers (the last epoch when none does)."""
    inside = np.isfinite(sample(sequence.wheel_speed.t, sequence.wheel_speed.value, t))
    return int(np.flatnonzero(inside)[-1]) if inside.any() else t.size - 1


def tight_figures(sequence: Sequence, table, epochs: np.ndarray) -> dict:
    """Heading figures over the moving epochs among ``epochs`` (mask); the tight heading is
    available where it is finite and reliable (issue 11's definition). The calibration is the
    table's at the last epoch the vehicle signals cover (after it the table holds it)."""
    moving = (truth_speed(sequence, table.t) > MOVING_MPS) & epochs
    truth_yaw = sequence.truth.yaw_at(table.t)
    error = np.degrees(np.abs(wrap_angle(table.yaw_tc - truth_yaw)))
    available = table.tc_available & table.tc_reliable & moving
    conventional = table.conv_valid & moving
    conv_error = np.degrees(np.abs(wrap_angle(table.yaw_conv - truth_yaw)))
    last = _last_signal_epoch(sequence, table.t)
    return {
        "moving_epochs": int(moving.sum()),
        "tc_available": float(available.sum() / max(moving.sum(), 1)),
        "tc_error_deg": _stats(error[available]),
        "conv_valid": float(conventional.sum() / max(moving.sum(), 1)),
        "conv_error_deg": _stats(conv_error[conventional]),
        "wheel_scale": float(table.wheel_scale[last]),
        "gyro_bias_dps": float(np.degrees(table.gyro_bias[last])),
    }


def tight_against_conventional(
    table: HeadingTable, epochs: np.ndarray, valid: np.ndarray, sigma: np.ndarray
) -> dict:
    """|tight − conventional heading| (°) at the ``epochs`` (mask) with a reliable tight
    heading and a ``valid`` conventional one whose ``sigma`` (rad) is below
    ``CONFIDENT_CONV_SIGMA_DEG``."""
    confident = epochs & valid & (sigma < np.radians(CONFIDENT_CONV_SIGMA_DEG))
    both = table.tc_available & table.tc_reliable & confident
    difference = np.degrees(np.abs(wrap_angle(table.yaw_tc - table.yaw_conv)))[both]
    return {
        "conv_confident_epochs": int(confident.sum()),
        "compared_epochs": int(both.sum()),
        "tc_minus_conv_deg": _stats(difference),
        "beyond_consistent": int((difference > CONSISTENT_DEG).sum()),
    }


def self_consistency_figures(table: HeadingTable, reference: SensorSeries) -> dict:
    """The tight heading's availability over the moving epochs by the ``reference`` speed, and
    its difference there from the confident conventional headings as heading.csv and as the
    GNSS stage flag them (module docstring). The calibration is the table's at the last epoch."""
    moving = sample(reference.t, reference.value, table.t) > MOVING_MPS
    tight = table.tc_available & table.tc_reliable
    return {
        "moving_epochs": int(moving.sum()),
        "tc_available": float((tight & moving).sum() / max(moving.sum(), 1)),
        "conv_valid": float((table.conv_valid & moving).sum() / max(moving.sum(), 1)),
        "against": {
            "heading.csv": tight_against_conventional(
                table, moving, table.conv_valid, table.sigma_conv
            ),
            "GNSS stage": tight_against_conventional(table, moving, *table.published_conventional),
        },
        "wheel_scale": float(table.wheel_scale[-1]),
        "gyro_bias_dps": float(np.degrees(table.gyro_bias[-1])),
    }


def evaluate_self_referenced(
    sequence: Sequence,
    reference: SensorSeries,
    fit_noise: bool,
    methods: tuple[str, ...] = ("snooping",),
    calibration: str = "ls",
) -> dict:
    """The self-consistency figures of a recording without ground truth, per heading method."""
    config = RunConfig()
    obs = sequence.observations
    gnss = sequence_gnss(sequence, config, fit_noise)
    figures = {
        "epochs": int(obs.epoch_time.size),
        "rate_hz": 1.0 / recorded_interval(obs.epoch_time),
        "kind": SELF_REFERENCED,
        "synthesised_wheel_scale": 1.0 / WHEEL_SCALE,
        "synthesised_gyro_bias_dps": float(np.degrees(GYRO_BIAS_RAD_S)),
        "doppler_noise": [model.to_dict() for model in gnss.noise_models.values()],
        "methods": {},
    }
    for method in methods:
        heading = heading_config(method, calibration)
        table = sequence_heading(sequence, gnss.rows, gnss.velocity, heading)
        figures["methods"][method] = {
            "self_consistency": self_consistency_figures(table, reference),
            "warnings": list(table.warnings),
        }
    return figures


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
        config.elevation_mask_rad,
        reported_sigma=sequence.doppler_sigma,
    )


def dead_reckoning_figures(sequence: Sequence, table: HeadingTable, config: RunConfig) -> dict:
    """Error per 100 m (m) of the wheel + gyro dead reckoning alone, corrected by the
    conventional and by the tightly coupled heading of ``table`` (``run``'s pipelines), over
    the time the ground truth covers. Without any absolute heading (no valid conventional
    heading, no reliable tight one) nothing places the trajectories, which ``run`` starts
    facing east with a warning: no figure (None) rather than that arbitrary start's."""
    if not (table.conv_valid.any() or (table.tc_available & table.tc_reliable).any()):
        return {str(name): None for name in DEAD_RECKONING}
    speed = table.calibrated_speed(sequence.wheel_speed)
    origin = AntennaTrack(np.zeros(0), np.zeros((1, 3)))  # the figures align the starts
    trajectories, usable = sequence_trajectories(sequence, table, None, speed, origin, config)
    errors, _, _ = evaluate_pipelines(trajectories, table, usable, sequence.truth)
    return {str(name): errors[name].error_per_100m_m for name in DEAD_RECKONING if name in errors}


def recording_kind(sequence: Sequence) -> str:
    """'standstill' (the truth never moves), 'real canyon' (``RECORDED_CANYONS``) or 'open
    sky' (the canyon is emulated)."""
    if not np.any(truth_speed(sequence, sequence.observations.epoch_time) > MOVING_MPS):
        return "standstill"
    return "real canyon" if sequence.name in RECORDED_CANYONS else "open sky"


def heading_config(method: str, calibration: str) -> HeadingPipelineConfig:
    """The heading stage's configuration of ``--heading-method`` with ``--calibration``."""
    return replace(HEADING_METHODS[method](), calibration=calibration)


def evaluate(
    sequence: Sequence,
    fit_noise: bool,
    methods: tuple[str, ...] = ("snooping",),
    calibration: str = "ls",
) -> dict:
    """The figures of one sequence with one Doppler noise model, per heading method."""
    config = RunConfig()
    obs = sequence.observations
    gnss = sequence_gnss(sequence, config, fit_noise)
    kind = recording_kind(sequence)
    inputs = {"recorded": (gnss.rows, gnss.velocity)}
    if kind == "open sky":
        inputs["canyon"] = canyon_inputs(sequence, config)
        inputs["canyon_start"] = canyon_inputs(sequence, config, after_s=0.0)
    after = obs.epoch_time >= obs.epoch_time[0] + CANYON_AFTER_S
    every = np.ones(after.size, dtype=bool)
    scored = {"recorded": every, "canyon": after, "canyon_start": every}
    scale_truth, bias_truth = calibration_truth(sequence)
    figures = {
        "epochs": int(obs.epoch_time.size),
        "rate_hz": 1.0 / recorded_interval(obs.epoch_time),
        "kind": kind,
        "conventional_gnss": conventional_figures(sequence, gnss.velocity),
        "standstill_gnss": standstill_figures(sequence, gnss.velocity),
        "truth_wheel_scale": scale_truth if np.isfinite(scale_truth) else None,
        "truth_gyro_bias_dps": float(np.degrees(bias_truth)),
        "doppler_noise": [model.to_dict() for model in gnss.noise_models.values()],
        "methods": {},
    }
    for method in methods:
        run_config = replace(config, heading=heading_config(method, calibration))
        tables = {
            case: sequence_heading(sequence, rows, velocity, run_config.heading)
            for case, (rows, velocity) in inputs.items()
        }
        recorded = tables["recorded"]
        figures["methods"][method] = {
            "conventional": conventional_figures(sequence, gnss.velocity, recorded),
            "standstill": standstill_figures(sequence, gnss.velocity, recorded),
            "cases": {
                case: tight_figures(sequence, table, scored[case]) for case, table in tables.items()
            },
            "dead_reckoning": {
                case: dead_reckoning_figures(sequence, table, run_config)
                for case, table in tables.items()
                if kind != "standstill"
            },
            "warnings": list(recorded.warnings),
        }
    return figures


def evaluate_folder(
    folder: Path,
    rate_hz: float | None,
    noises: tuple[str, ...],
    methods: tuple[str, ...],
    calibration: str,
) -> dict:
    """Every noise variant of one folder, decimated to ``rate_hz`` when given; a folder
    whose reference came from its own GNSS gets the self-consistency figures."""
    reference = read_self_reference(folder)
    sequence = read_with_truth(folder) if reference is None else read_sequence(folder)
    if rate_hz is not None:
        sequence = decimate(sequence, rate_hz)
    logging.disable(logging.WARNING)  # the tables' warnings go to the JSON
    try:
        if reference is not None:
            return {
                noise: evaluate_self_referenced(
                    sequence, reference, noise == "fitted", methods, calibration
                )
                for noise in noises
            }
        return {
            noise: evaluate(sequence, noise == "fitted", methods, calibration) for noise in noises
        }
    finally:
        logging.disable(logging.NOTSET)


def _fmt(value, spec: str) -> str:
    return "—" if value is None or not np.isfinite(value) else format(value, spec)


def print_sequence(console: Console, name: str, variants: dict) -> None:
    for noise, figures in variants.items():
        rate = f"{figures['rate_hz']:.3g} Hz"
        print_variant(console, f"{name} at {rate}, {noise} Doppler noise", figures)


def _table(title: str, columns: tuple[str, ...]) -> Table:
    table = Table(title=title)
    for column in columns:
        table.add_column(column, justify="right")
    return table


def _flag_rows(figures: dict, gnss_key: str, key: str) -> list[tuple[str, dict]]:
    """(label, figures) as the GNSS stage flags the epochs, then as each method's heading.csv."""
    rows = [("GNSS stage", figures[gnss_key])]
    return rows + [(f"+ gyro/wheel, {m}", f[key]) for m, f in figures["methods"].items()]


def print_variant(console: Console, name: str, figures: dict) -> None:
    if figures["kind"] == SELF_REFERENCED:
        print_self_consistency(console, name, figures)
        print_noise(console, name, figures)
        return
    moving = figures["conventional_gnss"]["moving_epochs"]
    table = _table(
        f"{name}: conventional Doppler velocity ({figures['epochs']} epochs, {moving} moving)",
        (
            "flags, σ",
            "valid",
            "verified",
            "speed med",
            "speed p95",
            "course med [°]",
            "course p95 [°]",
            "> 1.5°",
            "> 15°",
            "> 3σ",
        ),
    )
    for label, c in _flag_rows(figures, "conventional_gnss", "conventional"):
        speed, course = c["speed_error_mps"], c["course_error_deg"]
        table.add_row(
            label,
            f"{c['valid']:.1%}",
            f"{c['verified']:.1%}",
            *(_fmt(speed[k], ".3f") for k in ("median", "p95")),
            *(_fmt(course[k], ".2f") for k in ("median", "p95")),
            *(str(c[k]) for k in ("valid_course_beyond_bound", "valid_course_beyond_15deg")),
            str(c["valid_beyond_3_sigma"]),
        )
    if moving:
        console.print(table)
    if figures["standstill_gnss"]["standstill_epochs"]:
        print_standstill(console, name, figures)
    if figures["kind"] != "standstill":
        print_heading(console, name, figures)
    print_noise(console, name, figures)


def print_noise(console: Console, name: str, figures: dict) -> None:
    noise = _table(
        f"{name}: Doppler σ model fitted from the data (gnss.noise_model)",
        ("signal", "σ at 45 dB-Hz, zenith [m/s]", "C/N0 slope", "elevation exponent"),
    )
    for model in figures["doppler_noise"]:
        noise.add_row(
            f"{model['system']} {model['code']}",
            f"{model['sigma_ref_mps']:.3f}",
            f"{model['cn0_slope']:.2f}",
            f"{model['elevation_exponent']:.2f}",
        )
    console.print(noise)


def print_standstill(console: Console, name: str, figures: dict) -> None:
    table = _table(
        f"{name}: conventional speed at standstill (truth < {STANDSTILL_MPS} m/s)",
        ("flags", "standstill epochs", "valid", "valid > 0.2 m/s", "p95 [m/s]", "max"),
    )
    for label, s in _flag_rows(figures, "standstill_gnss", "standstill"):
        speed = s["speed_mps"]
        table.add_row(
            label,
            str(s["standstill_epochs"]),
            f"{s['valid']:.1%}",
            str(s["valid_above_standstill"]),
            *(_fmt(speed[k], ".3f") for k in ("p95", "max")),
        )
    console.print(table)


def print_heading(console: Console, name: str, figures: dict) -> None:
    heading = _table(
        f"{name}: tight heading and calibration",
        (
            "method",
            "case",
            "tc avail",
            "tc med [°]",
            "tc p95 [°]",
            "conv valid",
            "conv p95 [°]",
            "wheel scale (truth)",
            "gyro bias °/s (truth)",
            "DR alone / + conv / + TC [m/100 m]",
        ),
    )
    truth = (
        f"({_fmt(figures['truth_wheel_scale'], '.4f')})",
        f"({figures['truth_gyro_bias_dps']:.3f})",
    )
    for method, m in figures["methods"].items():
        for case, f in m["cases"].items():
            dr = m["dead_reckoning"][case]
            heading.add_row(
                method,
                CASE_LABELS[case],
                f"{f['tc_available']:.1%}",
                *(_fmt(f["tc_error_deg"][k], ".2f") for k in ("median", "p95")),
                f"{f['conv_valid']:.1%}",
                _fmt(f["conv_error_deg"]["p95"], ".2f"),
                f"{f['wheel_scale']:.4f} {truth[0]}",
                f"{f['gyro_bias_dps']:.3f} {truth[1]}",
                " / ".join(_fmt(dr.get(name), ".2f") for name in DEAD_RECKONING),
            )
    console.print(heading)


def print_self_consistency(console: Console, name: str, figures: dict) -> None:
    sigma = f"σ < {CONFIDENT_CONV_SIGMA_DEG:g}°"
    table = _table(
        f"{name}: self-consistency, no ground truth (reference from the receiver's own GNSS)",
        (
            "method",
            "moving",
            "tc avail",
            "conv valid",
            "conv flags",
            f"valid, {sigma}",
            "compared",
            "|tc − conv| med [°]",
            "p95 [°]",
            f"> {CONSISTENT_DEG:g}°",
            "wheel scale (synth.)",
            "gyro bias °/s (synth.)",
        ),
    )
    for method, m in figures["methods"].items():
        f = m["self_consistency"]
        for flags, c in f["against"].items():
            difference = c["tc_minus_conv_deg"]
            table.add_row(
                method,
                str(f["moving_epochs"]),
                f"{f['tc_available']:.1%}",
                f"{f['conv_valid']:.1%}",
                flags,
                str(c["conv_confident_epochs"]),
                str(c["compared_epochs"]),
                *(_fmt(difference[k], ".2f") for k in ("median", "p95")),
                str(c["beyond_consistent"]),
                f"{f['wheel_scale']:.4f} ({figures['synthesised_wheel_scale']:.4f})",
                f"{f['gyro_bias_dps']:.3f} ({figures['synthesised_gyro_bias_dps']:.3f})",
            )
    console.print(table)


def _choice(value: str, names: tuple[str, ...]) -> tuple[str, ...]:
    return names if value == "both" else (value,)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="real_heading.py", add_help=False, description="This benchmark's own options:"
    )
    parser.add_argument("--calibration", choices=values(CalibrationMethod), default="ls")
    parser.add_argument(
        "--rate",
        type=float,
        default=None,
        metavar="HZ",
        help="decimate every sequence's GNSS to this rate (default: as recorded)",
    )
    parser.add_argument(
        "--heading-method",
        choices=(*HEADING_METHODS, "both"),
        default="both",
        help="the heading stage's method (default: both)",
    )
    parser.add_argument(
        "--noise",
        choices=(*NOISES, "both"),
        default="both",
        help="Doppler σ: the receiver's (else the C/N0 model) or fitted (default: both)",
    )
    chosen, rest = parser.parse_known_args(argv)
    if {"-h", "--help"} & set(rest):
        parser.print_help()
    if chosen.rate is not None and not chosen.rate > 0:
        parser.error(f"--rate {chosen.rate}: give a positive rate in Hz")
    methods = _choice(chosen.heading_method, tuple(HEADING_METHODS))
    noises = _choice(chosen.noise, NOISES)
    suffix = "" if chosen.rate is None else f"_{chosen.rate:g}hz"
    return run_sequences(
        __doc__.splitlines()[0],
        ROOT / "benchmarks" / "results" / f"real_heading{suffix}.json",
        lambda folder, _, console: evaluate_folder(
            folder, chosen.rate, noises, methods, chosen.calibration
        ),
        print_sequence,
        rest,
    )


if __name__ == "__main__":
    raise SystemExit(main())
