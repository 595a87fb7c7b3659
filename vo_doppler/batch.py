"""The main job over many recordings: one process (or Ray task) per recording, failures kept
to their recording, resumable, and one aggregate table.

Each recording ``SOURCE`` writes what ``vo-doppler run`` writes into ``OUT/<name>/``
(:func:`vo_doppler.job.run_recording`, the job ``run`` runs), a log (``run.log``) and, last, its
completion marker ``OUT/<name>/batch_done.json``: written atomically (a temporary file renamed
over it) only after every output, with the fingerprint of the recording's inputs and of the
configuration. A batch started again with ``resume=True`` skips every recording whose marker
holds the current fingerprint and whose listed outputs still exist, unless its last run failed
(its :data:`FAILED_LOG` beside the earlier results: the failure may have been fixed, and the
aggregate would otherwise list as fine a recording whose last run failed); a recording that was
cut off (killed process, crash, power loss) has no marker and runs again from the start (the
staging folder it left is deleted then, whichever host's worker left it).

``OUT`` must be new, empty or a batch's own, and hold no recording; each ``OUT/<name>/`` is
replaced as a whole, so it must be new, empty or one that ``run`` or ``batch`` wrote, with
nothing added since, and no recording (``vo_doppler.io.output_folder``). All of this is checked
for every recording before any runs: a refused folder stops the batch with nothing touched.

A recording is written as ``vo-doppler run`` writes its folder: into a temporary folder beside
``OUT/<name>/`` (``OUT/.<name>.partial-*``) that replaces it once the run has written its
outputs, so no output of an earlier run stays beside the new ones. A run that fails before
its outputs (unreadable input, a crash) leaves earlier results (a ``summary.json``) as they
were and adds its log beside them as :data:`FAILED_LOG`; a folder without earlier results is
replaced by the failed run's (its ``run.log``). A recording that does not exist fails without
any folder, its message naming the list's file and line when it came from a list.

The fingerprint hashes the package version, the configuration, the span (``--start`` /
``--end``), the ``prepare`` step's name (or, for a callable object, its ``repr``: e.g. the
orbits an importer uses) and, for every file under ``SOURCE``, its relative path, size and
modification time (the quick check of rsync and make: touching or replacing a file re-runs the
recording; files outside ``SOURCE`` that a manifest points to are not followed).

``prepare``: a picklable function ``prepare(source, work_dir) -> sequence_folder`` run in the
worker before the job, for recordings that need importing first (e.g. a raw comma2k19 segment
turned into a sequence folder under ``work_dir``: the staging folder's ``prepared``, which
becomes ``OUT/<name>/prepared``). Without it every source is a sequence folder.

Executors: ``local`` (default), a ``concurrent.futures`` process pool started with ``spawn``
(no state inherited from the parent; each worker imports the package afresh and gives OpenCV
its share of the cores); ``ray``, the
same function as a Ray task on a local Ray instance or on the cluster at ``ray_address``
(or ``RAY_ADDRESS``). A worker that dies (killed, out of memory, a crash in native code)
fails only its recording: the local pool's other victims run again, each alone.
"""

from __future__ import annotations

import hashlib
import json
import logging
import multiprocessing
import os
import shutil
import threading
import time
import traceback
from collections.abc import Callable, Iterable, Iterator, Mapping
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from contextlib import nullcontext
from dataclasses import dataclass, field
from enum import StrEnum
from pathlib import Path

from vo_doppler import __version__
from vo_doppler.choices import checked
from vo_doppler.errors import InputError, UsageError, VoDopplerError, storage_refused
from vo_doppler.io.output_folder import MARKER as OUTPUT_MARKER
from vo_doppler.io.output_folder import (
    RUN,
    STAGING_OWNER,
    begin_staging,
    check_output_folder,
    mark_output,
    open_output_folder,
    remove_cut_off_staging,
    swap_in,
    write_files,
)
from vo_doppler.io.tables import write_csv_and_parquet
from vo_doppler.job import require_tight_heading, run_recording
from vo_doppler.model.time_span import TimeSpan
from vo_doppler.report.batch_summary import (
    COLUMNS,
    overall_row,
    recording_row,
    write_batch_html,
)
from vo_doppler.report.json_text import json_text
from vo_doppler.report.run_outputs import SUMMARY_FILE
from vo_doppler.run import RunConfig

