#!/usr/bin/env python
"""The diagnosis' answers on the first cases of the ten rate tests, saved or compared.

Runs cases ``0..N-1`` of every rate test of :data:`benchmarks.rate_tests.RATE_TESTS` on its
fixed seed and keeps, per case, the row the test judges and every diagnosis the row made
(``to_dict()`` without its timings and its effects library), with the CPU time per test.
``--save rows.json`` writes them; ``--compare rows.json`` checks a run against a saved one:
strings, booleans and integers identical, floats equal to ``--rtol`` (relative, with an
absolute floor of ``rtol`` times the largest magnitude of its list), and prints the CPU time
of both runs per test.

Usage: ``python scripts/diagnosis_equivalence.py [--cases 6] [--tests a,b]
(--save rows.json | --compare rows.json) [--rtol 1e-6]``.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # benchmarks/, not installed

from benchmarks import rate_tests as rt  # noqa: E402
from powertrain.diagnosis.result import _finite_or_null, _jsonable  # noqa: E402

#: Keys left out of a diagnosis: timings and the registry's description.
SKIP = {"seconds", "effects_library", "t_crossfit", "cpu_s"}


def _plain(obj):
    """JSON-ready copy of ``obj`` without the keys :data:`SKIP`."""
    text = json.dumps(_finite_or_null(obj), allow_nan=False, default=_jsonable)
    return _drop(json.loads(text))


def _drop(obj):
    if isinstance(obj, dict):
        return {k: _drop(v) for k, v in obj.items() if k not in SKIP}
    if isinstance(obj, list):
        return [_drop(v) for v in obj]
    return obj


def run(names, n_cases) -> dict:
    """``{test: {"cpu_s": float, "cases": [{"row", "diagnoses"}]}}``."""
    seen = []
    plain = rt.diagnosis

    def recording(measured, engine):
        d = plain(measured, engine)
        seen.append(_plain(d))
        return d

    rt.diagnosis = recording
    out = {}
    for name in names:
        test = rt.RATE_TESTS[name]
        cases, cpu = [], 0.0
        for i in range(n_cases):
            seen.clear()
            t0 = time.process_time()
            row = test.row((i, test.seed, *test.extra))
            dt = time.process_time() - t0
            cpu += dt
            cases.append({"row": _plain(row), "diagnoses": list(seen), "cpu_s": dt})
        out[name] = {"cpu_s": cpu, "cases": cases}
        print(f"{name}: {n_cases} cases, CPU {cpu:.1f} s", flush=True)
    rt.diagnosis = plain
    return out


def differences(a, b, rtol, path="", scale=None) -> list:
    """Where ``a`` and ``b`` differ (strings, paths)."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            return [f"{path}: keys {sorted(set(a) ^ set(b))}"]
        return [d for k in a for d in differences(a[k], b[k], rtol, f"{path}.{k}", scale)]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: length {len(a)} != {len(b)}"]
        nums = [abs(v) for v in a if isinstance(v, float)]
        sc = max(nums) if nums else scale
        return [d for i, (x, y) in enumerate(zip(a, b))
                for d in differences(x, y, rtol, f"{path}[{i}]", sc)]
    if isinstance(a, float) and isinstance(b, (int, float)) and not isinstance(b, bool):
        floor = rtol * (scale or 0.0)
        if math.isclose(a, b, rel_tol=rtol, abs_tol=floor):
            return []
        return [f"{path}: {a!r} != {b!r} (rel {abs(a - b) / max(abs(a), abs(b)):.2e})"]
    return [] if a == b else [f"{path}: {a!r} != {b!r}"]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=6)
    ap.add_argument("--tests", default=",".join(rt.RATE_TESTS))
    ap.add_argument("--save")
    ap.add_argument("--compare")
    ap.add_argument("--rtol", type=float, default=1e-6)
    args = ap.parse_args(argv)
    names = args.tests.split(",")
    rt.diagnosis(*_warm_up())                      # compiled kernels loaded before timing
    now = run(names, args.cases)
    if args.save:
        Path(args.save).write_text(json.dumps(now, indent=1))
    if args.compare:
        return _report(json.loads(Path(args.compare).read_text()), now, names, args.rtol)
    return 0


def _warm_up():
    case = rt.make_case(99, [], "sz", 1)
    return case.measured, rt.engines()["sz"]


def _cpu(run, k) -> float:
    """CPU seconds of the first ``k`` cases of a test's run (all of them where the run kept
    only the total)."""
    cases = run["cases"][:k]
    if all("cpu_s" in c for c in cases):
        return sum(c["cpu_s"] for c in cases)
    return run["cpu_s"]


def _report(old, now, names, rtol) -> int:
    bad, totals = 0, [0.0, 0.0]
    for name in names:
        o, n = old[name], now[name]
        k = min(len(o["cases"]), len(n["cases"]))
        diff = differences(_drop(o["cases"][:k]), _drop(n["cases"][:k]), rtol, name)
        bad += len(diff)
        for d in diff[:10]:
            print("  DIFF", d)
        co, cn = (_cpu(r, k) for r in (o, n))
        totals[0] += co
        totals[1] += cn
        print(f"{name} ({k} cases): CPU {co:.1f} s -> {cn:.1f} s ({co / max(cn, 1e-9):.2f}x), "
              f"{'same' if not diff else f'{len(diff)} differences'}")
    tot_o, tot_n = totals
    print(f"total: CPU {tot_o:.1f} s -> {tot_n:.1f} s ({tot_o / max(tot_n, 1e-9):.2f}x); "
          f"{bad} differences")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
