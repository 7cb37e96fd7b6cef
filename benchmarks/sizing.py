r"""Sizing of the statistical rate tests (the Wilson rule) and their group-sequential rule.

A rate test draws ``n`` cases, counts the successes ``k`` and **fails when the data
show, at one-sided 95 % confidence, that the target is missed**: for a target to reach
(``higher_is_better``, e.g. top-1 ≥ 0.9) it fails when the upper end of the Wilson score
interval of ``k/n`` (:func:`benchmarks.scoring.wilson_interval`, ``z`` =
:data:`Z_ONE_SIDED`) is below the target; for a ceiling (false claims ≤ 0.05) when its
lower end is above it. For a given ``n`` that is a count threshold: the test passes for
``k >= k_pass`` (target to reach) or ``k <= k_pass`` (ceiling).

:func:`size` picks the smallest ``n`` at which a true rate :data:`WORSE_BY` worse than the
target (0.1 below a target to reach, 0.1 above a ceiling) fails the test with probability
at least :data:`POWER`, by exact binomial sums. A true rate exactly at the target then fails
with probability 0.08 (top-1 0.9: n 61, pass k >= 52), 0.06 (unexplained 0.8: 105, >= 78)
and 0.10 (false claims 0.05: 36, k <= 3) (:func:`fail_probability`; the discreteness of k
moves it off the nominal 5 %); rates better than the target fail less. ``tests/test_rates.py``
checks the power, the size at the target and that ``n`` is the smallest, by exact sums.
"""

from __future__ import annotations

import math
import os

from benchmarks.scoring import wilson_interval
from powertrain.parallel import executor

#: Normal quantile of a one-sided 95 % bound.
Z_ONE_SIDED = 1.6448536269514722
#: How much worse than its target a true rate must be caught [rate] ...
WORSE_BY = 0.1
#: ... and with which probability (power).
POWER = 0.8


def passes(k, n, target, higher_is_better=True, z=Z_ONE_SIDED) -> bool:
    """The Wilson rule: ``k`` successes in ``n`` do not show that ``target`` is missed."""
    lo, hi = wilson_interval(k, n, z)
    return hi >= target if higher_is_better else lo <= target


def threshold(n, target, higher_is_better=True, z=Z_ONE_SIDED) -> int:
    """``k_pass``: fewest successes that pass (target to reach) or most that pass (ceiling)."""
    ok = [k for k in range(n + 1) if passes(k, n, target, higher_is_better, z)]
    return ok[0] if higher_is_better else ok[-1]


def _binom_pmf(k, n, p):
    return math.comb(n, k) * p ** k * (1 - p) ** (n - k)


def fail_probability(n, target, true_rate, higher_is_better=True, z=Z_ONE_SIDED) -> float:
    """Probability, by the exact binomial sum, that ``n`` cases of rate ``true_rate`` fail."""
    return sum(_binom_pmf(k, n, true_rate) for k in range(n + 1)
               if not passes(k, n, target, higher_is_better, z))


def size(target, higher_is_better=True, worse_by=WORSE_BY, power=POWER, z=Z_ONE_SIDED,
         n_max=2000):
    """``(n, k_pass)``: the smallest number of cases whose test fails with probability
    ≥ ``power`` when the true rate is ``worse_by`` worse than ``target``, and its pass
    threshold (:func:`threshold`)."""
    worse = target - worse_by if higher_is_better else target + worse_by
    for n in range(1, n_max + 1):
        if fail_probability(n, target, worse, higher_is_better, z) >= power:
            return n, threshold(n, target, higher_is_better, z)
    raise ValueError(f"no n <= {n_max} reaches power {power}")


# --- group-sequential rate tests -------------------------------------------------------------
#
# A fixed-size test spends its n cases even when the first dozen already show a rate far
# above its target. The group-sequential version draws a first batch (the fewest cases that
# can pass at once, :func:`batch_size`), then STEP cases at a time, and after each draw stops
# early on Wald's likelihood ratio between the target and the rate WORSE_BY worse (Wald
# 1947, *Sequential Analysis*): it passes when the ratio falls below
# WALD_PASS = beta/(1 - alpha) and fails when it rises above WALD_FAIL = (1 - beta)/alpha
# (alpha 0.05, beta 0.2: the same error rates as the fixed-size test). Truncated at ``n_max``,
# where the Wilson rule decides as above. :func:`sequential_plan` picks the smallest
# ``n_max`` whose exact operating characteristic (:func:`sequential_oc`, a sum over every
# path of the draws) still fails a rate WORSE_BY worse with probability >= POWER.

WALD_ALPHA = 0.05
WALD_BETA = 0.2
WALD_PASS = WALD_BETA / (1 - WALD_ALPHA)
WALD_FAIL = (1 - WALD_BETA) / WALD_ALPHA
#: Cores of a CI runner: a batch is a multiple of them.
CORES = 2
#: Cases drawn at each later look, after the first batch: looking every 4 cases instead of
#: every batch (14 at a target of 0.9) stops a test nearer the point where its record became
#: clear: 27.8 instead of 30.2 cases on average at a true rate of 0.93 against 0.9, 22.4
#: instead of 26.7 at 0.885 against 0.8, with the same power (exact sums,
#: tests/test_rates.py); two cores still share each draw.
STEP = 2 * CORES


def _good_rates(target, higher_is_better, worse_by=WORSE_BY):
    """The target and the worse rate as rates of *good* outcomes (a ceiling on a bad rate
    is a floor on the good one)."""
    q0 = target if higher_is_better else 1 - target
    return q0, q0 - worse_by


