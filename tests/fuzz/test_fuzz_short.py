"""Short fuzz run of every reader family (the long one is ``make fuzz``), and the runner's own
classification of outcomes."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import REPO_ROOT
from tests.fuzz.families import FAMILIES, Family, Seed, check_observations
from tests.fuzz.mutators import TEXT_MUTATIONS
from tests.fuzz.runner import FAILURES, Worker, run
from vo_doppler.errors import InputError

SHORT_CASES = 20


@pytest.mark.slow
def test_short_fuzz_of_every_reader_family():
    """20 mutated files of every registered family (600 with the shared data, 420 without the
    families seeded from it): each read plausibly or refused with the project's error naming
    the file, within 500 MB. The 5-s limit is ``make fuzz``'s (tests do not depend on timing: a
    loaded machine may be slow); a case killed at the runner's hard timeout still fails."""
    families = sorted(FAMILIES)
    report = run(families, cases=SHORT_CASES, run_seed=12, workers=2)
    failures = [
        (f["kind"], f["case"]["family"], f["case"]["number"], f["detail"][:200])
        for f in report.failures
        if f["kind"] != "slow"
    ]
    assert failures == []
    assert sorted(report.counts) == families
    for family in families:
        counts = report.counts[family]
        assert sum(counts.values()) == SHORT_CASES, family
        assert counts["ok"] > 0 and counts["error"] > 0, (family, dict(counts))


def test_no_seed_holds_the_checkouts_path():
    """A case is its family's seed mutated at offsets drawn from the run seed: a seed holding
    the checkout's path (the manifest's did, made absolute) would make case k a different
    file in every checkout, and a failure found in one could not be replayed in another."""
    root = str(REPO_ROOT).encode()
    holding = [
        (name, seed.name)
        for name, family in sorted(FAMILIES.items())
        for seed in family.seeds()
        if root in seed.load()
    ]
    assert holding == []


def _sample_obs_seed() -> Seed:
    """The sample sequence's observation file, plain (its four variants come last)."""
    return FAMILIES["rinex-obs"].seeds()[-4]


def _seed_text() -> bytes:
    return _sample_obs_seed().load()[:20_000]


@pytest.fixture
def fake_family():
    """A family whose behaviour the test chooses, registered for the test only."""
    made = []

    def make(read):
        family = Family(
            "fake", lambda: [Seed("obs", _seed_text, suffix=".obs")], read, lambda r, p: r
        )
        FAMILIES["fake"] = family
        made.append(family)
        return family

    yield make
    FAMILIES.pop("fake", None)


@pytest.mark.parametrize(
    ("read", "kind"),
    [
        (lambda path: [], "ok"),
        (lambda path: ["time goes backwards"], "violation"),
        (lambda path: (_ for _ in ()).throw(KeyError("x")), "crash"),
        (lambda path: (_ for _ in ()).throw(InputError("bad", path)), "error"),
        (lambda path: (_ for _ in ()).throw(InputError("bad")), "unnamed"),
    ],
)
def test_runner_classifies_outcomes(fake_family, read, kind, monkeypatch):
    # In-process here, so the test process's own peak memory must not count as the case's.
    monkeypatch.setattr("tests.fuzz.runner.MEMORY_LIMIT_MB", float("inf"))
    fake_family(read)
    outcome = Worker(0).run("fake", 3)
    assert outcome.kind == kind
    assert (kind in FAILURES) == (kind not in ("ok", "error"))


def test_mutations_are_deterministic_and_change_the_file():
    import random

    data = _seed_text()
    changed = 0
    for name, mutation in TEXT_MUTATIONS.items():
        first = mutation(data, random.Random(5))
        assert first == mutation(data, random.Random(5)), name
        changed += first != data
    assert changed >= len(TEXT_MUTATIONS) - 1


def test_observation_invariants_catch_impossible_values(tmp_path):
    obs_path = tmp_path / "seed.obs"
    obs_path.write_bytes(_sample_obs_seed().load())
    obs = FAMILIES["rinex-obs"].read(obs_path)
    assert check_observations(obs, obs_path) == []
    backwards = obs.__class__(**{**obs.__dict__, "epoch_time": obs.epoch_time[::-1]})
    assert "epoch times not strictly increasing" in check_observations(backwards, obs_path)
    bad_prn = obs.__class__(**{**obs.__dict__, "prn": np.zeros_like(obs.prn)})
    assert any("number outside" in v for v in check_observations(bad_prn, obs_path))