log = logging.getLogger(__name__)

MARKER = "batch_done.json"
LOG_FILE = "run.log"
FAILED_LOG = "failed_run.log"
"""The log of a run that failed before its outputs, beside the earlier results it left."""
PREPARED = "prepared"
TABLE_NAME = "batch_summary"
PARENT_POLL_S = 0.5
WHOLE = TimeSpan()
"""No ``--start`` / ``--end``: each recording whole."""

Prepare = Callable[[Path, Path], Path]
"""``prepare(source, work_dir) -> sequence folder``: imports a raw recording (module docstring)."""


class Executor(StrEnum):
    """Where the recordings run (module docstring)."""

    LOCAL = "local"
    RAY = "ray"


class Status(StrEnum):
    DONE = "done"
    SKIPPED = "skipped"
    """Finished by an earlier batch with the same fingerprint (``resume``)."""
    FAILED = "failed"


class Failure(StrEnum):
    """Why a recording failed; ``input-error`` is what makes ``vo-doppler run`` exit 1."""

    INPUT = "input-error"
    """The toolkit's own error (:class:`~vo_doppler.errors.VoDopplerError`): unusable input."""
    USAGE = "usage-error"
    """An option that contradicts the recording (:class:`~vo_doppler.errors.UsageError`: a
    ``--start`` / ``--end`` outside it), what makes ``vo-doppler run`` exit 2."""
    INTERNAL = "internal-error"
    """Any other exception: a bug; the traceback is in the recording's ``run.log``."""
    WORKER_LOST = "worker-lost"
    """The process running it died (killed, out of memory, crash in native code)."""


@dataclass(frozen=True)
class Listing:
    """Where a list of recordings names one: the list file and the line (from 1)."""

    file: Path
    line: int


@dataclass(frozen=True)
class RecordingJob:
    """Everything a worker needs for one recording (picklable)."""

    source: Path
    out: Path
    config: RunConfig
    fingerprint: str
    prepare: Prepare | None = None
    listed: Listing | None = None
    """Where a list named the recording (for its messages), None when given directly."""
    span: TimeSpan = WHOLE
    """The part of the recording to run on (``--start`` / ``--end``; default all of it)."""

    @property
    def name(self) -> str:
        return self.out.name


@dataclass
class RecordingOutcome:
    name: str
    source: Path
    status: Status
    seconds: float
    summary: dict | None = None
    error: str | None = None
    category: Failure | None = None


@dataclass
class BatchResult:
    outcomes: list[RecordingOutcome]
    """In the order the recordings were given."""
    rows: list[dict]
    """The aggregate: one row per recording, then the overall row."""
    csv: Path
    parquet: Path
    html: Path
    failed: list[RecordingOutcome] = field(init=False)

    def __post_init__(self) -> None:
        self.failed = [o for o in self.outcomes if o.status is Status.FAILED]

    @property
    def exit_code(self) -> int:
        """The command's exit status: 2 when a recording failed on a usage error (a span
        outside it, as ``run`` exits 2), else 1 when any failed, else 0."""
        if any(o.category is Failure.USAGE for o in self.failed):
            return 2
        return 1 if self.failed else 0


