r"""Sizing of the statistical rate tests (the Wilson rule).

A rate test draws ``n`` fresh cases, counts the successes ``k`` and **fails when the data
show, at one-sided 95 % confidence, that the target is missed**: for a target to reach
(``higher_is_better``, e.g. top-1 ≥ 0.9) it fails when the upper end of the Wilson score
interval of ``k/n`` (:func:`powertrain.validation.scoring.wilson_interval`, ``z`` =
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

from powertrain.validation.scoring import wilson_interval

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
