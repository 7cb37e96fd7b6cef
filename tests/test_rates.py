"""The sizing helper of the rate tests (benchmarks/sizing.py), checked by exact binomial sums
written out here independently of the helper; the ten rate tests' fixed seeds and their
printed line (benchmarks/rate_tests.py, ``python -m benchmarks.rates``)."""

from __future__ import annotations

import ast
import random
from math import comb
from pathlib import Path

import pytest

from benchmarks import rates as rates_cli
from benchmarks import sizing as rates
from benchmarks.rate_tests import RATE_TESTS, RateOutcome, RateTest
from benchmarks.scoring import TARGETS

#: Seed of the simulation of the sequential rule (printed on failure).
SIMULATION_SEED = 20000


def binomial_cdf(k, n, p):
    """P(X <= k), X ~ Binomial(n, p)."""
    return sum(comb(n, j) * p ** j * (1 - p) ** (n - j) for j in range(0, k + 1))


@pytest.mark.parametrize("target,higher", [(TARGETS["top1"], True),
                                            (TARGETS["unexplained_ok"], True),
                                            (TARGETS["false_claims"], False)])
def test_size_catches_a_rate_worse_by_a_tenth_with_power_0_8(target, higher):
    n, k_pass = rates.size(target, higher)
    if higher:
        power = binomial_cdf(k_pass - 1, n, target - 0.1)          # P(k < k_pass)
        at_target = binomial_cdf(k_pass - 1, n, target)
    else:
        power = 1 - binomial_cdf(k_pass, n, target + 0.1)          # P(k > k_pass)
        at_target = 1 - binomial_cdf(k_pass, n, target)
    assert power >= rates.POWER
    # a test at the target itself rarely fails (one-sided 95 % Wilson bound; discreteness
    # and the Wilson approximation leave it near, not at, 5 %)
    assert at_target <= 0.11
    # and n is the smallest: one case fewer has less power
    n1 = n - 1
    assert rates.fail_probability(n1, target, target - 0.1 if higher else target + 0.1,
                                  higher) < rates.POWER


def test_threshold_is_the_wilson_rule_edge():
    n, k = rates.size(0.9)
    assert rates.passes(k, n, 0.9) and not rates.passes(k - 1, n, 0.9)
    n, k = rates.size(0.05, higher_is_better=False)
    assert rates.passes(k, n, 0.05, False) and not rates.passes(k + 1, n, 0.05, False)


@pytest.mark.parametrize("n", [2, 3, 4])
def test_the_old_sizes_have_no_power(n):
    """The old CI sizes (2-4 draws, 95 % two-sided Wilson interval) catch a rate 0.1 below
    the top-1 or unexplained target with probability below 0.8: the reason for the sizing."""
    for target in (TARGETS["top1"], TARGETS["unexplained_ok"]):
        k_pass = rates.threshold(n, target, z=1.96)
        fail = binomial_cdf(k_pass - 1, n, target - 0.1) if k_pass > 0 else 0.0
        assert fail == pytest.approx(rates.fail_probability(n, target, target - 0.1, z=1.96))
        assert fail < rates.POWER


def _paths_fail_probability(n_max, target, higher, rate, batch, step):
    """P(fail) of the sequential test by brute-force enumeration of the draws' outcomes (an
    independent check of rates.sequential_oc): a recursion over looks, the first after
    ``batch`` cases, then every ``step``."""
    g = rate if higher else 1 - rate

    def go(n, good):
        total = 0.0
        m = min(batch if n == 0 else step, n_max - n)
        for j in range(m + 1):
            p = comb(m, j) * g ** j * (1 - g) ** (m - j)
            verdict = rates.look(good + j, n + m, target, higher, n_max)
            if verdict == "fail":
                total += p
            elif verdict == "go on":
                total += p * go(n + m, good + j)
        return total
    return go(0, 0)


@pytest.mark.parametrize("target,higher", [(TARGETS["top1"], True),
                                            (TARGETS["unexplained_ok"], True),
                                            (TARGETS["false_claims"], False)])