def read_list(path: Path) -> dict[Path, Listing]:
    """The recordings listed one per line (blank lines and ``#`` comments skipped; relative
    paths are relative to the list's folder), in order, each with where it is listed. Entries
    naming one recording (``s1``, ``./s1``, ``s1/``, a link to it) count once, at their first
    line, with a warning naming their lines."""
    try:
        lines = path.read_text().splitlines()
    except OSError as exc:
        reason = exc.strerror or exc
        raise InputError(f"cannot read the list of recordings: {reason}", path) from exc
    spellings: dict[Path, list[tuple[int, str]]] = {}
    listed: dict[Path, Listing] = {}
    for number, line in enumerate(lines, start=1):
        entry = line.split("#", 1)[0].strip()
        if not entry:
            continue
        source = path.parent / entry
        spelled = spellings.setdefault(source.resolve(), [])
        if not spelled:
            listed[source] = Listing(path, number)
        spelled.append((number, entry))
    for spelled in spellings.values():
        if len(spelled) > 1:
            where = ", ".join(str(number) for number, _ in spelled)
            names = ", ".join(entry for _, entry in spelled)
            log.warning(
                "%s: lines %s name the same recording (%s); it runs once", path, where, names
            )
    return listed


def output_names(sources: list[Path]) -> list[str]:
    """Output folder names: the last path component, or as many last components as make every
    name unique, joined by ``__`` (``route__10`` for segments all called ``10``)."""
    parts = [s.resolve().parts for s in sources]
    for depth in range(1, max((len(p) for p in parts), default=1) + 1):
        names = ["__".join(p[-depth:]) for p in parts]
        if len(set(names)) == len(names):
            return names
    raise InputError("two recordings resolve to the same path")


def fingerprint(
    source: Path, config: RunConfig, prepare: Prepare | None, span: TimeSpan = WHOLE
) -> str:
    """SHA-256 of the version, configuration, span, prepare step and input files (module
    docstring)."""
    digest = hashlib.sha256()
    step = None
    if prepare is not None:
        name = getattr(prepare, "__qualname__", None)
        step = f"{prepare.__module__}.{name}" if name else repr(prepare)
    digest.update(repr((__version__, config, span, step)).encode())
    files = sorted(p for p in source.rglob("*") if p.is_file()) if source.is_dir() else [source]
    for path in files:
        try:
            stat = path.stat()
        except OSError:
            continue
        relative = path.relative_to(source) if source.is_dir() else path.name
        digest.update(f"{relative}\0{stat.st_size}\0{stat.st_mtime_ns}\n".encode())
    return digest.hexdigest()


