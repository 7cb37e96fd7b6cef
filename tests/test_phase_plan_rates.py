"""Rates of issue 21 over fresh draws of the independent truth (no pinned seeds): a weak
cylinder named with its sign when the order phases are measured; with whole-order phases
only, never a set of cylinders without the true one; a two-run plan (loads 1.0 and 0.4)
never less right than its best single run, and no wrong name with engine-side channels; on
two-sided plans, amplitude-dependent mounts told from a stiffer mount (named right, never
"ambiguous").

Sized and judged by the Wilson rule of ``tests/rates.py`` (as tests/test_diagnosis_rates.py);
``slow`` and ``rates``: they run on request (``python -m pytest -m rates``). The benchmark
lines quoted in docs/validation/diagnosis.md are printed by
``scripts/phase_plan_benchmark.py``.
"""

import os

import numpy as np
import pytest
import rates

from powertrain.diagnosis import diagnose
from powertrain.parallel import run_map
from powertrain.validation.cases import FLOOR, engines, make_case
from powertrain.validation.plans import make_plan_case

#: Redraws allowed to find a detectable case.
MAX_DRAWS = 30
#: Plan kinds (engine side only).
PLAN_KINDS = ("mount_temperature", "amplitude_elastomer", "weak_cylinder", "balancer_shafts")
#: Two-sided plan kinds: issue 21's pair, an amplitude law or a stiffer mount.
TWO_SIDED_KINDS = ("amplitude_elastomer", "mount_temperature")


def _seed():
    return int.from_bytes(os.urandom(4), "little")


def _cylinder_row(task):
    i, seed, phase = task
    eng = ("sz", "traces")[i % 2]
    rng = np.random.default_rng([seed, i])
    for _ in range(MAX_DRAWS):
        case = make_case(i, ["weak_cylinder"], eng, int(rng.integers(2 ** 31)), phase=phase)
        if case.detectable:
            break
    d = diagnose(case.measured, engines()[eng], noise_floor=FLOOR).to_dict()
    f = d.get("finding") or {}
    return {"truth": (case.truth[0][1]["cylinder"] + 1, "weak"),
            "named": (f.get("cylinder"), f.get("sign")),
            "could_be": [(c["cylinder"], c["sign"]) for c in f.get("could_be", [])]}


@pytest.mark.slow
@pytest.mark.rates
def test_weak_cylinder_and_sign_are_named_with_phase():
    n, k_pass = rates.size(0.9)
    seed = _seed()
    rows = run_map(_cylinder_row, [(i, seed, "all") for i in range(n)])
    k = sum(r["named"] == r["truth"] for r in rows)
    assert k >= k_pass, f"seed {seed}: {k}/{n} (pass needs {k_pass}): {rows}"


@pytest.mark.slow
@pytest.mark.rates
def test_without_half_order_phases_the_named_set_holds_the_truth():
    n, k_pass = rates.size(0.05, higher_is_better=False)
    seed = _seed()
    rows = run_map(_cylinder_row, [(i, seed, "whole") for i in range(n)])
    k = sum(bool(r["could_be"]) and r["truth"] not in r["could_be"] for r in rows)
    assert k <= k_pass, f"seed {seed}: {k}/{n} wrong (pass needs <= {k_pass}): {rows}"


def _claim(measured, engine):
    d = diagnose(measured, engine, noise_floor=FLOOR).to_dict()
    return sorted((d.get("chosen") or {}).get("effects", []))


def _plan_row(task):
    i, seed = task
    kind = PLAN_KINDS[i % len(PLAN_KINDS)]
    rng = np.random.default_rng([seed, i])
    for _ in range(MAX_DRAWS):
        case = make_plan_case(i, [kind], int(rng.integers(2 ** 31)), phase="all")
        if case.detectable:
            break
    e = engines()["sz"]
    singles = [_claim(r.measured, e.at_load(load)) for r, load in zip(case.runs, case.loads)]
    return {"truth": case.truth_set, "singles": singles, "plan": _claim(case.plan(), e)}


@pytest.mark.slow
@pytest.mark.rates
def test_two_run_plan_is_never_less_right_than_its_best_single_run_nor_wrong():
    n, k_pass = rates.size(0.05, higher_is_better=False)
    seed = _seed()
    rows = run_map(_plan_row, [(i, seed) for i in range(n)])
    less = sum(r["truth"] in r["singles"] and r["plan"] != r["truth"] for r in rows)
    wrong = sum(bool(r["plan"]) and r["plan"] != r["truth"] for r in rows)
    assert less <= k_pass and wrong <= k_pass, \
        f"seed {seed}: less right {less}, wrong {wrong} of {n} (<= {k_pass}): {rows}"


def _two_sided_plan_row(task):
    i, seed = task
    kind = TWO_SIDED_KINDS[i % len(TWO_SIDED_KINDS)]
    rng = np.random.default_rng([seed, i])
    for _ in range(MAX_DRAWS):
        case = make_plan_case(i, [kind], int(rng.integers(2 ** 31)), phase="all",
                              sides="both")
        if case.detectable:
            break
    d = diagnose(case.plan(), case.engine, noise_floor=FLOOR).to_dict()
    return {"truth_set": case.truth_set, "verdict": d["verdict"],
            "claimed": sorted((d.get("chosen") or {}).get("effects", []))}


@pytest.mark.slow
@pytest.mark.rates
def test_two_sided_plans_tell_an_amplitude_law_from_a_stiffer_mount():
    """Named right >= 0.9 (group-sequential Wilson rule), and "ambiguous" never."""
    seed = _seed()
    passed, rows, good = rates.run_sequential(
        lambda start, count: run_map(_two_sided_plan_row,
                                     [(i, seed) for i in range(start, start + count)]),
        lambda r: r["claimed"] == r["truth_set"], 0.9)
    ambiguous = [r for r in rows if r["verdict"].startswith("ambiguous")]
    assert passed and not ambiguous, f"seed {seed}: {good}/{len(rows)} right: {rows}"