def test_sequential_test_keeps_the_power_and_size(target, higher):
    n_max = rates.sequential_plan(target, higher)
    worse = target - 0.1 if higher else target + 0.1
    p_worse, _ = rates.sequential_oc(n_max, target, higher, worse)
    p_target, _ = rates.sequential_oc(n_max, target, higher, target)
    assert p_worse >= rates.POWER
    assert p_target <= 0.11
    # the smallest truncation with that power
    assert rates.sequential_oc(n_max - rates.STEP, target, higher, worse)[0] < rates.POWER


def test_sequential_oc_matches_enumeration():
    for target, higher, rate, step in [(0.9, True, 0.8, 8), (0.9, True, 0.93, 4),
                                       (0.05, False, 0.15, 4)]:
        n_max = 32
        exact = rates.sequential_oc(n_max, target, higher, rate, batch=8, step=step)[0]
        assert exact == pytest.approx(
            _paths_fail_probability(n_max, target, higher, rate, 8, step), rel=1e-12)


def test_sequential_run_stops_early_on_a_perfect_record():
    calls = []

    def rows_of(start, count):
        calls.append(count)
        return [True] * count
    passed, rows, good = rates.run_sequential(rows_of, bool, 0.9)
    assert passed and len(rows) == 14 and good == 14 and calls == [14]


def test_after_the_first_batch_the_test_looks_every_step():
    """One miss in the first batch: the rule goes on, drawing ``STEP`` cases at a time, and
    passes at the first look where Wald's ratio allows (14 + 8 cases at a target of 0.9)."""
    calls = []

    def rows_of(start, count):
        calls.append(count)
        return [i + start != 0 for i in range(count)]
    passed, rows, good = rates.run_sequential(rows_of, bool, 0.9)
    assert passed and calls == [14] + [rates.STEP] * (len(calls) - 1) and len(calls) > 1
    assert rates.look(good, len(rows), 0.9) == "pass"
    assert rates.look(good - rates.STEP, len(rows) - rates.STEP, 0.9) == "go on"


@pytest.mark.parametrize("target,higher,batch", [(0.9, True, 14), (0.8, True, 12),
                                                  (0.05, False, 16)])
def test_a_batch_is_the_fewest_cases_that_can_pass_at_the_first_look(target, higher, batch):
    """All good (successes, or no event under a ceiling), a batch passes at once; the
    cores' multiple below it goes on."""
    assert rates.batch_size(target, higher) == batch and batch % rates.CORES == 0
    assert rates.look(batch, batch, target, higher) == "pass"
    assert rates.look(batch - 2, batch - 2, target, higher) == "go on"


def _marked(marker):
    """``{test name: its pytest markers}`` of the rate-test files' functions with ``marker``."""
    import ast
    from pathlib import Path
    out = {}
    for path in sorted(Path(__file__).parent.glob("test_*rates.py")):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.FunctionDef):
                marks = {d.attr for d in node.decorator_list if isinstance(d, ast.Attribute)}
                if marker in marks:
                    out[node.name] = marks
    return out


def test_the_suite_runs_every_rate_test_and_the_long_ones_are_rate_tests():
    """CI runs the suite's default selection, which deselects nothing: all ten rate tests run
    with it; the four ``long_rates`` ones also carry ``rates`` (``-m rates`` runs all ten)
    and ``slow`` (not the fast lane)."""
    from pathlib import Path

    import tomllib
    conf = tomllib.loads((Path(__file__).parents[1] / "pyproject.toml").read_text())
    assert "-m" not in conf["tool"]["pytest"]["ini_options"]["addopts"].split()
    long, all_rates = _marked("long_rates"), _marked("rates")
    assert long and all(m >= {"rates", "slow"} for m in long.values())
    assert len(all_rates) == 10 and len(all_rates) - len(long) == 6


class _Item:
    def __init__(self, name, *marks):
        self.name, self.marks = name, set(marks)

    def get_closest_marker(self, name):
        return name if name in self.marks else None


