"""Everything ``vo-doppler run`` writes for one recording, as one library call shared with
``vo-doppler batch``: the trajectories (TUM and GeoJSON), the heading table (CSV), the figures
(PNG), the summary (JSON) and the self-contained HTML report."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from vo_doppler.eval.metrics import segment_lengths_note, segment_lengths_that_fit
from vo_doppler.eval.pipelines import epochs_within
from vo_doppler.eval.run_evaluation import evaluate_run
from vo_doppler.heading.integrity import car_checked_velocity
from vo_doppler.io.gnss_csv import write_velocity_csv
from vo_doppler.io.heading_csv import write_heading_csv
from vo_doppler.io.satellite_states import state_problems
from vo_doppler.io.sequence import InputReport
from vo_doppler.io.trajectory import write_tum
from vo_doppler.memory import release_cycles
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.timeseries import travelled_distance
from vo_doppler.report.heading_figure import build_heading_figure
from vo_doppler.report.json_text import json_text
from vo_doppler.report.provenance import (
    command_line,
    config_rows,
    describe_data,
    main_settings,
    version,
)
from vo_doppler.report.run_report import (
    TRACK_LABELS,
    RunReport,
    build_error_per_100m_figure,
    build_heading_error_figure,
    glossary,
    headline,
    png_data_uri,
    trajectories_figure,
    worst_reliable_tight_errors,
    write_run_report,
)
from vo_doppler.report.trajectory_map import TRUTH, write_geojson
from vo_doppler.run import Pipeline, RunConfig, RunResult

SUMMARY_FILE = "summary.json"
MAX_PROBLEMS_PER_FILE = 20

FACT_FORMATS = {
    "gnss_epochs": ("GNSS epochs", "{:d}"),
    "conventional_heading_availability": (
        "conventional heading available (GNSS tests; the comparison pipeline's input)",
        "{:.1%}",
    ),
    "conventional_heading_valid": ("conventional heading valid (every integrity test)", "{:.1%}"),
    "tight_heading_availability": ("tightly coupled heading available", "{:.1%}"),
    "tight_heading_reliable": ("tightly coupled heading reliable (gyro-consistent)", "{:.1%}"),
    "tight_heading_method": ("tightly coupled heading settings (--heading-method)", "{}"),
    "tight_heading_used": ("tightly coupled heading used by the correction", "{:.1%}"),
    "vehicle_signal_epochs": (
        "GNSS epochs with vehicle signals (wheel speed and yaw rate)",
        "{:d}",
    ),
    "tight_heading_used_with_vehicle_signals": (
        "tightly coupled heading used by the correction, of the epochs with vehicle signals",
        "{:.1%}",
    ),
    "tight_heading_rejected_rows": ("Doppler rows rejected by the NLOS tests", "{:d}"),
    "tight_heading_epochs_with_rejection": ("epochs with a rejection", "{:d}"),
    "grade_prior_from_accelerometer": (
        "road-grade prior from the forward accelerometer",
        "{:.1%}",
    ),
    "grade_prior_sigma_median": ("road-grade prior σ, median (rise over run)", "{:.1%}"),
    "final_wheel_scale": ("wheel scale at the end", "{:.4f}"),
    "final_gyro_bias_dps": ("gyro bias at the end", "{:+.3f} deg/s"),
    "vo_frames": ("VO frames", "{:d}"),
    "vo_flagged_frames": ("VO frames flagged", "{:d}"),
    "vo_fps": ("VO speed", "{:.1f} frames/s"),
    "camera": ("camera", "{}"),
    "heading_correction": ("heading correction", "{}"),
    "placement_heights": ("heights placed by", "{}"),
    "gnss": ("GNSS", "{}"),
    "heading_source": ("absolute heading", "{}"),
    "can_clock_residual_offset_s": (
        "wheel-speed clock offset left (CAN/vehicle signals against the GNSS Doppler speed)",
        "{:+.3f} s",
    ),
}
"""Summary key → (label with the same words as the terminal, format with the unit). Every
scalar key of the summary has one (a test checks), so that the report shows no raw key."""

NOT_AVAILABLE = "not available"

NOT_FACTS = (
    "evaluation",
    "absolute_position_error",
    "time_order",
    "warnings",
    "doppler_noise",
    "calibration",
    "span",
)
"""Summary keys that are not scalars: the report shows them as tables or a list of their own,
or (``time_order``, ``doppler_noise``) leaves them to summary.json."""


def correction_label(config: RunConfig) -> str:
    """The heading correction as the summary names it, e.g. ``kalman (causal)``."""
    correction = config.correction
    return correction.method + ("" if correction.blend.smooth else " (causal)")


def summarise(result: RunResult, vehicle_span: tuple[float, float] | None = None) -> dict:
    """Heading availability, calibration and VO figures of a run (JSON-ready scalars); without
    GNSS only the VO figures and ``gnss``, saying that the GNSS pipelines were not run.
    ``vehicle_span``: the span both vehicle signals cover (``Sequence.vehicle_span``), outside
    which no tightly coupled heading can be used (``vehicle_signal_epochs``, and the share of
    them used, ``tight_heading_used_with_vehicle_signals``; None: every epoch). A run on a
    given heading (``result.heading_source``) says so in ``heading_source``; its figures are
    those of the given table, and ``gnss_epochs`` counts the recording's own epochs."""
    table = result.heading
    if table is None:
        summary: dict = {
            "gnss_epochs": 0,
            "gnss": "none: the GNSS pipelines were not run (VO and dead reckoning only)",
        }
        _vo_summary(summary, result)
        return summary
    covered = epochs_within(table.t, vehicle_span)
    summary = {
        "gnss_epochs": len(table),
        "conventional_heading_availability": float(np.mean(table.published_conventional[0])),
        "conventional_heading_valid": float(np.mean(table.conv_valid)),
        "tight_heading_availability": float(np.mean(table.tc_available)),
        "tight_heading_reliable": float(np.mean(table.tc_reliable)),
        "tight_heading_used": float(np.mean(result.tc_usable)),
        "tight_heading_method": table.method,
        "vehicle_signal_epochs": int(np.count_nonzero(covered)),
        "tight_heading_used_with_vehicle_signals": (
            float(np.mean(result.tc_usable[covered])) if covered.any() else None
        ),
        "tight_heading_rejected_rows": int(table.rejected_rows.sum()),
        "tight_heading_epochs_with_rejection": int(np.count_nonzero(table.rejected_rows)),
        "grade_prior_from_accelerometer": float(np.mean(table.grade_from_accelerometer)),
        "grade_prior_sigma_median": _finite_median(table.grade_prior_sigma),
        **final_calibration(table),
        "calibration": None if table.calibration is None else table.calibration.to_dict(),
    }
    if result.gnss is not None:
        summary["doppler_noise"] = doppler_noise_summary(result)
    if result.heading_source:
        summary["heading_source"] = result.heading_source
        summary["gnss_epochs"] = 0 if result.gnss is None else len(result.gnss.spp.t)
        if result.gnss is None:
            summary["gnss"] = "none: the trajectories start at the ENU origin"
    _vo_summary(summary, result)
    return summary


