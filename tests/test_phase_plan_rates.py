"""Rates of issue 21 on fixed seeds of the independent truth (the same cases every run): a
weak cylinder named with its sign when the order phases are measured; with whole-order phases
only, never a set of cylinders without the true one; a two-run plan (loads 1.0 and 0.4) never
less right than its best single run, and no wrong name with engine-side channels; on two-sided
plans, amplitude-dependent mounts told from a stiffer mount (named right, never "ambiguous").

Judged by the group-sequential Wilson rule of :mod:`benchmarks.sizing` (a first batch, 14
cases for a target of 0.9 and 16 for a ceiling of 0.05, then 4 at a time until it decides; a
true rate 0.1 worse than the target fails with probability >= 0.8, as
tests/test_diagnosis_rates.py); the cases are those of :mod:`benchmarks.rate_tests`. ``slow``
and ``rates``, run with the suite; the two plan tests, the longest, also ``long_rates`` (run
first; alone: ``python -m pytest -m long_rates``). The benchmark lines quoted in
docs/validation/diagnosis.md are printed by ``scripts/phase_plan_benchmark.py``.
"""

import pytest

from benchmarks.rate_tests import RATE_TESTS, plan_is_bad, run


@pytest.mark.slow
@pytest.mark.rates
def test_weak_cylinder_and_sign_are_named_with_phase():
    outcome = run(RATE_TESTS["weak_cylinder_with_phase"])
    print(outcome.line())
    assert outcome.passed, outcome.failure()


@pytest.mark.slow
@pytest.mark.rates
def test_without_half_order_phases_the_named_set_holds_the_truth():
    outcome = run(RATE_TESTS["whole_order_phase_set"])
    print(outcome.line())
    assert outcome.passed, outcome.failure()


@pytest.mark.slow
@pytest.mark.rates
@pytest.mark.long_rates
def test_two_run_plan_is_never_less_right_than_its_best_single_run_nor_wrong():
    """Less right than the best single run, or a wrong name: <= 0.05 (one rule, both)."""
    outcome = run(RATE_TESTS["two_run_plan"])
    print(outcome.line())
    assert outcome.passed, outcome.failure()


@pytest.mark.parametrize("truth, plan, singles, bad", [
    (["a"], ["a"], None, False),                 # right: the singles cannot matter
    (["a"], ["b"], None, True),                  # a wrong name whatever the singles say
    (["a"], [], [["a"], []], True),              # less right than a single run
    (["a"], [], [[], ["b"]], False),             # no claim, no single right either
    ([], [], None, False),                       # no effect, no claim
    ([], ["b"], None, True)])
def test_the_plan_rule_reads_the_singles_only_where_they_count(truth, plan, singles, bad):
    assert plan_is_bad({"truth": truth, "plan": plan, "singles": singles}) == bad


@pytest.mark.slow
@pytest.mark.rates
@pytest.mark.long_rates
def test_two_sided_plans_tell_an_amplitude_law_from_a_stiffer_mount():
    """Named right >= 0.9 (group-sequential Wilson rule), and "ambiguous" never."""
    outcome = run(RATE_TESTS["two_sided_plan"])
    print(outcome.line())
    assert outcome.passed, outcome.failure()