def test_the_rate_tests_are_collected_first_and_the_long_ones_lead():
    """tests/conftest.py orders the collection: ``long_rates``, then the other rate tests,
    then the rest, each group in its collected order (the test processes take the longest
    first and finish together)."""
    import conftest
    items = [_Item("a"), _Item("r1", "rates", "slow"), _Item("b", "slow"),
             _Item("l1", "rates", "long_rates", "slow"), _Item("r2", "rates"),
             _Item("l2", "rates", "long_rates")]
    conftest.pytest_collection_modifyitems(None, items)
    assert [i.name for i in items] == ["l1", "l2", "r1", "r2", "a", "b"]


@pytest.mark.parametrize("target, rate", [(0.9, 0.93), (0.8, 0.885), (0.9, 0.8)])
def test_stopping_counts_are_a_distribution_on_the_looks(target, rate):
    """The stopping case counts (rates.stopping_counts, behind sequential_oc) sum to one, fall
    on the looks (the first batch, then every ``STEP`` cases, up to n_max), and the test's
    failures are those of the truncated Wilson rule or Wald's fail bound (checked by a simulation of
    the rule itself, 20000 runs, within 5 standard errors)."""
    n_max, batch = rates.sequential_plan(target), rates.batch_size(target)
    stops, p_fail = rates.stopping_counts(n_max, target, True, rate)
    assert sum(stops.values()) == pytest.approx(1.0, abs=1e-12)
    assert set(stops) <= set(range(batch, n_max + 1, rates.STEP)) | {n_max}
    rng, runs, fails, total_n = random.Random(SIMULATION_SEED), 20000, 0, 0
    for _ in range(runs):
        n = good = 0
        while True:
            m = rates.draw_size(n, n_max, batch)
            good += sum(rng.random() < rate for _ in range(m))
            n += m
            verdict = rates.look(good, n, target, True, n_max)
            if verdict != "go on":
                break
        fails += verdict == "fail"
        total_n += n
    se = (p_fail * (1 - p_fail) / runs) ** 0.5 + 1e-4
    assert abs(fails / runs - p_fail) < 5 * se, f"seed {SIMULATION_SEED}"
    e_n = sum(n * p for n, p in stops.items())
    assert abs(total_n / runs - e_n) < 0.05 * e_n, f"seed {SIMULATION_SEED}"


def _run_calls() -> list:
    """Names ``RATE_TESTS[NAME]`` read by the rate-test files' tests, in order."""
    names = []
    for path in sorted(Path(__file__).parent.glob("test_*rates.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if (isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name)
                    and node.value.id == "RATE_TESTS"):
                names.append(node.slice.value)
    return names


def test_every_rate_test_runs_once_on_its_own_fixed_seed():
    """The ten rate tests of the suite are the ten of benchmarks.rate_tests, each on a fixed
    seed of its own (the same cases every run: CI is a test, not a draw)."""
    assert sorted(_run_calls()) == sorted(RATE_TESTS) and len(RATE_TESTS) == 10
    seeds = [t.seed for t in RATE_TESTS.values()]
    assert all(isinstance(s, int) for s in seeds) and len(set(seeds)) == len(seeds)


def test_the_printed_line_names_the_rate_its_interval_and_the_verdict():
    def good(r):
        return r
    ceiling = RateTest("x", None, good, 0.05, 7, higher_is_better=False)
    rows = [True] * 15 + [False]
    out = RateOutcome(ceiling, 7, rows, 1, True)
    assert out.line() == ("x: seed 7: 1/16 = 0.062 (95% Wilson 0.01-0.28), target <= 0.05: "
                          "pass")
    assert out.misses() == [False] and out.failure().endswith("misses: [False]")
    floor = RateTest("y", None, good, 0.9, 8)
    assert RateOutcome(floor, 9, rows, 15, False, "; note").line().endswith(
        "target >= 0.9: FAIL; note")


def test_the_command_refuses_an_unknown_rate_test(capsys):
    with pytest.raises(SystemExit) as exit_:
        rates_cli.main(["no_such_test"])
    assert exit_.value.code == 2 and "unknown rate test(s) no_such_test" in capsys.readouterr().err
    assert 0 <= rates_cli.fresh_seed() < 2 ** 32