def batch_size(target, higher_is_better=True) -> int:
    """Cases per batch: the fewest (a multiple of :data:`CORES`) whose batch, all good, passes
    Wald's rule at the first look: 14 for a target of 0.9, 12 for 0.8, 16 for a ceiling of
    0.05. A clear record then stops as early as the rule allows (with batches of 8 it went
    on to 16 cases at 0.9 and 0.8)."""
    q0, q1 = _good_rates(target, higher_is_better)
    n = math.ceil(math.log(WALD_PASS) / math.log(q1 / q0))
    return CORES * math.ceil(n / CORES)


def look(n_good, n, target, higher_is_better=True, n_max=None):
    """Decision after ``n`` cases with ``n_good`` good outcomes (successes for a target to
    reach, non-events for a ceiling): ``"pass"``, ``"fail"`` or ``"go on"``."""
    q0, q1 = _good_rates(target, higher_is_better)
    llr = n_good * math.log(q1 / q0) + (n - n_good) * math.log((1 - q1) / (1 - q0))
    if n_max is not None and n >= n_max:
        k = n_good if higher_is_better else n - n_good
        return "pass" if passes(k, n, target, higher_is_better) else "fail"
    if llr <= math.log(WALD_PASS):
        return "pass"
    if llr >= math.log(WALD_FAIL):
        return "fail"
    return "go on"


def draw_size(n, n_max, batch, step=STEP) -> int:
    """Cases to draw after ``n`` drawn: the first batch, then ``step`` at a time, never past
    ``n_max``."""
    return min(batch if n == 0 else step, n_max - n)


def stopping_counts(n_max, target, higher_is_better, true_rate, batch=None, step=STEP):
    """``({n: P(stop at n)}, P(fail))`` of the truncated group-sequential test when the true
    rate is ``true_rate`` (as ``target``: of successes, or of events for a ceiling), by exact
    sums over every path of the draws (a first ``batch``, default :func:`batch_size`, then
    ``step`` at a time)."""
    batch = batch or batch_size(target, higher_is_better)
    g = true_rate if higher_is_better else 1 - true_rate
    alive = {0: 1.0}                       # good outcomes -> probability, still going on
    n, p_fail, stops = 0, 0.0, {}
    while alive:
        m = draw_size(n, n_max, batch, step)
        nxt = {}
        for k, p in alive.items():
            for j in range(m + 1):
                nxt[k + j] = nxt.get(k + j, 0.0) + p * _binom_pmf(j, m, g)
        n += m
        alive = {}
        for k, p in nxt.items():
            verdict = look(k, n, target, higher_is_better, n_max)
            if verdict == "go on":
                alive[k] = p
                continue
            stops[n] = stops.get(n, 0.0) + p
            p_fail += p if verdict == "fail" else 0.0
    return stops, p_fail


def sequential_oc(n_max, target, higher_is_better, true_rate, batch=None, step=STEP):
    """``(P(fail), expected number of cases)`` of the truncated group-sequential test
    (:func:`stopping_counts`)."""
    stops, p_fail = stopping_counts(n_max, target, higher_is_better, true_rate, batch, step)
    return p_fail, sum(n * p for n, p in stops.items())


def sequential_plan(target, higher_is_better=True, batch=None, step=STEP, n_limit=600):
    """Smallest ``n_max`` (``batch``, default :func:`batch_size`, plus a multiple of
    ``step``) at which the sequential test fails a rate WORSE_BY worse than ``target`` with
    probability >= POWER."""
    batch = batch or batch_size(target, higher_is_better)
    worse = target - WORSE_BY if higher_is_better else target + WORSE_BY
    for n_max in range(batch, n_limit + 1, step):
        if sequential_oc(n_max, target, higher_is_better, worse, batch, step)[0] >= POWER:
            return n_max
    raise ValueError(f"no n_max <= {n_limit} reaches power {POWER}")


def run_sequential(rows_of, is_good, target, higher_is_better=True, batch=None, step=STEP):
    """Draw ``rows_of(start, count)`` (a list of result rows: the first batch, default
    :func:`batch_size`, then ``step`` at a time) until :func:`look` decides; returns
    ``(passed, rows, n_good)``."""
    batch = batch or batch_size(target, higher_is_better)
    n_max = sequential_plan(target, higher_is_better, batch, step)
    rows, good = [], 0
    while True:
        new = rows_of(len(rows), draw_size(len(rows), n_max, batch, step))
        rows += new
        good += sum(bool(is_good(r)) for r in new)
        verdict = look(good, len(rows), target, higher_is_better, n_max)
        if verdict != "go on":
            return verdict == "pass", rows, good


def run_sequential_map(row_fn, task_of, is_good, target, higher_is_better=True):
    """:func:`run_sequential` over rows ``row_fn(task_of(i))`` computed on every core by one
    pool of processes kept for all the draws (:func:`powertrain.parallel.executor`): its
    workers keep what they loaded (engines, compiled kernels) from one draw to the next,
    where a pool per draw started them afresh each time (about a second per process)."""
    # under pytest-xdist every core already runs a test: the rows run in its process
    where = "serial" if os.environ.get("PYTEST_XDIST_WORKER") else None
    with executor(where, n_jobs=batch_size(target, higher_is_better)) as ex:
        return run_sequential(
            lambda start, count: list(ex.map(row_fn, [task_of(i) for i in
                                                      range(start, start + count)])),
            is_good, target, higher_is_better)
