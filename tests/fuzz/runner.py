"""Fuzz runner: mutated copies of the real input files, read in worker processes, each case
classified as a plausible success, a project error, or a failure (another exception, an
impossible value, more than 5 s, more than 500 MB).

    python -m tests.fuzz.runner --cases 600 --workers 1 --json out/fuzz.json   # make fuzz
    python -m tests.fuzz.runner --family rinex-obs --case 17 --show    # replay one case

Cases are deterministic: case ``k`` of a family with run seed ``s`` always makes the same file.
Workers are separate processes so that a case's time and peak memory (``ru_maxrss`` of the
worker and of its children, e.g. ``crx2rnx``) are its own; a worker past a limit is replaced.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import resource
import select
import subprocess
import sys
import tempfile
import time
import traceback
from collections import Counter
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from pathlib import Path

from tests.conftest import REPO_ROOT
from tests.fuzz.families import FAMILIES, Family, Seed, stored_as_is
from tests.fuzz.mutators import BYTE_MUTATIONS, TEXT_MUTATIONS
from vo_doppler.errors import VoDopplerError

TIME_LIMIT_S = 5.0
MEMORY_LIMIT_MB = 500.0
HARD_TIMEOUT_S = 60.0
FAILURES = ("crash", "violation", "slow", "memory", "timeout", "unnamed")
"""Outcomes that fail the run: a non-project exception, an impossible value accepted, over 5 s,
over 500 MB, killed at the hard timeout, a project error that does not name the file."""


@dataclass(frozen=True)
class Case:
    family: str
    number: int
    seed_index: int
    seed_name: str
    stage: str
    mutations: tuple[str, ...]
    rng_seed: int


def make_case(family: Family, seeds: list[Seed], number: int, run_seed: int) -> Case:
    rng = random.Random(f"{run_seed}:{family.name}:{number}")
    index = rng.randrange(len(seeds))
    packed = seeds[index].pack is not stored_as_is
    stage = "stored" if packed and rng.random() < 0.25 else "text"
    table = BYTE_MUTATIONS if stage == "stored" else text_mutations(family)
    count = 1 if rng.random() < 0.8 else 2
    mutations = tuple(rng.choice(sorted(table)) for _ in range(count))
    return Case(
        family.name, number, index, seeds[index].name, stage, mutations, rng.getrandbits(32)
    )


def mutated_bytes(case: Case, seed: Seed, plain: bytes) -> bytes:
    rng = random.Random(case.rng_seed)
    if case.stage == "stored":
        data = seed.pack(plain)
        for name in case.mutations:
            data = BYTE_MUTATIONS[name](data, rng)
        return data
    table = text_mutations(FAMILIES[case.family])
    for name in case.mutations:
        plain = table[name](plain, rng)
    return seed.pack(plain)


def text_mutations(family: Family) -> dict:
    """The text mutations of every family and the family's own (``Family.mutations``)."""
    return {**TEXT_MUTATIONS, **family.mutations}


@dataclass
class Outcome:
    case: Case
    kind: str
    seconds: float = 0.0
    rss_mb: float = 0.0
    detail: str = ""


def _own_peak_kb() -> float:
    """This process's peak resident memory (KiB): the kernel's high-water mark of its own
    address space (``VmHWM``), which starts afresh at exec, unlike ``ru_maxrss``, which a
    worker inherits from the process that started it (a large test run)."""
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith("VmHWM:"):
                return float(line.split()[1])
    except OSError:
        pass
    return float(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)


_INHERITED_PEAK_KB = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
"""The ``ru_maxrss`` this process started with; a child (the Hatanaka decompressor) inherits
it too, so a child's figure counts only above it."""


def _rss_mb() -> float:
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    child_peak = children if children > _INHERITED_PEAK_KB else 0.0
    return max(_own_peak_kb(), child_peak) / 1024.0