def finished(job: RecordingJob) -> dict | None:
    """The marker of a recording finished with the job's fingerprint whose outputs are all still
    there and whose last run did not fail, else None. A :data:`FAILED_LOG` says the last run
    failed: a run that succeeds replaces the whole folder, so the log cannot be older than the
    results beside it."""
    if (job.out / FAILED_LOG).exists():
        return None
    try:
        marker = json.loads((job.out / MARKER).read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(marker, dict) or marker.get("fingerprint") != job.fingerprint:
        return None
    if not all((job.out / name).is_file() for name in marker.get("outputs", [])):
        return None
    return marker


def _run_job(job: RecordingJob, staging: Path) -> dict:
    """Run the recording, writing its outputs into ``staging`` (which becomes ``job.out``)."""
    if job.prepare is None:
        folder = shown = job.source
    else:
        folder, shown = job.prepare(job.source, staging / PREPARED), job.out / PREPARED
    job_output = run_recording(folder, job.config, lambda: nullcontext(staging), job.span)
    require_tight_heading(job_output.result, shown, job.out)
    return job_output.summary


def process_recording(job: RecordingJob) -> RecordingOutcome:
    """Run one recording into a staging folder and, last, write its marker; never raises for a
    failure of the recording itself (the outcome says what failed). The staging folder replaces
    the recording's folder unless the run failed before its outputs and the folder holds
    earlier results, which then stay, with the failed run's log beside them (module
    docstring); a folder that a run did not write, or that holds the recording, is refused
    and left as it is."""
    start = time.perf_counter()
    if not job.source.exists():
        if job.listed is None:
            error = InputError("the recording does not exist", job.source)
        else:
            what = f"the recording {job.source} does not exist"
            error = InputError(what, job.listed.file, job.listed.line)
        return _failed(job, Failure.INPUT, str(error))
    try:
        check_output_folder(job.out, RUN, [job.source], replace=True)
        remove_cut_off_staging(job.out, alone=True)
        staging = begin_staging(job.out, RUN, [job.source])
    except VoDopplerError as exc:
        return _failed(job, Failure.INPUT, str(exc))
    try:
        outcome = _logged_run(job, staging, start)
        if outcome.status is Status.FAILED and _keeps_earlier_results(job.out, staging):
            os.replace(staging / LOG_FILE, job.out / FAILED_LOG)
            mark_output(job.out, RUN)
            outcome.error += (
                f" (the earlier results in {job.out} are kept; this run's log is {FAILED_LOG})"
            )
        else:
            swap_in(staging, job.out, RUN, [job.source])
    except VoDopplerError as exc:
        return _failed(job, Failure.INPUT, str(exc), time.perf_counter() - start)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return outcome


def _keeps_earlier_results(out: Path, staging: Path) -> bool:
    """Whether a failed run's ``staging`` is dropped for the earlier results in ``out``: they
    hold a summary and the failed run wrote none (a run that wrote its outputs and then failed,
    as one without any tightly coupled heading does, replaces them, as with ``run``)."""
    return (out / SUMMARY_FILE).is_file() and not (staging / SUMMARY_FILE).exists()


def _logged_run(job: RecordingJob, staging: Path, start: float) -> RecordingOutcome:
    """Run the job with the package's log also written to ``staging``'s :data:`LOG_FILE`; a
    failure becomes the outcome (with the error, or an internal error's traceback, logged)."""
    handler = logging.FileHandler(staging / LOG_FILE, mode="w")
    handler.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
    package_log = logging.getLogger("vo_doppler")
    package_log.addHandler(handler)
    if package_log.level == logging.NOTSET:
        package_log.setLevel(logging.INFO)
    try:
        summary = _run_job(job, staging)
    except VoDopplerError as exc:
        package_log.error("%s", exc)
        category = Failure.USAGE if isinstance(exc, UsageError) else Failure.INPUT
        return _failed(job, category, str(exc), time.perf_counter() - start)
    except Exception as exc:
        if storage_refused(exc):  # a full disk: the environment, as for ``run``
            message = f"{job.out}: cannot write the results: {exc.strerror}"
            return _failed(job, Failure.INPUT, message, time.perf_counter() - start)
        package_log.error("%s", traceback.format_exc())
        message = f"{type(exc).__name__}: {exc}"
        return _failed(job, Failure.INTERNAL, message, time.perf_counter() - start)
    finally:
        package_log.removeHandler(handler)
        handler.close()
    return _done(job, staging, summary, time.perf_counter() - start)


def _done(job: RecordingJob, staging: Path, summary: dict, seconds: float) -> RecordingOutcome:
    """A finished recording's outcome, after its completion marker in ``staging`` (module
    docstring)."""
    outputs = sorted(
        p.name
        for p in staging.iterdir()
        if p.is_file() and p.name not in (MARKER, OUTPUT_MARKER, STAGING_OWNER)
    )
    marker = {
        "fingerprint": job.fingerprint,
        "source": str(job.source),
        "seconds": seconds,
        "outputs": outputs,
        "summary": summary,
    }
    text = json_text(marker, indent=2)
    write_files([(staging / MARKER, lambda path: path.write_text(text))])
    return RecordingOutcome(job.name, job.source, Status.DONE, seconds, summary)


def _failed(job: RecordingJob, category: Failure, message: str, seconds: float = 0.0):
    return RecordingOutcome(job.name, job.source, Status.FAILED, seconds, None, message, category)


def _lost(job: RecordingJob, exc: BaseException) -> RecordingOutcome:
    return _failed(job, Failure.WORKER_LOST, f"the worker process died: {exc}")


def default_workers(recordings: int) -> int:
    """min(CPU cores, recordings), at least 1."""
    return max(1, min(os.cpu_count() or 1, recordings))


def opencv_threads(workers: int) -> int:
    """OpenCV threads per worker: the machine's cores shared out, at least 1 (a run's OpenCV
    threads would otherwise compete with the other workers for the same cores)."""
    return max(1, (os.cpu_count() or 1) // max(1, workers))


def _start_worker(parent: int, threads: int) -> None:
    """Pool initializer: OpenCV limited to ``threads`` threads, and a thread that ends the
    worker once its parent is gone (a batch killed by any signal leaves no worker computing
    on)."""
    import cv2

    cv2.setNumThreads(threads)

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(PARENT_POLL_S)
        os._exit(1)

    threading.Thread(target=watch, name="exit-with-parent", daemon=True).start()


def _pool(workers: int) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(
        max_workers=workers,
        mp_context=multiprocessing.get_context("spawn"),
        initializer=_start_worker,
        initargs=(os.getpid(), opencv_threads(workers)),
    )


def local_outcomes(jobs: list[RecordingJob], workers: int) -> Iterator[RecordingOutcome]:
    """Run jobs on a spawn process pool, yielding outcomes as they finish. Jobs lost with a
    broken pool run again one by one, each in a pool of its own, so that only the recording
    whose worker dies again is failed."""
    lost = []
    pool = _pool(workers)
    try:
        futures = {pool.submit(process_recording, job): job for job in jobs}
        for future in as_completed(futures):
            try:
                yield future.result()
            except BrokenProcessPool:
                lost.append(futures[future])
            except Exception as exc:  # the job could not reach its worker (e.g. not picklable)
                yield _failed(futures[future], Failure.INTERNAL, f"{type(exc).__name__}: {exc}")
    except BaseException:
        _stop(pool)
        raise
    pool.shutdown()
    for job in lost:
        with _pool(1) as alone:
            try:
                yield alone.submit(process_recording, job).result()
            except BrokenProcessPool as exc:
                yield _lost(job, exc)


def _stop(pool: ProcessPoolExecutor) -> None:
    """Cancel what has not started and end the workers (an interrupted batch leaves none)."""
    pool.shutdown(wait=False, cancel_futures=True)
    for child in multiprocessing.active_children():
        child.terminate()


def ray_outcomes(
    jobs: list[RecordingJob], workers: int | None, address: str | None
) -> Iterator[RecordingOutcome]:
    """Run jobs as Ray tasks, at most ``workers`` at a time, yielding outcomes as they finish.

    Ray is started here unless already initialised: on the cluster at ``address`` (or the
    ``RAY_ADDRESS`` environment variable), else a local instance with ``workers`` CPUs bound
    to the loopback address. Every node must see the recordings and ``OUT`` at the same paths.
    """
    try:
        import ray
    except ImportError as exc:
        raise InputError("the ray executor needs Ray: pip install 'vo-doppler[ray]'") from exc
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")
    started = not ray.is_initialized()
    if started:
        address = address or os.environ.get("RAY_ADDRESS")
        options = {"include_dashboard": False, "log_to_driver": False}
        if address:
            ray.init(address=address, **options)
        else:
            cpus = workers or default_workers(len(jobs))
            ray.init(num_cpus=cpus, _node_ip_address="127.0.0.1", **options)
    try:
        limit = workers or max(1, int(ray.cluster_resources().get("CPU", 1)))
        task = ray.remote(max_retries=0)(process_recording)
        queue = iter(jobs)
        running = {}
        for job in queue:
            running[task.remote(job)] = job
            if len(running) >= limit:
                break
        while running:
            (ref,), _ = ray.wait(list(running), num_returns=1)
            job = running.pop(ref)
            try:
                yield ray.get(ref)
            except ray.exceptions.RayError as exc:
                yield _lost(job, exc)
            following = next(queue, None)
            if following is not None:
                running[task.remote(following)] = following
    finally:
        if started:
            ray.shutdown()


def plan(
    sources: Iterable[Path],
    out: Path,
    config: RunConfig,
    prepare: Prepare | None = None,
    listings: Mapping[Path, Listing] | None = None,
    span: TimeSpan = WHOLE,
) -> list[RecordingJob]:
    """One job per distinct recording (repeats dropped with a warning naming their spellings),
    each with its output folder, the ``span`` to run on and, from ``listings``
    (:func:`read_list`), where a list named it."""
    spellings: dict[Path, list[str]] = {}
    for source in sources:
        spellings.setdefault(Path(source).resolve(), []).append(str(source))
    for given in spellings.values():
        if len(given) > 1:
            log.warning("%s name the same recording; it runs once", ", ".join(given))
    unique = list(spellings)
    listed = {Path(s).resolve(): where for s, where in (listings or {}).items()}
    names = output_names(unique)
    return [
        RecordingJob(
            source,
            out / name,
            config,
            fingerprint(source, config, prepare, span),
            prepare,
            listed.get(source),
            span,
        )
        for source, name in zip(unique, names, strict=True)
    ]


def run_batch(
    folders: Iterable[Path],
    out: Path,
    executor: Executor | str = Executor.LOCAL,
    workers: int | None = None,
    resume: bool = False,
    config: RunConfig | None = None,
    prepare: Prepare | None = None,
    ray_address: str | None = None,
    on_outcome: Callable[[RecordingOutcome], None] | None = None,
    listings: Mapping[Path, Listing] | None = None,
    span: TimeSpan = WHOLE,
) -> BatchResult:
    """Run the main job on every recording and write the aggregate into ``out``
    (``batch_summary.csv``, ``.parquet``, ``.html``).

    ``workers`` defaults to min(CPU cores, recordings to run); with ``resume`` the recordings
    finished by an earlier batch with the same fingerprint are skipped (their summaries still
    enter the aggregate). ``on_outcome`` is called in the calling process as each recording
    ends (skipped ones first). ``listings``: where a list named the recordings it named
    (:func:`read_list`), for their messages. ``span`` (``--start`` / ``--end``) is resolved on
    each recording as ``run`` resolves it: a recording it does not fit fails with the usage
    error (category ``usage-error``, exit status 2), the others run.
    """
    executor = checked(Executor, executor, "executor")
    if workers is not None and workers < 1:
        raise InputError(f"workers must be at least 1, got {workers}")
    config = config or RunConfig()
    sources = [Path(folder) for folder in folders]
    check_output_folder(out, "batch", sources)
    jobs = plan(sources, out, config, prepare, listings, span)
    for job in jobs:
        check_output_folder(job.out, RUN, sources, replace=True)
    open_output_folder(out, "batch")
    outcomes: dict[str, RecordingOutcome] = {}
    todo = []
    for job in jobs:
        marker = finished(job) if resume else None
        if marker is None:
            todo.append(job)
            continue
        outcome = RecordingOutcome(
            job.name, job.source, Status.SKIPPED, marker["seconds"], marker["summary"]
        )
        outcomes[job.name] = outcome
        if on_outcome:
            on_outcome(outcome)
    if todo:
        if executor is Executor.RAY:
            stream = ray_outcomes(todo, workers, ray_address)
        else:
            stream = local_outcomes(todo, workers or default_workers(len(todo)))
        for outcome in stream:
            outcomes[outcome.name] = outcome
            if on_outcome:
                on_outcome(outcome)
    ordered = [outcomes[job.name] for job in jobs]
    return _aggregate(ordered, out)


def _aggregate(outcomes: list[RecordingOutcome], out: Path) -> BatchResult:
    rows = [
        recording_row(
            o.name,
            o.status.value,
            None if o.category is None else o.category.value,
            o.error,
            o.seconds,
            o.summary,
        )
        for o in outcomes
    ]
    rows.append(overall_row(rows))
    csv, parquet, page = (out / f"{TABLE_NAME}.{ext}" for ext in ("csv", "parquet", "html"))
    write_csv_and_parquet(COLUMNS, rows, csv, parquet)
    write_batch_html(page, rows)
    return BatchResult(outcomes, rows, csv, parquet, page)
