"""Diagnosis rates of the blind benchmark's cases on fixed seeds (the same cases every run).

Each test draws the cases of its :class:`benchmarks.rate_tests.RateTest` from the test's fixed
seed (Newmark truth of :mod:`benchmarks`, its own effect models, scatter and noise floor),
diagnoses them (on every core, one pool of processes for all its draws) and applies the
group-sequential Wilson rule of :mod:`benchmarks.sizing`: a first batch (14 cases for a target
of 0.9, 16 for a ceiling of 0.05: the fewest that can pass at once), then 4 at a time, until
Wald's likelihood ratio between the target and a rate 0.1 worse decides, truncated where the
Wilson rule (one-sided 95 %) decides; a true rate 0.1 worse than the target fails with
probability >= 0.8 (exact sums, tests/test_rates.py). The diagnoses skip the band check,
which enters nothing the tests judge (``benchmarks.rate_tests.diagnosis``).

Each prints one line (name, seed, k/n, rate, Wilson interval, target, pass/FAIL);
``python -m benchmarks.rates --fresh`` prints the same lines for new draws. They carry the
``slow`` and ``rates`` markers and run with the suite; the passive-side test, the longest,
also ``long_rates`` (run first; alone: ``python -m pytest -m long_rates``). The 50-case rates
of the benchmark are printed by ``scripts/blind_diagnosis.py``.
"""

import pytest

from benchmarks.kinds import IN_LIBRARY, KINDS
from benchmarks.rate_tests import RATE_TESTS, run
from powertrain.effects import EFFECTS


@pytest.mark.slow
@pytest.mark.rates
def test_effect_free_runs_make_no_false_claims():
    outcome = run(RATE_TESTS["effect_free_false_claims"])
    print(outcome.line())
    assert outcome.passed, outcome.failure()


@pytest.mark.slow
@pytest.mark.rates
def test_detectable_in_library_effects_are_named():
    outcome = run(RATE_TESTS["in_library_top1"])
    print(outcome.line())
    assert outcome.passed, outcome.failure()


@pytest.mark.slow
@pytest.mark.rates
def test_detectable_out_of_library_effects_are_unexplained():
    outcome = run(RATE_TESTS["out_of_library_unexplained"])
    print(outcome.line())
    assert outcome.passed, outcome.failure()


def test_every_in_library_kind_has_a_library_match():
    assert {KINDS[k].library for k in IN_LIBRARY} <= set(EFFECTS)


@pytest.mark.slow
@pytest.mark.rates
@pytest.mark.long_rates
def test_passive_side_body_and_mount_changes_are_named():
    """Issue 13's target (>= 0.9 of detectable body-mode and one-mount stiffness cases named,
    both sides of every mount measured)."""
    outcome = run(RATE_TESTS["passive_side_named"])
    print(outcome.line())
    assert outcome.passed, outcome.failure()
