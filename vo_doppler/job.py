"""One recording's job, the same for ``vo-doppler run`` and ``vo-doppler batch``: read the
sequence (cut to a span when asked), log what reading found, run the main job
(:func:`vo_doppler.run.run_sequence`), check the result and write every output
(:func:`vo_doppler.report.run_outputs.write_run_outputs`); then the verdict on a drive without
any tightly coupled heading (:func:`require_tight_heading`), which each caller gives once its
outputs are in place."""

from __future__ import annotations

import gc
import logging
from collections.abc import Callable
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from vo_doppler.child_process import call_in_child
from vo_doppler.errors import InputError
from vo_doppler.io.heading_csv import read_heading_csv
from vo_doppler.io.sequence import (
    InputReport,
    read_ground_truth,
    read_manifest,
    read_sequence_with_report,
)
from vo_doppler.model.given_heading import GivenHeading
from vo_doppler.model.sequence import Sequence
from vo_doppler.model.time_span import GpsInterval, TimeSpan, trim, trim_sequence
from vo_doppler.model.trajectory import Trajectory
from vo_doppler.report.run_outputs import input_warnings, result_checks, write_run_outputs
from vo_doppler.run import RunResult, run_sequence
from vo_doppler.run_stages import RunConfig
from vo_doppler.time_hints import epochs_offset_fix, time_base_check

log = logging.getLogger(__name__)

Running = Callable[[Sequence], AbstractContextManager[Callable[[int], None] | None]]
"""Around the run of a sequence just read: a context that gives the per-frame callback of the
VO (or None), e.g. a progress bar's."""


@dataclass
class JobOutput:
    sequence: Sequence
    """As run: cut to the span when one was given."""
    result: RunResult
    summary: dict
    """What ``summary.json`` holds."""


def run_recording(
    folder: Path,
    config: RunConfig,
    write_into: Callable[[], AbstractContextManager[Path]],
    span: TimeSpan | None = None,
    heading_file: Path | None = None,
    allow_outside_paths: bool = False,
    running: Running | None = None,
) -> JobOutput:
    """Read the sequence ``folder`` (manifest paths outside it only with
    ``allow_outside_paths``), cut it to ``span`` unless that is the whole recording, read the
    absolute heading of ``heading_file`` (:class:`~vo_doppler.model.given_heading.GivenHeading`,
    used instead of the heading stage) when given, log what reading found, run the main job
    inside ``running`` (default: nothing around it), check the result and write the outputs
    into the folder ``write_into()`` gives (``staged_output`` for ``run``; ``batch`` its
    staging folder).

    What is alive before the run (the imported modules, the inputs) and after it (its results)
    is frozen until the job ends: the cycle collector's full passes (automatic, and after
    each figure) skip it."""
    sequence, report, interval, has_truth = call_in_child(
        lambda _: _read_for_the_run(folder, span, allow_outside_paths)
    )
    given = None
    warnings = input_warnings(sequence, report)
    if heading_file is not None:
        given = GivenHeading(read_heading_csv(heading_file), str(heading_file))
        warnings += _heading_time_base(sequence, given, heading_file)
    for text in warnings:
        log.warning("%s", text)
    try:
        gc.freeze()
        with (running or _nothing)(sequence) as on_frame:
            result = run_sequence(
                sequence, config, on_frame, given=given, in_child=True, keep_rows=False
            )
        if has_truth:
            sequence.truth = _ground_truth_again(folder, allow_outside_paths, interval, warnings)
        gc.freeze()
        checks = result_checks(sequence, report, result, warnings)
        with write_into() as out:
            summary = write_run_outputs(
                sequence,
                result,
                config,
                out,
                checks,
                read_manifest(folder),
                span=None if interval is None else interval.to_dict(),
            )
    finally:
        gc.unfreeze()
    return JobOutput(sequence, result, summary)


def _read_for_the_run(
    folder: Path, span: TimeSpan | None, allow_outside_paths: bool
) -> tuple[Sequence, InputReport, GpsInterval | None, bool]:
    """The sequence of ``folder`` read and cut to ``span`` (with the GPS interval of the cut, or
    None), what reading found, and whether it has ground truth, which is left out of the
    sequence: the run does not use it, and :func:`run_recording` reads it again for the outputs
    (a 30-min drive's at 100 Hz is 11 MiB not held through the VO). Run in a child process
    (:func:`~vo_doppler.child_process.call_in_child`), so that the readers' libraries (python-can
    and cantools, 8 MiB) and their transients leave with it."""
    sequence, report = read_sequence_with_report(folder, allow_outside_paths)
    interval = None
    if span is not None and not span.whole:
        sequence, interval = trim_sequence(sequence, span)
    return replace(sequence, truth=None), report, interval, sequence.truth is not None