def _vo_summary(summary: dict, result: RunResult) -> None:
    if result.vo is not None:
        summary["vo_frames"] = result.vo.stats.frames
        summary["vo_flagged_frames"] = len(result.vo.stats.flagged_frames)
        summary["vo_fps"] = result.vo.stats.fps
    else:
        summary["camera"] = "none: non-visual pipelines only"


def _finite_median(values: np.ndarray) -> float | None:
    finite = values[np.isfinite(values)]
    return float(np.median(finite)) if finite.size else None


def final_calibration(table) -> dict:
    """The wheel scale and gyro bias at the last epoch the vehicle signals cover (the table's
    last value where the table has no calibration summary)."""
    if table.calibration is not None:
        return {
            "final_wheel_scale": table.calibration.final_wheel_scale,
            "final_gyro_bias_dps": float(np.degrees(table.calibration.final_gyro_bias)),
        }
    return {
        "final_wheel_scale": float(table.wheel_scale[-1]),
        "final_gyro_bias_dps": float(np.degrees(table.gyro_bias[-1])),
    }


def doppler_noise_summary(result: RunResult) -> dict:
    """The Doppler σ(C/N0, elevation) model fitted per receiver signal (``gnss.noise_model``),
    whether the run weighted the Doppler with it, and the rest factor and speed share that
    every run applies (``gnss.moving_noise``)."""
    gnss = result.gnss
    return {
        "applied": gnss.noise_fitted,
        "models": [model.to_dict() for model in gnss.noise_models.values()],
        "moving": gnss.moving_noise.to_dict(),
    }