class Worker:
    """Runs cases of one process: seeds and original reads are cached."""

    def __init__(self, run_seed: int):
        self.run_seed = run_seed
        self.seeds: dict[str, list[Seed]] = {}
        self.plain: dict[tuple[str, int], bytes] = {}
        self.originals: dict[tuple[str, int], object] = {}
        self.folder = Path(tempfile.mkdtemp(prefix="vo-doppler-fuzz-"))

    def family_seeds(self, name: str) -> list[Seed]:
        if name not in self.seeds:
            self.seeds[name] = FAMILIES[name].seeds()
        return self.seeds[name]

    def original(self, family: Family, index: int, seed: Seed) -> object:
        key = (family.name, index)
        if key not in self.originals:
            path = self.folder / f"original{seed.suffix}"
            path.write_bytes(seed.pack(self.plain[key]))
            self.originals[key] = family.read(path)
            path.unlink()
        return self.originals[key]

    def run(self, family_name: str, number: int) -> Outcome:
        family = FAMILIES[family_name]
        seeds = self.family_seeds(family_name)
        case = make_case(family, seeds, number, self.run_seed)
        seed = seeds[case.seed_index]
        key = (family_name, case.seed_index)
        if key not in self.plain:
            self.plain[key] = seed.load()
        data = mutated_bytes(case, seed, self.plain[key])
        path = self.folder / f"case{seed.suffix}"
        path.write_bytes(data)
        start = time.perf_counter()
        try:
            result = family.read(path)
        except VoDopplerError as exc:
            outcome = Outcome(case, "error", detail=str(exc)[:300])
            if str(path) not in str(exc):
                outcome.kind, outcome.detail = "unnamed", f"error without the file: {exc}"[:300]
        except Exception as exc:  # anything else is what the fuzz looks for
            tail = traceback.format_exception(exc)[-3:]
            outcome = Outcome(case, "crash", detail=f"{type(exc).__name__}: {''.join(tail)}"[:600])
        else:
            outcome = Outcome(case, "ok")
            seconds = time.perf_counter() - start
            bad = family.check(result, path)
            shrinking = case.stage == "text" and set(case.mutations) <= seed.shrinking
            if not bad and family.same_content and shrinking:
                bad = family.same_content(result, self.original(family, case.seed_index, seed))
            if bad:
                outcome.kind, outcome.detail = "violation", "; ".join(bad)[:600]
            outcome.seconds = seconds
        if not outcome.seconds:
            outcome.seconds = time.perf_counter() - start
        outcome.rss_mb = _rss_mb()
        if outcome.seconds > TIME_LIMIT_S:
            outcome.detail = f"{outcome.kind}: {outcome.detail}"
            outcome.kind = "slow"
        if outcome.rss_mb > MEMORY_LIMIT_MB:
            outcome.detail = f"{outcome.kind}: {outcome.detail}"
            outcome.kind = "memory"
        path.unlink(missing_ok=True)
        return outcome


def worker_main(run_seed: int) -> None:
    """Serve cases read from stdin ('family number' lines), one JSON outcome per line."""
    import logging

    logging.disable(logging.CRITICAL)
    worker = Worker(run_seed)
    for line in sys.stdin:
        family, number = line.split()
        outcome = worker.run(family, int(number))
        print(json.dumps(asdict(outcome)), flush=True)


class _Process:
    def __init__(self, run_seed: int):
        env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
        self.popen = subprocess.Popen(
            [sys.executable, "-m", "tests.fuzz.runner", "--worker", "--seed", str(run_seed)],
            cwd=REPO_ROOT,
            env=env,
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            bufsize=1,
        )
        self.job: tuple[str, int] | None = None
        self.started = 0.0

    def send(self, family: str, number: int) -> None:
        self.job, self.started = (family, number), time.perf_counter()
        self.popen.stdin.write(f"{family} {number}\n")
        self.popen.stdin.flush()

    def stop(self) -> None:
        self.popen.kill()
        self.popen.wait()


@dataclass
class Report:
    counts: dict[str, Counter] = field(default_factory=dict)
    by_mutation: dict[str, Counter] = field(default_factory=dict)
    failures: list[dict] = field(default_factory=list)
    max_seconds: dict[str, float] = field(default_factory=dict)
    max_rss_mb: dict[str, float] = field(default_factory=dict)
    progress: Callable[[Report], None] | None = None
    """Called every 500 cases (the long run writes its JSON so far)."""

    def done(self) -> int:
        return sum(sum(c.values()) for c in self.counts.values())

    def add(self, outcome: dict) -> None:
        family = outcome["case"]["family"]
        self.counts.setdefault(family, Counter())[outcome["kind"]] += 1
        for name in outcome["case"]["mutations"]:
            self.by_mutation.setdefault(name, Counter())[outcome["kind"]] += 1
        self.max_seconds[family] = max(self.max_seconds.get(family, 0.0), outcome["seconds"])
        self.max_rss_mb[family] = max(self.max_rss_mb.get(family, 0.0), outcome["rss_mb"])
        if outcome["kind"] in FAILURES:
            self.failures.append(outcome)
        if self.done() % 500 == 0:
            print(
                f"{self.done()} cases, {len(self.failures)} failures", file=sys.stderr, flush=True
            )
            if self.progress:
                self.progress(self)

    def totals(self) -> Counter:
        """Outcome counts over every family."""
        return sum(self.counts.values(), Counter())

    def table(self) -> str:
        """Cases and outcomes per family, slowest case and largest peak memory, and a total."""
        kinds = ("ok", "error", *FAILURES)
        rows = [f"{'family':<15} {'cases':>6} " + " ".join(f"{k:>9}" for k in kinds)]
        rows[0] += f" {'max s':>6} {'max MB':>7}"
        lines = [(f, c, self.max_seconds[f], self.max_rss_mb[f]) for f, c in self.counts.items()]
        if lines:
            top = (max(x[2] for x in lines), max(x[3] for x in lines))
            lines = [*sorted(lines), ("total", self.totals(), *top)]
        for family, counts, seconds, megabytes in lines:
            row = f"{family:<15} {sum(counts.values()):>6} "
            row += " ".join(f"{counts.get(k, 0):>9}" for k in kinds)
            row += f" {seconds:>6.2f} {megabytes:>7.0f}"
            rows.append(row)
        return "\n".join(rows)


