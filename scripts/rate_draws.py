"""A fixed number of a rate test's cases, with its misses listed.

The rate tests (:mod:`benchmarks.rate_tests`) stop as soon as their record is clear; to study
the misses behind a rate, this script draws ``--cases`` cases of one test's own row function
at ``--seed`` (case i draws from ``[seed, i]``, as in the test), diagnoses them in parallel
and prints every miss and, last, ``k/n``:

    python scripts/rate_draws.py passive --seed 424243 --cases 70
    python scripts/rate_draws.py missing_mode --seed 5150 --cases 48

The last line printed: ``passive seed 424243: 68/70 (0.971, 95% Wilson 0.90-0.99)``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from benchmarks.rate_tests import RATE_TESTS  # noqa: E402
from benchmarks.scoring import wilson_interval  # noqa: E402
from powertrain.parallel import run_map  # noqa: E402

#: script's name of a test -> its rate test
TESTS = {"passive": RATE_TESTS["passive_side_named"],
         "missing_mode": RATE_TESTS["missing_body_mode"]}


def _row(task):
    name, i, seed = task
    r = TESTS[name].row((i, seed))
    r["case"] = i
    return r


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("test", choices=sorted(TESTS))
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--cases", type=int, default=48)
    a = ap.parse_args(argv)
    good = TESTS[a.test].is_good
    rows = run_map(_row, [(a.test, i, a.seed) for i in range(a.cases)])
    for r in rows:
        if not good(r):
            print(f"miss: case {r['case']}, claimed {r['claimed']}, verdict {r['verdict'][:100]}")
    k = sum(bool(good(r)) for r in rows)
    lo, hi = wilson_interval(k, a.cases)
    print(f"{a.test} seed {a.seed}: {k}/{a.cases} ({k / a.cases:.3f}, 95% Wilson "
          f"{lo:.2f}-{hi:.2f})")


if __name__ == "__main__":
    main()