def readable_facts(summary: dict) -> dict[str, str]:
    """The summary's scalars with labels and units for people (the report's list); a figure
    the run could not compute (None, NaN) reads "not available"."""
    facts = {}
    for key, value in summary.items():
        if key in NOT_FACTS:
            continue
        label, fmt = FACT_FORMATS.get(key, (key, "{}"))
        missing = value is None or (isinstance(value, float) and not np.isfinite(value))
        facts[label] = NOT_AVAILABLE if missing else fmt.format(value)
    return facts


def input_warnings(inputs: Sequence, report: InputReport) -> list[str]:
    """What reading the sequence found: the samples the readers skipped and each sensor's time
    order (the checks of the data themselves are the library's, in ``run_sequence``)."""
    return report.warnings()


def result_checks(
    inputs: Sequence, report: InputReport, result: RunResult, warnings: list[str]
) -> dict:
    """The summary's ``checks``: the input ``warnings``, what the GNSS readers skipped
    (:func:`file_problems`, already logged by them), the library's warnings
    (``result.warnings``, already logged: the origin, the CAN clock against the GNSS Doppler
    speed, the calibration), the residual clock offset, the time order per sensor."""
    return {
        "warnings": warnings + file_problems(inputs) + result.warnings,
        "can_clock_residual_offset_s": None
        if result.heading is None
        else result.heading.clock_residual_offset_s,
        "time_order": {r.sensor: r.as_dict() for r in report.time_order},
    }


def file_problems(inputs: Sequence) -> list[str]:
    """The records the observation and navigation readers skipped, each named by file and line
    (a damaged epoch, an unreadable header value): the first ``MAX_PROBLEMS_PER_FILE`` of each
    kind, then how many more."""
    found = []
    if not inputs.has_gnss:
        return found
    for what, problems in (
        ("observation", inputs.observations.problems),
        ("navigation", state_problems(inputs.navigation)),
    ):
        found += problems[:MAX_PROBLEMS_PER_FILE]
        if len(problems) > MAX_PROBLEMS_PER_FILE:
            more = len(problems) - MAX_PROBLEMS_PER_FILE
            found.append(f"{more} more {what}-file problems (see the log)")
    return found


def driven_m(result: RunResult) -> float:
    """Distance driven by the calibrated wheel speed (m)."""
    speed = result.calibrated_speed
    return float(travelled_distance(speed.t, np.abs(speed.value), speed.t[-1:])[0])