def _ground_truth_again(
    folder: Path, allow_outside_paths: bool, interval: GpsInterval | None, warnings: list[str]
) -> Trajectory | None:
    """The ground truth read again for the outputs and cut as the sequence was
    (:func:`_read_for_the_run` checked it before the run): a file changed or gone since costs
    the evaluation, said in ``warnings`` and the log, not the run's results."""
    try:
        truth = read_ground_truth(folder, allow_outside_paths)
    except (InputError, OSError) as exc:
        text = f"the ground truth could not be read again for the outputs ({exc}): no evaluation"
        log.warning("%s", text)
        warnings.append(text)
        return None
    return truth if truth is None or interval is None else trim(truth, interval)


def _heading_time_base(sequence: Sequence, given: GivenHeading, path: Path) -> list[str]:
    """``correct``'s check of a heading file's clock (:func:`time_base_check`) for ``run
    --heading FILE``: its epochs against the vehicle signals' span, where the tightly coupled
    heading it replaces would be (none when the signals do not overlap: a check of its own
    refuses that). Raises the check's error naming the file; returns its warning, naming the
    file, if any."""
    if sequence.vehicle_span is None:
        return []
    recording = np.array(sequence.vehicle_span)
    epochs = given.table.t
    verdict = time_base_check(
        recording,
        epochs,
        "recording",
        "heading epochs",
        "--heading",
        offset_fix=epochs_offset_fix(recording, epochs),
    )
    if verdict.error:
        raise InputError(verdict.error, path)
    return [f"{path}: {verdict.warning}"] if verdict.warning else []


def _nothing(_: Sequence) -> AbstractContextManager[None]:
    return nullcontext()


def require_tight_heading(result: RunResult, folder: Path, out: Path) -> None:
    """A run whose tightly coupled heading was unavailable at every epoch failed: raise the
    project's error naming the recording (after its outputs were written to ``out``, to show
    why). A heading is a direction of travel: when the vehicle never moved (:func:`standstill`)
    the message says so rather than blame the heading. A recording without GNSS has no heading
    to require, nor has a run on a given heading (``result.heading_source``: the library
    required a valid one)."""
    if result.heading is None or result.heading_source or result.heading.tc_available.any():
        return
    kept = f"(the other results are in {out})"
    still = standstill(result)
    if still is not None:
        raise InputError(f"{still}, so no Doppler heading exists {kept}", folder)
    raise InputError(
        f"the tightly coupled heading was unavailable at every epoch {kept}",
        folder,
    )


def standstill(result: RunResult, config: RunConfig | None = None) -> str | None:
    """Why the drive has no heading when the wheel speed never reaches the tightly coupled
    heading's minimum speed (``config.heading.tight.min_speed_mps``; the default config when
    None), in words: the vehicle never moved, with both speeds' maxima, or the GNSS Doppler
    speed contradicting the wheels (above the conventional heading's minimum at valid epochs);
    None when the wheels did move."""
    heading = (config or RunConfig()).heading
    wheel_limit, gnss_limit = heading.tight.min_speed_mps, heading.conventional_min_speed_mps
    wheel = np.abs(result.calibrated_speed.value)
    wheel_max = float(np.max(wheel)) if wheel.size else 0.0
    if wheel_max >= wheel_limit:
        return None
    velocity = result.gnss.velocity
    gnss = np.hypot(velocity.velocity_enu[:, 0], velocity.velocity_enu[:, 1])[velocity.valid]
    gnss_max = float(np.max(gnss)) if gnss.size else None
    wheels = f"the wheel speed stays below {wheel_limit:g} m/s throughout (at most {wheel_max:.2f})"
    if gnss_max is None:
        return f"the vehicle never moved by its wheels: {wheels}; no GNSS Doppler speed is valid"
    if gnss_max < gnss_limit:
        return (
            f"the vehicle never moved: {wheels} and the GNSS Doppler speed below {gnss_limit:g} "
            f"m/s at every valid epoch (at most {gnss_max:.2f})"
        )
    return (
        f"the wheels never moved: {wheels}, while the GNSS Doppler speed reaches "
        f"{gnss_max:.2f} m/s (is the wheel-speed signal, or its unit, right?)"
    )