def run(
    families: list[str], cases: int, run_seed: int, workers: int, report: Report | None = None
) -> Report:
    """Run ``cases`` cases of each family on ``workers`` processes."""
    jobs = [(family, k) for k in range(cases) for family in families]
    jobs.reverse()
    report = report or Report()
    pool = [_Process(run_seed) for _ in range(max(1, workers))]
    try:
        busy: dict[int, _Process] = {}
        while jobs or busy:
            for process in pool:
                if process.job is None and jobs:
                    process.send(*jobs.pop())
                    busy[process.popen.stdout.fileno()] = process
            ready, _, _ = select.select(list(busy), [], [], 1.0)
            for fd in ready:
                process = busy.pop(fd)
                line = process.popen.stdout.readline()
                outcome = json.loads(line) if line else _lost(process, run_seed, "worker died")
                report.add(outcome)
                process.job = None
                if not line or outcome["kind"] == "memory":
                    pool[pool.index(process)] = _restart(process, run_seed)
            for fd, process in list(busy.items()):
                if time.perf_counter() - process.started > HARD_TIMEOUT_S:
                    del busy[fd]
                    report.add(_lost(process, run_seed, f"killed after {HARD_TIMEOUT_S:g} s"))
                    pool[pool.index(process)] = _restart(process, run_seed)
    finally:
        for process in pool:
            process.stop()
    return report


def _lost(process: _Process, run_seed: int, why: str) -> dict:
    family, number = process.job
    fam = FAMILIES[family]
    case = make_case(fam, fam.seeds(), number, run_seed)
    kind = "timeout" if why.startswith("killed") else "crash"
    seconds = time.perf_counter() - process.started
    return asdict(Outcome(case, kind, seconds=seconds, detail=why))


def _restart(process: _Process, run_seed: int) -> _Process:
    process.stop()
    return _Process(run_seed)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--family", action="append", choices=sorted(FAMILIES))
    parser.add_argument("--cases", type=int, default=3000, help="cases per family")
    parser.add_argument("--seed", type=int, default=0, help="run seed")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", type=Path, help="write counts and failures here")
    parser.add_argument("--case", type=int, help="replay one case in this process")
    parser.add_argument("--show", action="store_true", help="with --case: keep the file")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker_main(args.seed)
        return 0
    families = args.family or sorted(FAMILIES)
    if args.case is not None:
        worker = Worker(args.seed)
        outcome = worker.run(families[0], args.case)
        print(json.dumps(asdict(outcome), indent=2))
        if args.show:
            seeds = worker.family_seeds(families[0])
            case = outcome.case
            data = mutated_bytes(case, seeds[case.seed_index], seeds[case.seed_index].load())
            kept = Path(f"fuzz-case-{families[0]}-{args.case}{seeds[case.seed_index].suffix}")
            kept.write_bytes(data)
            print(f"file: {kept}")
        return 0
    started = time.perf_counter()

    def write_json(report: Report) -> None:
        if args.json:
            args.json.parent.mkdir(parents=True, exist_ok=True)
            summary = {
                "command": " ".join(sys.argv),
                "seed": args.seed,
                "cases_per_family": args.cases,
                "cases_done": report.done(),
                "seconds": round(time.perf_counter() - started, 1),
                "limits": {"seconds": TIME_LIMIT_S, "memory_mb": MEMORY_LIMIT_MB},
                "families": len(report.counts),
                "cases_by_family": {f: sum(c.values()) for f, c in sorted(report.counts.items())},
                "totals": dict(report.totals()),
                "counts": {f: dict(c) for f, c in sorted(report.counts.items())},
                "by_mutation": {m: dict(c) for m, c in report.by_mutation.items()},
                "max_seconds": report.max_seconds,
                "max_rss_mb": report.max_rss_mb,
                "failures": report.failures,
            }
            args.json.write_text(json.dumps(summary, indent=1))

    report = run(families, args.cases, args.seed, args.workers, Report(progress=write_json))
    print(report.table())
    print(f"{report.done()} cases in {time.perf_counter() - started:.0f} s")
    for failure in report.failures[:20]:
        case = failure["case"]
        print(
            f"FAIL {failure['kind']} {case['family']} case {case['number']} "
            f"({case['seed_name']}, {case['stage']}, {'+'.join(case['mutations'])}): "
            f"{failure['detail'][:300]}"
        )
    write_json(report)
    return 1 if report.failures else 0


if __name__ == "__main__":
    sys.exit(main())