def write_run_outputs(
    sequence: Sequence,
    result: RunResult,
    config: RunConfig,
    out: Path,
    checks: dict | None = None,
    manifest: dict | None = None,
    command: str | None = None,
    span: dict | None = None,
) -> dict:
    """Write a run's outputs into ``out`` (created if missing) and return its summary.

    The summary (also ``out/summary.json``) holds :func:`summarise`'s figures, the heading
    correction used, the input ``checks`` (warnings, clock estimate, time order per sensor)
    and, when the recording has ground truth, ``evaluation``: per pipeline the errors of
    :func:`vo_doppler.eval.pipelines.evaluate_pipelines` as dictionaries.
    ``manifest`` (the parsed ``sequence.yaml``) tells the report whether the drive is simulated;
    ``command`` is the command line it shows (default: this process's); ``span`` (the part of
    the recording run, :meth:`vo_doppler.model.time_span.GpsInterval.to_dict`) goes to the
    summary as it is.
    """
    out.mkdir(parents=True, exist_ok=True)
    config = config.for_sequence(sequence)
    for name, trajectory in result.trajectories.items():
        file = (
            "trajectory_corrected.tum" if name == Pipeline.VO_GPS_TC else f"trajectory_{name}.tum"
        )
        write_tum(out / file, trajectory)
    if result.heading is not None:
        write_heading_csv(out / "heading.csv", result.heading)
        if result.gnss is not None and not result.heading_source:
            velocity = car_checked_velocity(result.gnss.velocity, result.heading)
            write_velocity_csv(out / "vel.csv", velocity)
    summary = summarise(result, sequence.vehicle_span)
    summary["heading_correction"] = correction_label(config)
    summary["placement_heights"] = result.antenna.height_source
    summary.update(checks or {})
    if span is not None:
        summary["span"] = span
    table, truth = result.heading, sequence.truth
    report = RunReport(
        title=f"vo-doppler run: {sequence.name}",
        headline="",
        data=describe_data(sequence, manifest, driven_m(result)),
        command=command or command_line(),
        version=version(),
        settings=main_settings(config, sequence.has_camera, sequence.has_gnss),
        config_rows=config_rows(config, sequence.has_camera, sequence.has_gnss),
        facts={},
        tracks=dict(result.trajectories),
        enu=sequence.enu,
        heading_figure="",
        warnings=list(summary.get("warnings", [])),
        definitions=glossary(sequence.has_camera, sequence.has_gnss),
        placement_heights=result.antenna.height_source,
    )
    truth_yaw = truth.yaw_at(table.t) if truth is not None and table is not None else None
    if truth is not None:
        report.tracks = {TRUTH: truth, **result.trajectories}
        evaluate_into(summary, report, sequence, result, out)
    trajectories_figure(
        out / "trajectories.png", result.trajectories, truth, f"{sequence.name}: as written"
    )
    release_cycles()
    write_geojson(out / "trajectories.geojson", report.tracks, TRACK_LABELS, sequence.enu)
    if table is not None:
        report.heading_figure = png_data_uri(
            build_heading_figure(table, truth_yaw, sequence.name, result.tc_usable),
            out / "heading.png",
        )
        release_cycles()
    covered = summary.get("vehicle_signal_epochs")
    used = summary.get("tight_heading_used_with_vehicle_signals")
    if used is None:  # no epoch with vehicle signals: the share of every epoch
        covered, used = None, summary.get("tight_heading_used")
    report.headline = headline(
        report.errors, used, truth is not None and not report.errors, covered
    )
    report.facts = readable_facts(summary)
    (out / SUMMARY_FILE).write_text(json_text(summary, indent=2))
    write_run_report(out / "report.html", report)
    return summary


def evaluate_into(
    summary: dict, report: RunReport, sequence: Sequence, result: RunResult, out: Path
) -> None:
    """The evaluation of the trajectories against the sequence's ground truth
    (:func:`~vo_doppler.eval.run_evaluation.evaluate_run`) into ``summary``
    (``absolute_position_error`` of the trajectories as written, ``evaluation`` of them moved
    to the truth, and ``warnings`` for what it could not evaluate or its failure) and
    ``report`` (tables, the map's layer of the trajectories as evaluated, figures written to
    ``out``)."""
    truth, table = sequence.truth, result.heading
    found = evaluate_run(result.trajectories, table, result.tc_usable, truth, sequence.vehicle_span)
    summary.setdefault("warnings", []).extend(found.warnings)
    report.warnings += found.warnings
    if found.absolute:
        summary["absolute_position_error"] = {
            name: e.to_dict() for name, e in found.absolute.items()
        }
        report.absolute = found.absolute
    errors = found.errors
    if not errors:
        return
    summary["evaluation"] = {name: e.to_dict() for name, e in errors.items()}
    report.errors = errors
    report.evaluated_tracks = found.shown
    report.error_figure = png_data_uri(
        build_error_per_100m_figure(found.per_100m, sequence.name), out / "error_per_100m.png"
    )
    release_cycles()
    heading_t0 = float(table.t[0]) if table is not None and len(table) else 0.0
    if table is None:  # no GNSS: the time axis starts with the ground truth
        heading_t0 = float(truth.t[0])
    report.heading_error_figure = png_data_uri(
        build_heading_error_figure(found.shown, truth, heading_t0, sequence.name),
        out / "heading_error.png",
    )
    release_cycles()
    if table is not None:
        report.worst = worst_reliable_tight_errors(table, result.tc_usable, truth.yaw_at(table.t))
    path_length = max(e.path_length_m for e in errors.values())
    report.segment_note = (
        "KITTI translation error: "
        + segment_lengths_note(segment_lengths_that_fit(path_length), path_length)
        + "."
    )
